//! Harmonics chosen point by point along a branch against the fixed harmonics that reach
//! the same worst error: the `adaptive-sweeps` section of docs/sweeps.md and
//! `examples/adaptive_sweep.rs`.
//!
//! For a rod and a target, the SSN-HB sweep over `[0.5, 2] ω_1` with `[solver] accuracy`
//! (stability off) is compared point by point with a reference that follows the same
//! solution: the point taken up by SSN-HB at [`REFERENCE_RATIO`] times the sweep's largest
//! harmonics (at least [`REFERENCE_HARMONICS`]) on the hyperplane
//! through it normal to the sweep's secant there ([`take_up`]; at its frequency where that
//! fails), so that near a fold, where the two discretisations' branches turn at different
//! frequencies, the point is compared with the nearest point of the reference's branch, not
//! with whatever solution the reference has at its frequency. A point's error is the
//! distance [`point_distance`] from its reference, as its estimate is. The fixed harmonics
//! reaching the adaptive sweep's worst error are found on the same points: for each rung
//! of the ladder in turn, every reference is taken up at that rung the same way, and the
//! first rung whose worst error is at most the adaptive sweep's is swept whole, in the same
//! run, for its cost.

use semismooth_contact::hb::resize_harmonics;
use semismooth_contact::model::Structure;
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::solve::{solve, RunError};
use semismooth_contact::sweep::adaptive::{point_distance, secant, take_up, HARMONICS_LADDER};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

/// A point's reference: its state, frequency, the observed dof's extremes and the
/// secant it was taken up across (at the reference's harmonics).
struct Reference {
    state: Vec<f64>,
    omega: f64,
    extremes: (f64, f64),
    secant: Vec<f64>,
}

/// Fewest harmonics of the reference solves.
pub const REFERENCE_HARMONICS: usize = 320;

/// The reference has at least this many times the adaptive sweep's largest harmonics, so
/// that its own error (order 0.75 in `H`: at most `4^-0.75`, 35 %, of a point's) does
/// not hide the points' errors.
pub const REFERENCE_RATIO: usize = 4;

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
    /// Harmonics of the references.
    pub reference_harmonics: usize,
    /// Error of each point against its reference (NaN where the reference did not
    /// converge).
    pub errors: Vec<f64>,
    /// Estimate of each point (NaN where none).
    pub estimates: Vec<f64>,
    /// Wall time of the adaptive sweep (its estimates included).
    pub seconds: f64,
    /// The fixed harmonics reaching the adaptive sweep's worst error on its points, their
    /// worst error there, and their whole sweep's points, folds (`ω / ω_1`) and wall time;
    /// `None` when no rung up to a [`REFERENCE_RATIO`]th of the reference's reaches it.
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

/// The largest finite value of `values` (0 when none).
fn largest_finite(values: &[f64]) -> f64 {
    values
        .iter()
        .copied()
        .filter(|e| e.is_finite())
        .fold(0.0, f64::max)
}

impl AdaptiveComparison {
    /// The largest error over the points with a reference.
    pub fn worst_error(&self) -> f64 {
        largest_finite(&self.errors)
    }

    /// The largest estimate.
    pub fn worst_estimate(&self) -> f64 {
        largest_finite(&self.estimates)
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

    /// The largest ratio of a point's estimate to its error (above 1: the estimate was
    /// high), over the same points as [`Self::worst_underestimate`].
    pub fn worst_overestimate(&self) -> f64 {
        self.errors
            .iter()
            .zip(&self.estimates)
            .filter(|(e, s)| e.is_finite() && s.is_finite() && **e > 0.01 * self.target)
            .map(|(e, s)| s / e)
            .fold(0.0, f64::max)
    }

    /// Wall time of the adaptive sweep over that of the fixed one.
    pub fn cost_ratio(&self) -> Option<f64> {
        self.fixed.as_ref().map(|f| self.seconds / f.seconds)
    }
}

/// A solution taken up across a branch: its state and `(max, min, ω)` (the observed
/// dof's extremes and the frequency).
type TakenUp = (Vec<f64>, (f64, f64, f64));

/// The solution at `h` harmonics of the SSN-HB branch of `rod` through `(x, ω)` at `from`
/// harmonics across `secant` ([`take_up`]): its extremes and frequency, `None` when
/// neither way converged.
fn taken_up(
    rod: &Structure,
    sweep: &SweepSettings,
    (x, omega, from): (&[f64], f64, usize),
    secant: &[f64],
    h: usize,
) -> Result<Option<TakenUp>, RunError> {
    let settings = SolverSettings {
        estimate_error: false,
        ..SolverSettings::with_harmonics(h)
    };
    let Some((state, at)) = take_up(rod, &settings, sweep, (x, omega, from), secant, h)? else {
        return Ok(None);
    };
    // The extremes as `ssn solve` reports them: a solve from the point, at its frequency,
    // converging at once.
    let solved = solve(rod, at, &settings, Some(&state))?;
    let extremes = (solved.stats.max, solved.stats.min, at);
    Ok(solved.converged().then_some((solved.state, extremes)))
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
    let point_harmonics = adaptive.harmonics();
    say(&format!(
        "adaptive sweep: {} points, harmonics {:?}, {:.2} s, {}",
        adaptive.points.len(),
        point_harmonics,
        adaptive.solve_seconds,
        crate::words::sweep_termination(&adaptive)
    ));
    let reference_harmonics = REFERENCE_HARMONICS
        .max(REFERENCE_RATIO * point_harmonics.iter().copied().max().unwrap_or(0));
    say(&format!("references at {reference_harmonics} harmonics"));
    let (references, errors) = reference_points(rod, &sweep, &adaptive, reference_harmonics)?;
    let estimates: Vec<f64> = adaptive
        .accuracy
        .as_ref()
        .map(|_| adaptive.column(|p| p.error_estimate.unwrap_or(f64::NAN)))
        .unwrap_or_default();
    let harmonics = (
        point_harmonics.iter().copied().min().unwrap_or(0),
        point_harmonics.iter().copied().max().unwrap_or(0),
    );
    let mean_harmonics =
        point_harmonics.iter().sum::<usize>() as f64 / adaptive.points.len().max(1) as f64;
    let mut comparison = AdaptiveComparison {
        target,
        points: adaptive.points.len(),
        converged: adaptive.converged(),
        termination: crate::words::sweep_termination(&adaptive),
        omega_ratio: adaptive.omega_ratio(),
        point_harmonics,
        folds: adaptive.folds.iter().map(|w| w / w1).collect(),
        harmonics,
        mean_harmonics,
        reference_harmonics,
        errors,
        estimates,
        seconds: adaptive.solve_seconds,
        fixed: None,
    };
    let worst = comparison.worst_error();
    comparison.fixed = fixed_sweep(rod, &sweep, (&references, reference_harmonics), worst, &say)?;
    Ok(comparison)
}

/// Each point of `adaptive` taken up across the branch at `reference_harmonics` (`None`
/// where neither way converged), and its error against it (NaN there).
fn reference_points(
    rod: &Structure,
    sweep: &SweepSettings,
    adaptive: &FrequencyResponse,
    reference_harmonics: usize,
) -> Result<(Vec<Option<Reference>>, Vec<f64>), RunError> {
    let (dofs, rows) = (rod.model.dofs(), rod.model.row_count());
    let mut references: Vec<Option<Reference>> = Vec::with_capacity(adaptive.points.len());
    let mut errors = Vec::with_capacity(adaptive.points.len());
    for (i, p) in adaptive.points.iter().enumerate() {
        let h = p.harmonics.unwrap_or(0);
        let secant = secant(adaptive, i, dofs, rows);
        let point = (p.state.as_slice(), p.omega, h);
        match taken_up(rod, sweep, point, &secant, reference_harmonics)? {
            Some((state, (max, min, omega))) => {
                let here = (p.observed_max, p.observed_min, p.omega);
                errors.push(point_distance(here, (max, min, omega)));
                let n = secant.len() - 1;
                let mut lifted = resize_harmonics(&secant[..n], h, reference_harmonics, dofs, rows);
                lifted.push(secant[n]);
                references.push(Some(Reference {
                    state,
                    omega,
                    extremes: (max, min),
                    secant: lifted,
                }));
            }
            None => {
                errors.push(f64::NAN);
                references.push(None);
            }
        }
    }
    Ok((references, errors))
}

/// The first fixed harmonics of the ladder (below the references') whose worst error on
/// the `references` (at `reference_harmonics`) is at most `worst`, swept over `sweep`;
/// `None` when none is.
fn fixed_sweep(
    rod: &Structure,
    sweep: &SweepSettings,
    (references, reference_harmonics): (&[Option<Reference>], usize),
    worst: f64,
    say: &dyn Fn(&str),
) -> Result<Option<FixedSweep>, RunError> {
    for &h in HARMONICS_LADDER
        .iter()
        .filter(|&&h| REFERENCE_RATIO * h <= reference_harmonics)
    {
        say(&format!("fixed H = {h} on the adaptive points"));
        let mut fixed_worst = 0.0f64;
        for reference in references.iter().flatten() {
            let point = (
                reference.state.as_slice(),
                reference.omega,
                reference_harmonics,
            );
            let (max, min) = reference.extremes;
            let error = match taken_up(rod, sweep, point, &reference.secant, h)? {
                Some((_, at)) => point_distance(at, (max, min, reference.omega)),
                None => f64::INFINITY,
            };
            fixed_worst = fixed_worst.max(error);
            if fixed_worst > worst {
                break;
            }
        }
        if fixed_worst <= worst {
            say(&format!("fixed H = {h} sweep"));
            let fixed_settings = SolverSettings {
                estimate_error: false,
                ..SolverSettings::with_harmonics(h)
            };
            let fixed = frequency_response(rod, &fixed_settings, sweep, None)?;
            return Ok(Some(FixedSweep {
                harmonics: h,
                worst_error: fixed_worst,
                points: fixed.points.len(),
                folds: fixed.folds.iter().map(|w| w / rod.omega_1).collect(),
                seconds: fixed.solve_seconds,
            }));
        }
    }
    Ok(None)
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

/// [`paper_rod`] forced five times as hard (`p0 = 0.2`): contact strong over the whole
/// resonance, a wide overhang.
pub fn strongly_forced_rod() -> Result<semismooth_contact::rod::RodModel, RunError> {
    use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
    Ok(build_rod(&RodSpec {
        mass: MassModel::Modified,
        amplitude: 0.2,
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
