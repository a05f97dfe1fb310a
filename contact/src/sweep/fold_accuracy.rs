//! Fold frequencies to a requested accuracy: each fold of a harmonic-balance branch
//! located again on a ladder of harmonics, only around the fold.
//!
//! A fold's frequency carries the truncation error of the harmonics it was found with, and
//! on a piecewise-smooth contact branch also the error of its interpolation between branch
//! points (the fold of the same branch moves by about 1e-5 relative with the step). For
//! each fold of a branch, [`refine_folds`] takes the branch point some way before it
//! ([`APPROACH`] `ω_1` in frequency, or the first point), carries its coefficients to `2H`
//! harmonics and `2Nt` AFT samples ([`resize_harmonics`]), and follows the branch at `2H`
//! from there (each further rung starts from the previous rung's corrected start, carried
//! to its harmonics: the sweep's point lifted to many more harmonics is too far from the
//! fine branch for the corrector) with the core's continuation, with steps of at most [`SEGMENT_MAX_STEP`],
//! until it turns back at the fold (the core confirms a fold by a retreat of
//! [`TURNING_POINT_EXCURSION`](super::TURNING_POINT_EXCURSION) `ω_1`, so that a corner's zigzag is not taken for it).
//!
//! The change `d` of the fold frequency between `H` and `2H` gives the coarser fold's error
//! by Richardson with the order [`HB_ORDER`] of the harmonic-balance estimate,
//! `e = d r^p / (r^p - 1)` with `r = 2`. Measured on the strongly forced rod, the fold
//! frequency does not converge monotonically in `H` (20, 40, 80, 160, 320: 1.184405,
//! 1.184574, 1.184362, 1.184243, 1.184267 `ω_1`), so one pair can be small by chance: the
//! uncertainty is the largest `e` of the last two pairs, and the ladder doubles `H` until
//! it is at most `target |ω_fold|`. The fold is reported at the finest rung, with that
//! uncertainty.
//!
//! The branch in between keeps the sweep's harmonics: only the segments that approach the
//! folds are solved with more, which is where the cost of a fine `H` is worth paying.

use std::time::Instant;

use semismooth::continuation::{
    Continuation, ContinuationEvent, ContinuationTermination, Direction,
};
use semismooth::{Factorize, GeneralizedJacobian, ParameterDependent};

use super::response::FrequencyResponse;
use super::{
    continuation_error, continuation_options, hb_solver, penalty_continuation, ssn_continuation,
    MethodContinuation, StateRecovery,
};
use crate::hb::resize_harmonics;
use crate::model::Structure;
use crate::settings::{SolverSettings, SweepSettings};
use crate::solve::accuracy::search::{check_target, MAX_SEARCH_UNKNOWNS};
use crate::solve::accuracy::HB_ORDER;
use crate::solve::{penalty_options, HarmonicProblem, RunError};

/// Frequency distance, in units of `ω_1`, before a fold where its refinement starts.
pub const APPROACH: f64 = 0.02;

/// Largest number of harmonics a fold is refined with by default (the accuracy search's
/// limit for single solves).
pub const MAX_FOLD_HARMONICS: usize = 1000;

/// Largest arclength step of a refinement segment (the sweep's scaled arclength: about
/// 0.2 % of `ω_1` on flat parts).
pub const SEGMENT_MAX_STEP: f64 = 0.002;

/// Largest number of points of one refinement segment.
pub const MAX_SEGMENT_POINTS: usize = 400;

/// One rung of a fold's ladder.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FoldRung {
    /// Harmonics.
    pub harmonics: usize,
    /// AFT samples per period.
    pub time_samples: usize,
    /// The fold frequency `ω` (absolute) at these harmonics.
    pub omega: f64,
    /// Points of the segment that found it (0 for the sweep's own fold).
    pub points: usize,
    /// Wall time of the segment.
    pub seconds: f64,
}

/// Why a fold's ladder stopped before its uncertainty met the target.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum FoldStop {
    /// The target is met.
    Met,
    /// The next rung would exceed the harmonics limit or the solvable size.
    Limit {
        /// The harmonics the next rung would need.
        harmonics: usize,
    },
    /// The segment at `harmonics` could not correct its start (the branch point carried to
    /// those harmonics): the core continuation's reason.
    StartFailed {
        /// Its harmonics.
        harmonics: usize,
        /// Why (the continuation's termination).
        termination: ContinuationTermination,
    },
    /// The segment at `harmonics` ended without turning back near the fold.
    NotFound {
        /// Its harmonics.
        harmonics: usize,
        /// Its points.
        points: usize,
    },
}

/// A fold frequency with its uncertainty.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FoldAccuracy {
    /// The fold as the sweep found it (`ω`, absolute).
    pub sweep_omega: f64,
    /// The fold at the finest rung.
    pub omega: f64,
    /// Estimated absolute error of `omega`, the largest Richardson error of the last two
    /// pairs of rungs (module documentation); `None` with fewer than two rungs.
    pub uncertainty: Option<f64>,
    /// The rungs, coarsest first (the first is the sweep's own fold).
    pub rungs: Vec<FoldRung>,
    /// Why the ladder stopped.
    pub stop: FoldStop,
}

impl FoldAccuracy {
    /// Whether the uncertainty meets `target` relative to the fold frequency.
    pub fn met(&self) -> bool {
        self.stop == FoldStop::Met
    }

    /// Harmonics of the reported fold.
    pub fn harmonics(&self) -> usize {
        self.rungs.last().map_or(0, |r| r.harmonics)
    }
}

/// Richardson's error of the coarser of two fold frequencies at `H` and `2H`.
fn coarse_error(coarse: f64, fine: f64) -> f64 {
    let rp = 2f64.powf(HB_ORDER);
    (fine - coarse).abs() * rp / (rp - 1.0)
}

/// Each fold of `response` (a harmonic-balance sweep of `structure` with `settings` over
/// `sweep`) to a relative accuracy `target` with at most `max_harmonics` harmonics
/// ([`MAX_FOLD_HARMONICS`] by default; module documentation). `Err` when a segment
/// could not run (the method is no harmonic balance, a bad setting); a ladder that did not
/// meet the target says why in [`FoldAccuracy::stop`].
pub fn refine_folds(
    structure: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    response: &FrequencyResponse,
    (target, max_harmonics): (f64, usize),
) -> Result<Vec<FoldAccuracy>, RunError> {
    check_target(target)?;
    if !settings.method.is_harmonic_balance() {
        return Err(RunError::Unsupported {
            method: settings.method.name(),
            what: "fold frequencies to an accuracy (harmonic balance only: ssn-hb, penalty-hb)",
        });
    }
    let omega_1 = structure.omega_1;
    let mut out = Vec::with_capacity(response.folds.len());
    let mut states = StateRecovery::new(structure, settings, response);
    for (&fold, &index) in response.folds.iter().zip(&response.fold_indices) {
        // The start: the last point at least APPROACH omega_1 before the fold.
        let start = (0..index)
            .rev()
            .find(|&j| (response.points[j].omega - fold).abs() >= APPROACH * omega_1)
            .unwrap_or(0);
        let ladder = Ladder {
            rod: structure,
            settings,
            sweep,
            start_omega: response.points[start].omega,
            heading: fold - response.points[start].omega,
            fold,
            u_ref: response.reference_amplitude,
            max_harmonics,
        };
        let at_fold = response.point_settings(settings, index);
        let first = FoldRung {
            harmonics: at_fold.harmonics,
            time_samples: at_fold.time_samples,
            omega: fold,
            points: 0,
            seconds: 0.0,
        };
        // The start of the next rung: the branch point, then each rung's corrected start.
        let from = (
            states.state(start)?.into_owned(),
            response.point_settings(settings, start).harmonics,
        );
        out.push(ladder.climb(first, from, target)?);
    }
    Ok(out)
}

/// The ladder of one fold: the sweep of `rod` with `settings` over `sweep`, the branch
/// point's frequency the segments start from, the heading from it towards the fold, the
/// fold as the sweep found it, the branch's reference amplitude and the harmonics allowed.
struct Ladder<'a> {
    rod: &'a Structure,
    settings: &'a SolverSettings,
    sweep: &'a SweepSettings,
    start_omega: f64,
    heading: f64,
    fold: f64,
    u_ref: f64,
    max_harmonics: usize,
}

impl Ladder<'_> {
    /// The fold to the relative accuracy `target`: rungs doubling the harmonics from
    /// `first` (the sweep's own fold), each segment starting from `from` (a state and its
    /// harmonics, the last corrected start), until two pairs meet the target or it stops.
    fn climb(
        &self,
        first: FoldRung,
        mut from: (Vec<f64>, usize),
        target: f64,
    ) -> Result<FoldAccuracy, RunError> {
        let mut rungs = vec![first];
        let mut uncertainty = None;
        let stop = loop {
            let last = rungs.last().expect("one rung at least");
            let rung = match self.rung(last, &mut from)? {
                Ok(rung) => rung,
                Err(stop) => break stop,
            };
            let omega = rung.omega;
            let error = coarse_error(last.omega, omega);
            let previous =
                (rungs.len() >= 2).then(|| coarse_error(rungs[rungs.len() - 2].omega, last.omega));
            rungs.push(rung);
            uncertainty = Some(previous.map_or(error, |p| p.max(error)));
            // One pair can be small by chance: met only on two pairs.
            if previous.is_some() && uncertainty.is_some_and(|u| u <= target * omega.abs()) {
                break FoldStop::Met;
            }
        };
        Ok(FoldAccuracy {
            sweep_omega: self.fold,
            omega: rungs.last().expect("one rung at least").omega,
            uncertainty,
            rungs,
            stop,
        })
    }

    /// The fold at twice the harmonics of `last`, the segment starting from `from` (set to
    /// its corrected start when there is one); `Err` inside: why the ladder stops there.
    fn rung(
        &self,
        last: &FoldRung,
        from: &mut (Vec<f64>, usize),
    ) -> Result<Result<FoldRung, FoldStop>, RunError> {
        let rod = self.rod;
        let (h, nt) = (2 * last.harmonics, 2 * last.time_samples);
        let width = rod.model.dofs() + rod.model.contact_count();
        if h > self.max_harmonics || width.saturating_mul(2 * h + 1) > MAX_SEARCH_UNKNOWNS {
            return Ok(Err(FoldStop::Limit { harmonics: h }));
        }
        let rung_settings = SolverSettings {
            harmonics: h,
            time_samples: nt,
            estimate_error: false,
            accuracy: None,
            ..self.settings.clone()
        };
        let segment = Segment {
            rod,
            settings: &rung_settings,
            sweep: self.sweep,
            from: (self.start_omega, &from.0, from.1),
            heading: self.heading,
            near: self.fold,
            u_ref: self.u_ref,
        };
        let SegmentRun {
            found,
            points,
            seconds,
            corrected_start,
        } = segment.fold()?;
        if let Some(state) = corrected_start {
            *from = (state, h);
        }
        Ok(match found {
            Found::Fold(omega) => Ok(FoldRung {
                harmonics: h,
                time_samples: nt,
                omega,
                points,
                seconds,
            }),
            Found::StartFailed(termination) => Err(FoldStop::StartFailed {
                harmonics: h,
                termination,
            }),
            Found::Nothing => Err(FoldStop::NotFound {
                harmonics: h,
                points,
            }),
        })
    }
}

/// What a segment met.
enum Found {
    /// The fold, at this frequency.
    Fold(f64),
    /// Its start could not be corrected: the continuation's termination.
    StartFailed(ContinuationTermination),
    /// The segment ended without turning back.
    Nothing,
}

/// What a segment met, its points, its wall time and its start as corrected.
struct SegmentRun {
    found: Found,
    points: usize,
    seconds: f64,
    corrected_start: Option<Vec<f64>>,
}

/// One refinement segment: from a branch point carried to the rung's harmonics, towards
/// the fold near `near`.
struct Segment<'a> {
    rod: &'a Structure,
    settings: &'a SolverSettings,
    sweep: &'a SweepSettings,
    /// `(ω, state, harmonics)` of the branch point it starts from.
    from: (f64, &'a [f64], usize),
    /// Sign of the frequency's change from the start towards the fold.
    heading: f64,
    /// The fold frequency at the coarser harmonics.
    near: f64,
    /// The branch's reference amplitude (the step scaling's `u_ref`).
    u_ref: f64,
}

impl Segment<'_> {
    /// What this segment meets.
    fn fold(&self) -> Result<SegmentRun, RunError> {
        let started = Instant::now();
        let model = &self.rod.model;
        let (omega, state, from_h) = self.from;
        let h = self.settings.harmonics;
        let dofs = model.dofs();
        let mut solver = hb_solver(self.settings.linear_solver);
        let problem = HarmonicProblem::of(model, omega, self.settings)?;
        let found = match problem {
            HarmonicProblem::Ssn(mut problem) => {
                let x = resize_harmonics(state, from_h, h, dofs, problem.contacts());
                let method = ssn_continuation(model, &problem, self.u_ref);
                self.follow((&mut problem, &mut *solver), &x, method, |c| c)?
            }
            HarmonicProblem::Penalty(mut problem) => {
                let options = penalty_options(self.settings, model);
                let x = resize_harmonics(state, from_h, h, dofs, 0);
                let method = penalty_continuation(model, &problem, &options, self.u_ref);
                let affine = method.affine_pieces;
                self.follow((&mut problem, &mut *solver), &x, method, |c| {
                    if affine {
                        c.with_affine_pieces()
                    } else {
                        c
                    }
                })?
            }
        };
        let (found, points, corrected_start) = found;
        Ok(SegmentRun {
            found,
            points,
            seconds: started.elapsed().as_secs_f64(),
            corrected_start,
        })
    }

    /// Follows the branch of `problem` from `x` at the segment's start until it has turned
    /// back at a fold the core confirms (module documentation); with the start as
    /// corrected.
    fn follow<P, S>(
        &self,
        (problem, solver): (&mut P, &mut S),
        x: &[f64],
        method: MethodContinuation,
        configure: impl FnOnce(Continuation<'_, P, S>) -> Continuation<'_, P, S>,
    ) -> Result<(Found, usize, Option<Vec<f64>>), RunError>
    where
        P: GeneralizedJacobian + ParameterDependent + ?Sized,
        S: Factorize<P::Jacobian> + ?Sized,
    {
        let omega_1 = self.rod.omega_1;
        let mut options = continuation_options(
            self.settings,
            self.sweep,
            omega_1,
            self.rod.model.dofs(),
            self.u_ref,
            &method,
        )?;
        options.direction = if self.heading >= 0.0 {
            Direction::Increasing
        } else {
            Direction::Decreasing
        };
        options.max_points = MAX_SEGMENT_POINTS.min(self.sweep.max_points);
        options.max_step = options.max_step.min(SEGMENT_MAX_STEP);
        options.initial_step = options.initial_step.min(SEGMENT_MAX_STEP);
        options.min_step = options.min_step.min(options.initial_step);
        // The segment never needs to go further than one approach beyond the fold.
        let reach = 2.0 * APPROACH * omega_1;
        options.parameter_min = options.parameter_min.max(self.near - reach);
        options.parameter_max = options.parameter_max.min(self.near + reach);
        let (omega, _, _) = self.from;
        let mut continuation = configure(
            Continuation::new(problem, solver, x, omega, options).map_err(continuation_error)?,
        );
        // The sweep's options confirm a fold by its excursion (`fold_excursion`), so the
        // first fold event is the fold and not a corner's zigzag.
        let mut points = 0;
        let mut corrected_start = None;
        while let Some(point) = continuation.next() {
            if points == 0 {
                corrected_start = Some(point.state);
            }
            points += 1;
            let fold = continuation.events().iter().find_map(|event| match event {
                ContinuationEvent::Fold { parameter, .. } => Some(*parameter),
                _ => None,
            });
            if let Some(fold) = fold {
                return Ok((Found::Fold(fold), points, corrected_start));
            }
        }
        let found = match continuation.termination() {
            Some(t) if points == 0 => Found::StartFailed(t.clone()),
            _ => Found::Nothing,
        };
        Ok((found, points, corrected_start))
    }
}
