//! The peak of a frequency response located between its branch points.
//!
//! A branch point is where the continuation's step happened to land, so the largest
//! amplitude among the points lies below the peak by up to the curvature times the step
//! squared. Where the branch is a graph over `ω` around its largest point (no fold between
//! the point and its neighbours), the amplitude `A(ω)` has a maximum bracketed by the
//! neighbours, located by a parabolic search with golden-section steps as the fallback
//! (Brent's scheme for a maximum), each evaluation a solve at fixed `ω` warm-started from
//! the nearest point already solved. A peak at the first or last point lies at the edge of
//! the computed branch (the window may cut it off); one at a fold is the fold's point.

use crate::model::Structure;
use crate::settings::SolverSettings;
use crate::solve::solve;

use super::{FrequencyResponse, StateRecovery};
use crate::hb::HbError;

/// Largest number of solves the search spends on one peak.
pub const MAX_PEAK_SOLVES: usize = 40;

/// The search stops when the bracket is narrower than this, in units of `ω_1`.
pub const PEAK_BRACKET: f64 = 1e-5;

/// Where the largest amplitude of a branch is, and how it was found.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct LocatedPeak {
    /// Frequency `ω` (absolute) of the peak.
    pub omega: f64,
    /// `max_t |u(t)|` of the observed dof there.
    pub amplitude: f64,
    /// Solves spent on the search (0 when not searched).
    pub solves: usize,
    /// How the peak relates to the branch points.
    pub location: PeakLocation,
}

/// How a peak was found.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum PeakLocation {
    /// Located between the branch points, to [`PEAK_BRACKET`] `ω_1` in frequency.
    Located,
    /// The largest amplitude is the first or last point of the branch: the peak may lie
    /// beyond the computed branch.
    AtEdge,
    /// The largest amplitude is at a fold of the branch (the frequency turns back there).
    AtFold,
    /// The search stopped: the largest branch point is reported, with the reason.
    NotLocated(String),
}

/// A bracketing point of the search: frequency, amplitude, the solve's unknowns.
struct Sample {
    omega: f64,
    amplitude: f64,
    state: Vec<f64>,
}

/// The peak of `response` (computed with `settings` on `structure`), located between the
/// branch points where the branch is a graph over `ω` there; `None` for an empty branch.
pub fn locate_peak(
    structure: &Structure,
    settings: &SolverSettings,
    response: &FrequencyResponse,
) -> Option<LocatedPeak> {
    let (i, amplitude) = response.peak()?;
    let points = &response.points;
    let unsearched = |location| LocatedPeak {
        omega: points[i].omega,
        amplitude,
        solves: 0,
        location,
    };
    if i == 0 || i + 1 == points.len() {
        return Some(unsearched(PeakLocation::AtEdge));
    }
    let [wa, wb, wc] = [i - 1, i, i + 1].map(|k| points[k].omega);
    if (wb - wa) * (wc - wb) <= 0.0 {
        return Some(unsearched(PeakLocation::AtFold));
    }
    let same_discretisation = [i - 1, i + 1]
        .iter()
        .all(|&k| points[k].harmonics == points[i].harmonics);
    if !same_discretisation {
        return Some(unsearched(PeakLocation::NotLocated(
            "the neighbouring points have other harmonics".into(),
        )));
    }
    let mut states = StateRecovery::new(structure, settings, response);
    let mut sample = |k: usize| -> Result<Sample, HbError> {
        Ok(Sample {
            omega: points[k].omega,
            amplitude: points[k].amplitude,
            state: states.state(k)?.into_owned(),
        })
    };
    let samples = (sample(i - 1), sample(i), sample(i + 1));
    let (Ok(a), Ok(b), Ok(c)) = samples else {
        let reason = "a neighbouring point's state could not be recovered".into();
        return Some(unsearched(PeakLocation::NotLocated(reason)));
    };
    let settings = SolverSettings {
        estimate_error: false,
        ..response.point_settings(settings, i)
    };
    let (a, c) = if a.omega < c.omega { (a, c) } else { (c, a) };
    Some(search(structure, &settings, [a, b, c], response.omega_1))
}

/// Brent's search for the maximum of `A(ω)` in the bracket `a < b < c`, `A(b) >= A(a),
/// A(c)`.
fn search(
    structure: &Structure,
    settings: &SolverSettings,
    [mut a, mut b, mut c]: [Sample; 3],
    omega_1: f64,
) -> LocatedPeak {
    let mut solves = 0;
    let result = |b: &Sample, solves, location| LocatedPeak {
        omega: b.omega,
        amplitude: b.amplitude,
        solves,
        location,
    };
    while c.omega - a.omega > PEAK_BRACKET * omega_1 {
        if solves == MAX_PEAK_SOLVES {
            let reason = format!("{MAX_PEAK_SOLVES} solves did not narrow the bracket");
            return result(&b, solves, PeakLocation::NotLocated(reason));
        }
        let omega = next_trial(&a, &b, &c);
        let start = if (omega - a.omega).abs() < (omega - c.omega).abs() {
            nearer(&a, &b, omega)
        } else {
            nearer(&c, &b, omega)
        };
        solves += 1;
        let trial = match solve(structure, omega, settings, Some(start)) {
            Ok(s) if s.converged() => Sample {
                omega,
                amplitude: s.stats.max.abs().max(s.stats.min.abs()),
                state: s.state,
            },
            Ok(s) => {
                let reason = format!(
                    "the solve at omega = {omega} did not converge ({})",
                    s.termination
                );
                return result(&b, solves, PeakLocation::NotLocated(reason));
            }
            Err(e) => return result(&b, solves, PeakLocation::NotLocated(e.to_string())),
        };
        // Keep a bracket around the larger amplitude.
        if trial.amplitude >= b.amplitude {
            if trial.omega < b.omega {
                c = std::mem::replace(&mut b, trial);
            } else {
                a = std::mem::replace(&mut b, trial);
            }
        } else if trial.omega < b.omega {
            a = trial;
        } else {
            c = trial;
        }
    }
    result(&b, solves, PeakLocation::Located)
}

/// The warm start of a solve at `omega`: the state of whichever of `x`, `b` is nearer.
fn nearer<'a>(x: &'a Sample, b: &'a Sample, omega: f64) -> &'a [f64] {
    if (omega - x.omega).abs() < (omega - b.omega).abs() {
        &x.state
    } else {
        &b.state
    }
}

/// The next trial frequency: the vertex of the parabola through the three samples when it
/// lies well inside the bracket, else the golden section of the larger side.
fn next_trial(a: &Sample, b: &Sample, c: &Sample) -> f64 {
    const GOLDEN: f64 = 0.381_966_011_250_105_1;
    let (p, q) = (
        (b.omega - a.omega) * (b.amplitude - c.amplitude),
        (b.omega - c.omega) * (b.amplitude - a.amplitude),
    );
    let denominator = 2.0 * (p - q);
    let width = c.omega - a.omega;
    if denominator != 0.0 {
        let vertex = b.omega - ((b.omega - a.omega) * p - (b.omega - c.omega) * q) / denominator;
        // Well inside, and not on b itself (which would not shrink the bracket).
        let margin = 0.01 * width;
        if vertex > a.omega + margin
            && vertex < c.omega - margin
            && (vertex - b.omega).abs() > 0.001 * width
        {
            return vertex;
        }
    }
    if b.omega - a.omega > c.omega - b.omega {
        b.omega - GOLDEN * (b.omega - a.omega)
    } else {
        b.omega + GOLDEN * (c.omega - b.omega)
    }
}
