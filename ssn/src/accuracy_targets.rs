//! Accuracy targets: what the discretisation search ([`semismooth_contact::accuracy`])
//! chooses for a target, checked against a converged reference.
//!
//! For each case, method and target the search runs cold (`[solver] accuracy`), and the
//! chosen solve's reported quantities (the tip's extremes, the mean contact force) are
//! compared with the reference: the true error (as [`RelativeErrors::between`] defines
//! it), the search's estimate and their ratio (the estimate is meant to lie within
//! `[true / 3, 10 true]`). The cost of the chosen discretisation (one cold solve) is set
//! against the cheapest discretisation of the method's [`ladder`] whose true error meets
//! the target.
//!
//! The reference is time marching at [`REFERENCE_STEPS`] trapezoidal steps per period (the
//! cases have a massless contact node), period-to-period tolerance 1e-10; its uncertainty
//! is Richardson's (order 2) from half the steps and is printed with the table.

use semismooth_contact::accuracy::{Discretisation, RelativeErrors, ReportedQuantities};
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};
use semismooth_contact::solve::{solve, DiscretisationKind, Solution};

use crate::scene::{Method, SolverSettings};
use crate::tables::{Table, TableError};
use crate::words::discretisation;

/// Steps per period of the time-marching reference.
pub const REFERENCE_STEPS: usize = 8000;
/// The targets of the table.
pub const TARGETS: [f64; 3] = [1e-3, 1e-4, 1e-5];
/// Runs faster than this (seconds) are timed as the median of five: on a loaded machine
/// one run of the same setting varies by a factor of 2.5 from the next.
const REPEAT_BELOW_SECONDS: f64 = 1.0;
/// Timings of a fast run (median taken).
const REPEATS: usize = 5;

/// A case of the table: a name and its rod.
#[derive(Debug, Clone)]
pub struct TargetCase {
    /// Short name (`paper rod`, `strong rod`).
    pub name: &'static str,
    /// The rod.
    pub spec: RodSpec,
}

/// The cases: the method comparison's rod with the massless contact node, and the
/// strongly forced rod (`p0 = 0.2`, gap 0.5, massless contact node).
pub fn target_cases() -> Vec<TargetCase> {
    let paper = RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    };
    let strong = RodSpec {
        amplitude: 0.2,
        ..paper.clone()
    };
    vec![
        TargetCase {
            name: "paper rod",
            spec: paper,
        },
        TargetCase {
            name: "strong rod",
            spec: strong,
        },
    ]
}

/// The methods of the table.
pub const METHODS: [Method; 5] = [
    Method::SsnHb,
    Method::PenaltyHb,
    Method::LcpLemke,
    Method::LcpSsn,
    Method::March,
];

/// The targets of `method` in the table: [`TARGETS`], but for penalty HB, whose error
/// at the default penalty stiffness stops falling near 3e-5 on the paper's rod (H = 452
/// and 640), not 1e-5.
pub fn targets_of(method: Method) -> &'static [f64] {
    if method.penalises_contact() {
        &TARGETS[..2]
    } else {
        &TARGETS
    }
}

/// A converged reference: its reported quantities and its own uncertainty.
#[derive(Debug, Clone)]
pub struct TargetReference {
    /// The reference's reported quantities.
    pub quantities: ReportedQuantities,
    /// Richardson's estimate of its relative error (order 2, from half the steps).
    pub uncertainty: f64,
}

/// The time-marching reference of `rod` (module documentation).
pub fn reference(rod: &RodModel) -> Result<TargetReference, TableError> {
    let run = |steps: usize| -> Result<Solution, TableError> {
        let settings = SolverSettings {
            method: Method::March,
            steps_per_period: steps,
            march_tolerance: 1e-10,
            estimate_error: false,
            ..SolverSettings::default()
        };
        let s = solve(rod, rod.omega(), &settings, None)?;
        if !s.converged() {
            return Err(TableError::Figure(format!(
                "the reference march at {steps} steps did not settle"
            )));
        }
        Ok(s)
    };
    let fine = ReportedQuantities::of(&run(REFERENCE_STEPS)?);
    let half = ReportedQuantities::of(&run(REFERENCE_STEPS / 2)?);
    Ok(TargetReference {
        uncertainty: RelativeErrors::between(&half, &fine).largest() / 3.0,
        quantities: fine,
    })
}

/// The settings of `method` at `level` on its ladder: harmonics with the default AFT
/// samples (harmonic balance), time steps per period (the LCP, time marching); no estimate.
pub fn at_level(method: Method, level: usize) -> SolverSettings {
    SolverSettings::for_method(method).at_level(level)
}

/// The discretisations of `method` the cheapest setting is looked for in, by increasing
/// cost (ratio about `sqrt 2`); penalty HB stops at 320 harmonics, where its error stops
/// falling ([`targets_of`]).
pub fn ladder(method: Method) -> Vec<usize> {
    match method.discretisation() {
        DiscretisationKind::Harmonics => {
            let top = if method.penalises_contact() { 320 } else { 640 };
            [
                5, 7, 10, 14, 20, 28, 40, 56, 80, 113, 160, 226, 320, 452, 640,
            ]
            .into_iter()
            .filter(|&h| h <= top)
            .collect()
        }
        DiscretisationKind::TimeSamples => {
            vec![
                32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024, 1536, 2048,
            ]
        }
        DiscretisationKind::StepsPerPeriod => vec![
            64, 96, 128, 192, 256, 384, 512, 768, 1024, 1536, 2048, 3072, 4096, 6144, 8192,
        ],
    }
}

/// Wall time of one cold solve with `settings` (the median of `REPEATS` below
/// `REPEAT_BELOW_SECONDS`) and the solution.
pub fn cold_solve(
    rod: &RodModel,
    settings: &SolverSettings,
) -> Result<(f64, Solution), TableError> {
    let first = solve(rod, rod.omega(), settings, None)?;
    if first.solve_seconds >= REPEAT_BELOW_SECONDS {
        return Ok((first.solve_seconds, first));
    }
    let mut times = vec![first.solve_seconds];
    for _ in 1..REPEATS {
        times.push(solve(rod, rod.omega(), settings, None)?.solve_seconds);
    }
    times.sort_by(f64::total_cmp);
    Ok((times[REPEATS / 2], first))
}

/// One setting of a ladder scan: its level, true error and cold wall time.
#[derive(Debug, Clone, Copy)]
pub struct Scanned {
    /// Harmonics or time steps.
    pub level: usize,
    /// Relative error against the reference (infinite when not converged).
    pub error: f64,
    /// Wall time of a cold solve.
    pub seconds: f64,
}

/// `method`'s ladder solved up to the first level whose true error meets `finest` (or the
/// ladder's end).
pub fn scan(
    rod: &RodModel,
    method: Method,
    reference: &TargetReference,
    finest: f64,
) -> Result<Vec<Scanned>, TableError> {
    let mut out = Vec::new();
    for level in ladder(method) {
        let (seconds, s) = cold_solve(rod, &at_level(method, level))?;
        let error = if s.converged() {
            RelativeErrors::between(&ReportedQuantities::of(&s), &reference.quantities).largest()
        } else {
            f64::INFINITY
        };
        out.push(Scanned {
            level,
            error,
            seconds,
        });
        if error <= finest {
            break;
        }
    }
    Ok(out)
}

/// What the search chose for one case, method and target, against the reference.
#[derive(Debug, Clone)]
pub struct TargetRow {
    /// The method.
    pub method: Method,
    /// The target.
    pub target: f64,
    /// The chosen discretisation.
    pub chosen: Discretisation,
    /// Whether the search says the target is met.
    pub met: bool,
    /// The chosen solve's error against the reference.
    pub true_error: f64,
    /// The search's estimate of it.
    pub estimate: Option<f64>,
    /// Wall time of the whole search.
    pub search_seconds: f64,
    /// Wall time of one cold solve at the chosen discretisation.
    pub chosen_seconds: f64,
    /// The cheapest setting of the ladder that meets the target, and its wall time.
    pub cheapest: Option<Scanned>,
}

impl TargetRow {
    /// The estimate over the true error.
    pub fn ratio(&self) -> Option<f64> {
        self.estimate.map(|e| e / self.true_error)
    }
}

/// The search for `target` on `rod` with `method`, against `reference`; `scanned` is the
/// method's ladder scan ([`scan`]).
pub fn target_row(
    rod: &RodModel,
    method: Method,
    target: f64,
    reference: &TargetReference,
    scanned: &[Scanned],
) -> Result<TargetRow, TableError> {
    let settings = SolverSettings {
        accuracy: Some(target),
        ..SolverSettings::for_method(method)
    };
    let s = solve(rod, rod.omega(), &settings, None)?;
    let search = s
        .search
        .clone()
        .ok_or_else(|| TableError::Figure("a search without its record".into()))?;
    let chosen = search.steps[search.chosen].discretisation;
    let chosen_settings = SolverSettings {
        harmonics: chosen.harmonics.unwrap_or(settings.harmonics),
        time_samples: if method.marches() {
            settings.time_samples
        } else {
            chosen.time_samples
        },
        steps_per_period: if method.marches() {
            chosen.time_samples
        } else {
            settings.steps_per_period
        },
        estimate_error: false,
        accuracy: None,
        ..settings.clone()
    };
    let cheapest = scanned.iter().find(|x| x.error <= target).copied();
    // Timed only to set against the cheapest setting.
    let chosen_seconds = match cheapest {
        Some(_) => cold_solve(rod, &chosen_settings)?.0,
        None => f64::NAN,
    };
    let true_error = if s.converged() {
        RelativeErrors::between(&ReportedQuantities::of(&s), &reference.quantities).largest()
    } else {
        f64::INFINITY
    };
    Ok(TargetRow {
        method,
        target,
        chosen,
        met: search.met(),
        true_error,
        estimate: s.error_estimate.as_ref().ok().map(|e| e.relative),
        search_seconds: search.seconds,
        chosen_seconds,
        cheapest,
    })
}

/// The table of `rows` of the case `case` (the first cell names case, method and target).
pub fn target_table(case: &str, rows: &[TargetRow]) -> Table {
    let header = [
        "case, method, target",
        "chosen",
        "met",
        "true error",
        "estimate",
        "estimate / true",
        "search ms",
        "chosen ms",
        "cheapest meeting it",
        "cheapest ms",
        "chosen / cheapest",
    ];
    let mut table = Table {
        header: header.iter().map(|s| s.to_string()).collect(),
        rows: Vec::new(),
        timing: vec![6, 7, 9, 10],
    };
    for r in rows {
        let cheapest = r.cheapest.map(|c| {
            let d = Discretisation::of(&at_level(r.method, c.level));
            (discretisation(r.method, &d), c.seconds)
        });
        table.rows.push(vec![
            format!("{case}, {}, {:.0e}", r.method.name(), r.target),
            discretisation(r.method, &r.chosen),
            if r.met { "yes" } else { "no" }.to_string(),
            format!("{:.1e}", r.true_error),
            r.estimate.map_or("none".into(), |e| format!("{e:.1e}")),
            r.ratio().map_or("-".into(), |q| format!("{q:.1}")),
            format!("{:.1}", 1e3 * r.search_seconds),
            if r.chosen_seconds.is_finite() {
                format!("{:.2}", 1e3 * r.chosen_seconds)
            } else {
                "-".into()
            },
            cheapest
                .as_ref()
                .map_or("none on the ladder".into(), |c| c.0.clone()),
            cheapest
                .as_ref()
                .map_or("-".into(), |c| format!("{:.2}", 1e3 * c.1)),
            cheapest
                .as_ref()
                .map_or("-".into(), |c| format!("{:.2}", r.chosen_seconds / c.1)),
        ]);
    }
    table
}

/// The rows of `methods` and `targets` on `case`, and the case's reference.
pub fn case_rows(
    case: &TargetCase,
    methods: &[Method],
    targets: &[f64],
) -> Result<(TargetReference, Vec<TargetRow>), TableError> {
    let rod = build_rod(&case.spec)?;
    let reference = reference(&rod)?;
    let mut rows = Vec::new();
    for &method in methods {
        let targets: Vec<f64> = targets
            .iter()
            .copied()
            .filter(|t| targets_of(method).contains(t))
            .collect();
        let finest = targets.iter().copied().fold(f64::INFINITY, f64::min);
        let scanned = scan(&rod, method, &reference, finest)?;
        for target in targets {
            rows.push(target_row(&rod, method, target, &reference, &scanned)?);
        }
    }
    Ok((reference, rows))
}

/// Every case of [`target_cases`] with every method of [`METHODS`] and target of
/// [`TARGETS`]: a line per case with its reference's uncertainty, and the table.
pub fn accuracy_targets() -> Result<(String, Table), TableError> {
    let mut notes = String::new();
    let mut table = target_table("", &[]);
    for case in target_cases() {
        let (reference, rows) = case_rows(&case, &METHODS, &TARGETS)?;
        notes += &format!(
            "- {}: the reference's own error {:.0e}\n",
            case.name, reference.uncertainty
        );
        table.rows.extend(target_table(case.name, &rows).rows);
    }
    Ok((notes, table))
}

/// `ssn compare --accuracy`: each method applicable to `structure` (the LCP and penalty HB
/// only with contact) solved at the discretisation its own search chose for `target`,
/// without a reference (`base` gives the rest of the settings), one line each: the choice,
/// whether the estimate met the target, the estimate, the change of the tip minimum
/// against `reference_tip_min` (the study's error, for comparison) and the search's wall
/// time.
pub fn self_chosen_lines(
    structure: &semismooth_contact::model::Structure,
    omega: f64,
    base: &SolverSettings,
    target: f64,
    reference_tip_min: f64,
    skipped: &[(Method, String)],
) -> Result<String, semismooth_contact::solve::RunError> {
    let contact = !structure.model.contacts.is_empty();
    let mut out = String::new();
    for method in METHODS {
        if !contact && method.needs_contact() {
            continue;
        }
        if skipped.iter().any(|(m, _)| *m == method) {
            out += &format!("  {:<11} skipped: does not apply\n", method.name());
            continue;
        }
        let settings = SolverSettings {
            method,
            accuracy: Some(target),
            ..base.clone()
        };
        let s = solve(structure, omega, &settings, None)?;
        let Some(search) = &s.search else { continue };
        let chosen = discretisation(method, &search.steps[search.chosen].discretisation);
        let estimate = s
            .error_estimate
            .as_ref()
            .map_or("none".into(), |e| format!("{:.1e}", e.relative));
        let tip_min_error = (s.stats.min - reference_tip_min).abs() / reference_tip_min.abs();
        out += &format!(
            "  {:<11} {:<18} {:<4} estimate {:<8} tip-min error {:.1e}  search {:.3} ms ({} solves)\n",
            method.name(),
            chosen,
            if search.met() { "met" } else { "not" },
            estimate,
            tip_min_error,
            1e3 * search.seconds,
            search.steps.len()
        );
    }
    Ok(out)
}
