//! Harmonics chosen point by point along a branch against the fixed harmonics that reach
//! the same worst error: the `adaptive-sweeps` section of docs/sweeps.md and
//! `examples/adaptive_sweep.rs`.
//!
//! For a rod and a target, the SSN-HB sweep over `[0.5, 2] ω_1` with `[solver] accuracy`
//! (stability off) is compared point by point with a reference: SSN-HB at
//! [`REFERENCE_HARMONICS`] solved at the point's frequency from the point lifted (so on
//! the same branch inside an overhang). A point's error is the largest change of the
//! observed dof's extremes relative to the reference's largest excursion, as its estimate
//! is. The fixed harmonics reaching the adaptive sweep's worst error are found on the
//! same points: for each rung of the ladder in turn, every point is solved at that rung
//! from its reference truncated, and the first rung whose worst error is at most the
//! adaptive sweep's is swept whole, in the same run, for its cost.

use semismooth_contact::hb::resize_harmonics;
use semismooth_contact::model::Structure;
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::solve::{solve, RunError};
use semismooth_contact::sweep::adaptive::HARMONICS_LADDER;
use semismooth_contact::sweep::frequency_response;

/// A point's reference: its state and the observed dof's extremes.
type Reference = (Vec<f64>, (f64, f64));

/// Harmonics of the reference solves.
pub const REFERENCE_HARMONICS: usize = 320;

/// One adaptive sweep against its references and against the fixed harmonics.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveComparison {
    /// The target.
    pub target: f64,
    /// Points of the adaptive sweep.
    pub points: usize,
    /// Whether the adaptive sweep reached the end of its range.
    pub converged: bool,
    /// Why it stopped (the words of `ssn sweep`).
    pub termination: String,
    /// `ω / ω_1` of each point.
    pub omega_ratio: Vec<f64>,
    /// Harmonics of each point.
    pub point_harmonics: Vec<usize>,
    /// Folds of the adaptive sweep (`ω / ω_1`).
    pub folds: Vec<f64>,
    /// Smallest and largest harmonics of its points.
    pub harmonics: (usize, usize),
    /// Mean harmonics over the points.
    pub mean_harmonics: f64,
    /// Error of each point against its reference (NaN where the reference did not
    /// converge).
    pub errors: Vec<f64>,
    /// Estimate of each point (NaN where none).
    pub estimates: Vec<f64>,
    /// Wall time of the adaptive sweep (its estimates included).
    pub seconds: f64,
    /// The fixed harmonics reaching the adaptive sweep's worst error on its points, their
    /// worst error there, and their whole sweep's points, folds (`ω / ω_1`) and wall time;
    /// `None` when no rung up to the reference's half reaches it.
    pub fixed: Option<FixedSweep>,
}

/// The fixed-harmonics sweep of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedSweep {
    /// Its harmonics.
    pub harmonics: usize,
    /// Its worst error on the adaptive sweep's points.
    pub worst_error: f64,
    /// Points of its sweep.
    pub points: usize,
    /// Folds of its sweep (`ω / ω_1`).
    pub folds: Vec<f64>,
    /// Wall time of its sweep.
    pub seconds: f64,
}

impl AdaptiveComparison {
    /// The largest error over the points with a reference.
    pub fn worst_error(&self) -> f64 {
        self.errors
            .iter()
            .copied()
            .filter(|e| e.is_finite())
            .fold(0.0, f64::max)
    }

    /// The largest estimate.
    pub fn worst_estimate(&self) -> f64 {
        self.estimates
            .iter()
            .copied()
            .filter(|e| e.is_finite())
            .fold(0.0, f64::max)
    }

    /// Points whose error meets the target.
    pub fn met(&self) -> usize {
        self.errors.iter().filter(|e| **e <= self.target).count()
    }

    /// The largest ratio of a point's error to its estimate (above 1: the estimate was
    /// low), over the points whose error exceeds a hundredth of the target (below, both
    /// are round-off).
    pub fn worst_underestimate(&self) -> f64 {
        self.errors
            .iter()
            .zip(&self.estimates)
            .filter(|(e, s)| e.is_finite() && s.is_finite() && **e > 0.01 * self.target)
            .map(|(e, s)| e / s.max(f64::MIN_POSITIVE))
            .fold(0.0, f64::max)
    }

    /// Wall time of the adaptive sweep over that of the fixed one.
    pub fn cost_ratio(&self) -> Option<f64> {
        self.fixed.as_ref().map(|f| self.seconds / f.seconds)
    }
}

/// The relative error of extremes `(max, min)` against the reference's.
fn displacement_error((max, min): (f64, f64), (ref_max, ref_min): (f64, f64)) -> f64 {
    let excursion = ref_max.abs().max(ref_min.abs());
    let change = (max - ref_max).abs().max((min - ref_min).abs());
    if change == 0.0 {
        0.0
    } else if excursion > 0.0 {
        change / excursion
    } else {
        f64::INFINITY
    }
}

/// The comparison of the module documentation for `rod` and `target`; `say` hears of each
/// stage.
pub fn compare_adaptive(
    rod: &Structure,
    target: f64,
    say: Option<&dyn Fn(&str)>,
) -> Result<AdaptiveComparison, RunError> {
    let say = |line: &str| {
        if let Some(say) = say {
            say(line)
        }
    };
    let sweep = SweepSettings {
        stability: false,
        ..SweepSettings::new(0.5, 2.0)
    };
    let settings = SolverSettings {
        accuracy: Some(target),
        ..SolverSettings::default()
    };
    say("adaptive sweep");
    let adaptive = frequency_response(rod, &settings, &sweep, None)?;
    let w1 = rod.omega_1;
    say(&format!(
        "adaptive sweep: {} points, harmonics {:?}, {:.2} s, {}",
        adaptive.points(),
        adaptive.harmonics,
        adaptive.solve_seconds,
        crate::words::sweep_termination(&adaptive)
    ));
    let model = &rod.model;
    let (dofs, contacts) = (model.dofs(), model.contact_count());
    // The references and the fixed-harmonics solves estimate no error of their own.
    let fixed_at = |h: usize| SolverSettings {
        estimate_error: false,
        ..SolverSettings::with_harmonics(h)
    };
    let reference_settings = fixed_at(REFERENCE_HARMONICS);
    say("references");
    // Each point's reference state and extremes.
    let mut references: Vec<Option<Reference>> = Vec::with_capacity(adaptive.points());
    let mut errors = Vec::with_capacity(adaptive.points());
    for i in 0..adaptive.points() {
        let h = adaptive.harmonics[i];
        let start = resize_harmonics(&adaptive.states[i], h, REFERENCE_HARMONICS, dofs, contacts);
        let reference = solve(rod, adaptive.omega[i], &reference_settings, Some(&start))?;
        if reference.converged() {
            let extremes = (reference.stats.max, reference.stats.min);
            errors.push(displacement_error(
                (adaptive.tip_max[i], adaptive.tip_min[i]),
                extremes,
            ));
            references.push(Some((reference.state, extremes)));
        } else {
            errors.push(f64::NAN);
            references.push(None);
        }
    }
    let estimates: Vec<f64> = adaptive
        .accuracy
        .as_ref()
        .map(|a| a.estimates.iter().map(|e| e.unwrap_or(f64::NAN)).collect())
        .unwrap_or_default();
    let harmonics = (
        adaptive.harmonics.iter().copied().min().unwrap_or(0),
        adaptive.harmonics.iter().copied().max().unwrap_or(0),
    );
    let mean_harmonics =
        adaptive.harmonics.iter().sum::<usize>() as f64 / adaptive.points().max(1) as f64;
    let mut comparison = AdaptiveComparison {
        target,
        points: adaptive.points(),
        converged: adaptive.converged(),
        termination: crate::words::sweep_termination(&adaptive),
        omega_ratio: adaptive.omega_ratio(),
        point_harmonics: adaptive.harmonics.clone(),
        folds: adaptive.folds.iter().map(|w| w / w1).collect(),
        harmonics,
        mean_harmonics,
        errors,
        estimates,
        seconds: adaptive.solve_seconds,
        fixed: None,
    };
    let worst = comparison.worst_error();
    for &h in HARMONICS_LADDER
        .iter()
        .filter(|&&h| 2 * h <= REFERENCE_HARMONICS)
    {
        say(&format!("fixed H = {h} on the adaptive points"));
        let fixed_settings = fixed_at(h);
        let mut fixed_worst = 0.0f64;
        for (i, reference) in references.iter().enumerate() {
            let Some((reference, extremes)) = reference else {
                continue;
            };
            let start = resize_harmonics(reference, REFERENCE_HARMONICS, h, dofs, contacts);
            let at = solve(rod, adaptive.omega[i], &fixed_settings, Some(&start))?;
            let error = if at.converged() {
                displacement_error((at.stats.max, at.stats.min), *extremes)
            } else {
                f64::INFINITY
            };
            fixed_worst = fixed_worst.max(error);
            if fixed_worst > worst {
                break;
            }
        }
        if fixed_worst <= worst {
            say(&format!("fixed H = {h} sweep"));
            let fixed = frequency_response(rod, &fixed_settings, &sweep, None)?;
            comparison.fixed = Some(FixedSweep {
                harmonics: h,
                worst_error: fixed_worst,
                points: fixed.points(),
                folds: fixed.folds.iter().map(|w| w / w1).collect(),
                seconds: fixed.solve_seconds,
            });
            break;
        }
    }
    Ok(comparison)
}

/// The paper's rod with the massless contact node (Fig. 1 and 2's forcing `p0 = 0.04`, gap
/// 0.5, modified mass: with a massive contact node harmonic balance does not converge in
/// `H` and the error against `H = 320` is not defined).
pub fn paper_rod() -> Result<semismooth_contact::rod::RodModel, RunError> {
    use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
    Ok(build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })?)
}

/// The rods and targets of the docs' table: [`paper_rod`] for 1e-2 and 1e-3, labelled.
pub fn study(say: Option<&dyn Fn(&str)>) -> Result<Vec<(String, AdaptiveComparison)>, RunError> {
    let paper = paper_rod()?;
    let mut rows = Vec::new();
    for target in [1e-2, 1e-3] {
        rows.push((
            "paper's rod".to_string(),
            compare_adaptive(&paper, target, say)?,
        ));
    }
    Ok(rows)
}
