//! The canonical modified-mass rod's steady period by the time-marching reference, and the
//! quantities read off one period of a sampled periodic signal (last sample = first). Shared
//! by the time-marching tests and the `time_marching_reference` example.

use std::time::Instant;

use semismooth_contact::march::{march_to_steady_state, MarchOptions, SteadyPeriod};
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};

/// The canonical rod with the modified (massless tip) mass.
pub fn modified_rod() -> RodModel {
    build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })
    .unwrap()
}

/// The steady period of the canonical modified-mass rod at `spp` steps per period (tip
/// observed) and the seconds it took.
pub fn canonical_modified_period(spp: usize, tolerance: f64) -> (SteadyPeriod, f64) {
    let rod = modified_rod();
    let options = MarchOptions {
        steps_per_period: spp,
        tolerance,
        ..MarchOptions::default()
    };
    let start = Instant::now();
    let period =
        march_to_steady_state(&rod.model, rod.omega(), &options, &[rod.tip_dof()]).unwrap();
    (period, start.elapsed().as_secs_f64())
}

/// `(min, max)` of the samples.
pub fn extremes(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        })
}

/// Minimum of a periodic sampled signal, refined by the parabola through the smallest
/// sample and its neighbours (removes the O(h^2) sampling error).
pub fn parabolic_min(x: &[f64]) -> f64 {
    let n = x.len() - 1;
    let i = (0..n).min_by(|&a, &b| x[a].total_cmp(&x[b])).unwrap();
    let (a, b, c) = (x[(i + n - 1) % n], x[i], x[(i + 1) % n]);
    let curvature = a - 2.0 * b + c;
    if curvature > 0.0 {
        b - (c - a) * (c - a) / (8.0 * curvature)
    } else {
        b
    }
}

/// Mean over one period of a periodic sampled signal (trapezoidal rule).
pub fn period_mean(x: &[f64]) -> f64 {
    x.windows(2).map(|w| 0.5 * (w[0] + w[1])).sum::<f64>() / (x.len() - 1) as f64
}

/// Root mean square over one period (trapezoidal rule).
pub fn period_rms(x: &[f64]) -> f64 {
    period_mean(&x.iter().map(|v| v * v).collect::<Vec<_>>()).sqrt()
}
