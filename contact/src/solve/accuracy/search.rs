//! The cheapest discretisation for an accuracy target ([`SolverSettings::accuracy`]).
//!
//! The method is solved on a ladder of discretisations, each solve started from the
//! previous answer carried over (harmonic-balance coefficients lifted, the LCP's forces
//! interpolated, the march's final state): harmonic balance over `H` (with
//! the default AFT samples for `H`, times a factor the search may double), the periodic
//! LCP over its time steps `Nt`, time marching over its steps per period. Each new solve
//! closes a pair with the previous one; the change of the reported quantities between them
//! gives Richardson's estimate of both errors (module [`super`]): the finer one's, change
//! `/ (r^p - 1)`, and the coarser one's, change `r^p / (r^p - 1)` (`r` the ratio of the two
//! discretisations, `p` the method's order). The search stops at the first pair in which
//! one estimate meets the target and returns the cheaper solve that meets it; otherwise
//! the next discretisation is the one the error model `C h^p` predicts for the target,
//! times [`SAFETY`], between [`MIN_RATIO`] and [`MAX_RATIO`] times the current one.
//!
//! Harmonic balance then checks its AFT samples on their own ("Nt matters where contact
//! opens and closes"): the chosen `H` is solved again with twice the samples (started from
//! the same coefficients: a few iterations), the quadrature part of the error (order 2 in
//! `Nt`) is added, and when that exceeds the target the finer samples are kept and the
//! search goes on with them. Penalty HB adds its penalty part (the change against
//! `k_p / 10`, divided by 9) at the end.
//!
//! What was tried, what was chosen, the estimate and the cost of the search are in the
//! returned solution's [`Solution::search`] and [`Solution::error_estimate`].

use std::time::Instant;

use super::{
    carried_start, penalty_part, Discretisation, ErrorEstimate, EstimateBasis, NoEstimate,
    RelativeErrors, ReportedQuantities,
};
use crate::model::Structure;
use crate::settings::SolverSettings;
use crate::solve::DiscretisationKind;
use crate::solve::{solve_as_given, RunCounters, RunError, Solution};

/// The predicted discretisation is multiplied by this (the error model's constant and
/// order are those of the last pair only).
pub const SAFETY: f64 = 1.15;
/// Smallest ratio of one discretisation of the ladder to the previous one.
pub const MIN_RATIO: f64 = 1.5;
/// Largest ratio of one discretisation of the ladder to the previous one (the Richardson
/// factor relies on the order over this ratio).
pub const MAX_RATIO: f64 = 4.0;
/// Most harmonics a search tries (and fewer for large models: at most
/// [`MAX_SEARCH_UNKNOWNS`] harmonic-balance unknowns).
pub const MAX_SEARCH_HARMONICS: usize = 1000;
/// Most harmonic-balance unknowns `(N + m)(2H + 1)` a search tries.
pub const MAX_SEARCH_UNKNOWNS: usize = 2_000_000;
/// Most time steps per period of a periodic-LCP search (the LCP matrix is dense, of order
/// `m Nt`; also at most [`crate::lcp::MAX_LCP_SIZE`]` / m`).
pub const MAX_SEARCH_LCP_STEPS: usize = 4096;
/// Most steps per period of a time-marching search.
pub const MAX_SEARCH_MARCH_STEPS: usize = 65_536;
/// Harmonic balance solves harmonics between the last rung that missed the target and the
/// first that met it only when they are at most this fraction of the latter (fewer would
/// save little).
pub const WORTH_BETWEEN: f64 = 0.85;
/// Largest factor on the default AFT samples of harmonic balance.
pub const MAX_SAMPLE_FACTOR: usize = 8;

/// One solve of a search.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchStep {
    /// Its discretisation.
    pub discretisation: Discretisation,
    /// Whether it converged.
    pub converged: bool,
    /// Newton iterations, Lemke pivots or periods marched.
    pub iterations: usize,
    /// Wall time of the solve.
    pub seconds: f64,
    /// Work of the solve.
    pub counters: RunCounters,
    /// Its estimated relative error from the pair it closes (`None` for the first solve
    /// and a solve that did not converge).
    pub estimate: Option<f64>,
}

/// Why a search stopped.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SearchStop {
    /// The chosen discretisation's estimate meets the target.
    Met,
    /// The finest discretisation the search allows was solved without meeting the target
    /// (its answer is returned).
    Limit {
        /// The finest level: harmonics (HB) or time steps per period.
        limit: usize,
    },
    /// A solve of the search did not converge (its answer is returned).
    NotConverged {
        /// Its discretisation.
        at: Discretisation,
    },
    /// Penalty HB: the penalty part of the estimate alone keeps it above the target (raise
    /// the penalty stiffness).
    PenaltyTooSoft {
        /// The penalty stiffness used.
        penalty_stiffness: f64,
    },
    /// An estimate could not be made.
    NoEstimate(NoEstimate),
}

/// What a search tried, chose and cost.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscretisationSearch {
    /// The accuracy asked (relative, on the reported quantities).
    pub target: f64,
    /// Why it stopped.
    pub stop: SearchStop,
    /// Every solve, in order.
    pub steps: Vec<SearchStep>,
    /// Index in `steps` of the solve returned.
    pub chosen: usize,
    /// Wall time of the whole search.
    pub seconds: f64,
    /// Work of every solve of the search.
    pub counters: RunCounters,
}

impl DiscretisationSearch {
    /// Whether the returned solve meets the target.
    pub fn met(&self) -> bool {
        self.stop == SearchStop::Met
    }
}

/// The discretisations a method's search walks through.
struct Ladder {
    kind: DiscretisationKind,
    /// The method's order in its discretisation.
    order: f64,
    /// First level.
    start: usize,
    /// Finest level.
    limit: usize,
    /// Harmonic balance: factor on the default AFT samples.
    sample_factor: usize,
}

impl Ladder {
    fn new(rod: &Structure, settings: &SolverSettings) -> Self {
        let formulation = crate::solve::formulation::of(settings.method);
        let (order, start, limit) = formulation.search_ladder(rod, settings);
        Self {
            kind: formulation.discretisation(),
            order,
            start,
            limit,
            sample_factor: 1,
        }
    }

    /// This ladder starting at `level` (kept inside it; `None`: its own first level).
    fn starting_at(mut self, level: Option<usize>) -> Self {
        if let Some(level) = level {
            self.start = level.clamp(self.start, self.limit);
        }
        self
    }

    /// `base` with the discretisation `level` and neither an estimate nor a target.
    fn settings(&self, base: &SolverSettings, level: usize) -> SolverSettings {
        let mut s = base.clone();
        s.accuracy = None;
        s.estimate_error = false;
        self.kind.set_level(&mut s, level, self.sample_factor);
        s
    }

    /// The level after `level` whose pair estimate was `estimate` (module documentation).
    fn next(&self, level: usize, estimate: f64, target: f64) -> usize {
        let wanted = if estimate.is_finite() {
            level as f64 * (estimate / target).powf(1.0 / self.order) * SAFETY
        } else {
            f64::INFINITY
        };
        let ratio = (wanted / level as f64).clamp(MIN_RATIO, MAX_RATIO);
        let mut next = (ratio * level as f64).ceil() as usize;
        if self.kind != DiscretisationKind::Harmonics {
            // Time steps in multiples of 8.
            next = next.div_ceil(8) * 8;
        }
        next.max(level + 1).min(self.limit)
    }
}

/// The search's record while it runs.
struct Record {
    target: f64,
    steps: Vec<SearchStep>,
    counters: RunCounters,
    started: Instant,
}

impl Record {
    fn new(target: f64) -> Self {
        Self {
            target,
            steps: Vec::new(),
            counters: RunCounters::default(),
            started: Instant::now(),
        }
    }

    fn push(&mut self, solution: &Solution, estimate: Option<f64>) -> usize {
        self.counters = self.counters + solution.counters;
        self.steps.push(SearchStep {
            discretisation: Discretisation {
                harmonics: solution.harmonics,
                time_samples: solution.time_samples,
            },
            converged: solution.converged(),
            iterations: solution.iterations,
            seconds: solution.solve_seconds,
            counters: solution.counters,
            estimate,
        });
        self.steps.len() - 1
    }

    /// `solution` (step `chosen`) with its estimate and the search.
    fn finish(
        self,
        mut solution: Solution,
        chosen: usize,
        stop: SearchStop,
        estimate: Option<(RelativeErrors, EstimateBasis)>,
    ) -> Solution {
        let others = self
            .steps
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != chosen)
            .fold((0.0, RunCounters::default()), |(s, c), (_, step)| {
                (s + step.seconds, c + step.counters)
            });
        solution.error_estimate = match (&stop, estimate) {
            (_, Some((parts, basis))) => Ok(ErrorEstimate {
                relative: parts.largest(),
                parts,
                basis,
                seconds: others.0,
                counters: others.1,
            }),
            (SearchStop::NoEstimate(why), None) => Err(why.clone()),
            (_, None) if !solution.converged() => Err(NoEstimate::NotConverged),
            (_, None) => Err(NoEstimate::Coarsest { minimum: 1 }),
        };
        solution.search = Some(DiscretisationSearch {
            target: self.target,
            stop,
            steps: self.steps,
            chosen,
            seconds: self.started.elapsed().as_secs_f64(),
            counters: self.counters,
        });
        solution
    }
    /// `solution`, which did not converge, as the last step of the finished search.
    fn unconverged(mut self, solution: Solution) -> Solution {
        let step = self.push(&solution, None);
        let at = self.steps[step].discretisation;
        self.finish(solution, step, SearchStop::NotConverged { at }, None)
    }

    /// The basis of an estimate against the rung `against` with the order `order`.
    fn basis(&self, against: &Rung, order: f64) -> EstimateBasis {
        EstimateBasis {
            against: self.steps[against.step].discretisation,
            order,
            softer_penalty: None,
            time_samples_check: None,
        }
    }

    /// Richardson's estimates of the pair `(coarse, fine)` from the `change` between them
    /// with the convergence order `order`, recorded on their steps (the fine one's only
    /// without a finer partner): the coarse and the fine error.
    fn estimate_pair(
        &mut self,
        (coarse, fine): (&Rung, &Rung),
        change: &RelativeErrors,
        order: f64,
        finer_partner: bool,
    ) -> (RelativeErrors, RelativeErrors) {
        let rp = (fine.level as f64 / coarse.level as f64).powf(order);
        let fine_error = change.scaled(1.0 / (rp - 1.0));
        let coarse_error = change.scaled(rp / (rp - 1.0));
        self.steps[coarse.step].estimate = Some(coarse_error.largest());
        if !finer_partner {
            self.steps[fine.step].estimate = Some(fine_error.largest());
        }
        (coarse_error, fine_error)
    }
}

/// A converged solve of the ladder and its index in the record.
struct Rung {
    level: usize,
    solution: Solution,
    step: usize,
}

/// `Err` unless `target` is a relative accuracy in (0, 1) (the scene's `solver.accuracy`).
pub(crate) fn check_target(target: f64) -> Result<(), RunError> {
    if !(target.is_finite() && target > 0.0 && target < 1.0) {
        return Err(RunError::InvalidSetting {
            name: "solver.accuracy",
            value: target,
            allowed: "a relative accuracy in (0, 1)",
        });
    }
    Ok(())
}

/// Solves `structure` at `omega` with the cheapest discretisation of `settings.method` whose
/// estimated relative error meets `target` (module documentation), from `warm_start` on the
/// first rung when it fits. `Err` only when a solve could not run; a search that did not
/// meet the target returns its last answer with the reason in [`DiscretisationSearch::stop`].
pub fn solve_to_accuracy(
    structure: &Structure,
    omega: f64,
    settings: &SolverSettings,
    target: f64,
    warm_start: Option<&[f64]>,
) -> Result<Solution, RunError> {
    solve_to_accuracy_from(structure, omega, settings, target, warm_start, None)
}

/// [`solve_to_accuracy`] whose first rung is `first_level` (e.g. the harmonics of the
/// state `warm_start` was taken from: a branch point's), kept inside the method's ladder;
/// `None`: the ladder's own first level.
pub(crate) fn solve_to_accuracy_from(
    structure: &Structure,
    omega: f64,
    settings: &SolverSettings,
    target: f64,
    warm_start: Option<&[f64]>,
    first_level: Option<usize>,
) -> Result<Solution, RunError> {
    check_target(target)?;
    let mut ladder = Ladder::new(structure, settings).starting_at(first_level);
    let mut record = Record::new(target);
    let first = solve_as_given(
        structure,
        omega,
        &ladder.settings(settings, ladder.start),
        warm_start,
    )?;
    if !first.converged() {
        return Ok(record.unconverged(first));
    }
    let step = record.push(&first, None);
    let mut current = Rung {
        level: ladder.start,
        solution: first,
        step,
    };
    // The estimate of `current` and its basis, once it closes a pair; harmonic balance:
    // the level and estimate of the last rung that did not meet the target.
    let mut last: Option<(RelativeErrors, EstimateBasis)> = None;
    let mut failed: Option<(usize, f64)> = None;
    let finer_partner = ladder.kind == DiscretisationKind::Harmonics;
    loop {
        if current.level >= ladder.limit {
            let stop = SearchStop::Limit {
                limit: ladder.limit,
            };
            return Ok(record.finish(current.solution, current.step, stop, last));
        }
        let level = match &last {
            Some((e, _)) if !finer_partner => ladder.next(current.level, e.largest(), target),
            _ => (2 * current.level).min(ladder.limit),
        };
        let (fine, change) = match pair(
            structure,
            omega,
            (settings, &ladder),
            &mut record,
            &current,
            level,
        )? {
            Ok(pair) => pair,
            Err(unconverged) => return Ok(unconverged),
        };
        let (coarse_error, fine_error) =
            record.estimate_pair((&current, &fine), &change, ladder.order, finer_partner);
        let basis = |against: &Rung| record.basis(against, ladder.order);
        let (chosen, error, basis) = if coarse_error.largest() <= target {
            let b = basis(&fine);
            let chosen = (current, coarse_error, b);
            match failed {
                Some(below) if finer_partner => between(
                    structure,
                    omega,
                    (settings, &ladder),
                    &mut record,
                    below,
                    chosen,
                )?,
                _ => chosen,
            }
        } else if !finer_partner && fine_error.largest() <= target {
            let b = basis(&current);
            (fine, fine_error, b)
        } else {
            failed = Some((current.level, coarse_error.largest()));
            last = Some((fine_error, basis(&current)));
            current = fine;
            continue;
        };
        // Harmonic balance: the AFT samples on their own.
        if finer_partner && ladder.sample_factor < MAX_SAMPLE_FACTOR {
            let (rung, error, basis, met) = check_samples(
                structure,
                omega,
                (settings, &mut ladder),
                &mut record,
                (chosen, error, basis),
            )?;
            if !met {
                last = Some((error, basis));
                failed = None;
                current = rung;
                continue;
            }
            return finish_met(structure, omega, settings, record, rung, (error, basis));
        }
        return finish_met(structure, omega, settings, record, chosen, (error, basis));
    }
}

/// Solves the rung `level` from `current` (carried over) and returns it with the change of
/// the reported quantities from `current` (relative to the new rung); `Err` with the
/// finished search when it did not converge.
fn pair(
    rod: &Structure,
    omega: f64,
    (settings, ladder): (&SolverSettings, &Ladder),
    record: &mut Record,
    current: &Rung,
    level: usize,
) -> Result<Result<(Rung, RelativeErrors), Solution>, RunError> {
    let fine_settings = ladder.settings(settings, level);
    let start = carried_start(rod, &current.solution, &fine_settings);
    let fine = super::solve_carried(rod, omega, &fine_settings, start.as_deref(), |failed| {
        record.push(failed, None);
    })?;
    if !fine.converged() {
        let record = std::mem::replace(record, Record::new(record.target));
        return Ok(Err(record.unconverged(fine)));
    }
    let change = RelativeErrors::between(
        &ReportedQuantities::of(&current.solution),
        &ReportedQuantities::of(&fine),
    );
    let step = record.push(&fine, None);
    Ok(Ok((
        Rung {
            level,
            solution: fine,
            step,
        },
        change,
    )))
}

/// Harmonic balance: the rung `chosen` meets the target and the rung `below` (level and
/// estimate) did not; the error model `C H^-p` through both predicts the harmonics
/// `H*` between them that meet the target with [`SAFETY`]. When `H*` is at most
/// [`WORTH_BETWEEN`] of the chosen harmonics it is solved (from the chosen rung, truncated)
/// and estimated against the chosen rung (the finer partner); it is taken when it meets
/// the target.
fn between(
    rod: &Structure,
    omega: f64,
    (settings, ladder): (&SolverSettings, &Ladder),
    record: &mut Record,
    below: (usize, f64),
    chosen: (Rung, RelativeErrors, EstimateBasis),
) -> Result<(Rung, RelativeErrors, EstimateBasis), RunError> {
    let (level, error) = (chosen.0.level, chosen.1.largest());
    let (low, low_error) = below;
    if !(error > 0.0 && low_error > error) {
        return Ok(chosen);
    }
    let p = ((low_error / error).ln() / (level as f64 / low as f64).ln()).clamp(0.5, 3.0);
    let wanted = level as f64 * (error * SAFETY / record.target).powf(1.0 / p);
    let h = (wanted.ceil() as usize).max(low + 1);
    if h as f64 > WORTH_BETWEEN * level as f64 {
        return Ok(chosen);
    }
    let (candidate, change) = match pair(rod, omega, (settings, ladder), record, &chosen.0, h)? {
        Ok(pair) => pair,
        Err(_) => return Ok(chosen),
    };
    // The change was measured relative to the candidate; the chosen rung is its finer
    // partner: r = level / h.
    let rp = (level as f64 / h as f64).powf(ladder.order);
    let candidate_error = change.scaled(rp / (rp - 1.0));
    record.steps[candidate.step].estimate = Some(candidate_error.largest());
    if candidate_error.largest() > record.target {
        return Ok(chosen);
    }
    let basis = EstimateBasis {
        against: record.steps[chosen.0.step].discretisation,
        ..chosen.2
    };
    Ok((candidate, candidate_error, basis))
}

/// Harmonic balance's check of the AFT samples at the chosen `H`: the chosen rung solved
/// again with twice the samples; its quadrature part (order 2) added. Returns the rung to
/// go on with, its estimate and basis, and whether it meets the target.
fn check_samples(
    rod: &Structure,
    omega: f64,
    (settings, ladder): (&SolverSettings, &mut Ladder),
    record: &mut Record,
    (chosen, error, basis): (Rung, RelativeErrors, EstimateBasis),
) -> Result<(Rung, RelativeErrors, EstimateBasis, bool), RunError> {
    let mut finer = ladder.settings(settings, chosen.level);
    finer.time_samples = 2 * chosen.solution.time_samples;
    let doubled = super::solve_carried(rod, omega, &finer, Some(&chosen.solution.state), |f| {
        record.push(f, None);
    })?;
    if !doubled.converged() {
        record.push(&doubled, None);
        // The samples cannot be checked: the chosen rung stands on its H estimate.
        return Ok((chosen, error, basis, true));
    }
    let change = RelativeErrors::between(
        &ReportedQuantities::of(&chosen.solution),
        &ReportedQuantities::of(&doubled),
    );
    // Order 2 in Nt: the coarser samples' error is 4/3 of the change, the finer's 1/3.
    let coarse = error.plus(&change.scaled(4.0 / 3.0));
    if coarse.largest() <= record.target {
        let basis = EstimateBasis {
            time_samples_check: Some(doubled.time_samples),
            ..basis
        };
        let total = error.plus(&change.scaled(1.0 / 3.0));
        record.push(&doubled, Some(total.largest()));
        return Ok((chosen, coarse, basis, true));
    }
    let fine_error = error.plus(&change.scaled(1.0 / 3.0));
    let step = record.push(&doubled, Some(fine_error.largest()));
    ladder.sample_factor *= 2;
    let basis = EstimateBasis {
        time_samples_check: Some(chosen.solution.time_samples),
        ..basis
    };
    let met = fine_error.largest() <= record.target;
    let rung = Rung {
        level: chosen.level,
        solution: doubled,
        step,
    };
    Ok((rung, fine_error, basis, met))
}

/// The search's answer once a rung meets the target on its discretisation: penalty HB
/// adds its penalty part.
fn finish_met(
    rod: &Structure,
    omega: f64,
    settings: &SolverSettings,
    mut record: Record,
    chosen: Rung,
    (error, basis): (RelativeErrors, EstimateBasis),
) -> Result<Solution, RunError> {
    if !crate::solve::formulation::of(settings.method).penalises_contact() {
        return Ok(record.finish(
            chosen.solution,
            chosen.step,
            SearchStop::Met,
            Some((error, basis)),
        ));
    }
    let chosen_settings = SolverSettings {
        harmonics: chosen.solution.harmonics.unwrap_or(settings.harmonics),
        time_samples: chosen.solution.time_samples,
        ..settings.clone()
    };
    match penalty_part(rod, omega, &chosen_settings, &chosen.solution) {
        Ok((softer, part, seconds, counters)) => {
            record.counters = record.counters + counters;
            let total = error.plus(&part);
            let basis = EstimateBasis {
                softer_penalty: Some(softer),
                ..basis
            };
            let stop = if total.largest() <= record.target {
                SearchStop::Met
            } else {
                SearchStop::PenaltyTooSoft {
                    penalty_stiffness: softer * 10.0,
                }
            };
            let mut solution =
                record.finish(chosen.solution, chosen.step, stop, Some((total, basis)));
            if let Ok(e) = &mut solution.error_estimate {
                e.seconds += seconds;
                e.counters = e.counters + counters;
            }
            Ok(solution)
        }
        Err(why) => Ok(record.finish(
            chosen.solution,
            chosen.step,
            SearchStop::NoEstimate(why),
            None,
        )),
    }
}
