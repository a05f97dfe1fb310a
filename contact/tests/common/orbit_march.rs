//! Time marching from a periodic orbit: the march's state and distances between states,
//! shared by the stability tests.

use semismooth_contact::march::{MarchOptions, MarchScheme, TimeMarcher};

/// The state `(u, v / omega)` of a march.
pub fn snapshot(m: &TimeMarcher, omega: f64) -> Vec<f64> {
    m.displacement()
        .iter()
        .copied()
        .chain(m.velocity().iter().map(|v| v / omega))
        .collect()
}

/// Euclidean distance of two states.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Moreau–Jean (`theta = 1/2`) with `steps_per_period` steps and the impact law's
/// `restitution`.
pub fn moreau_jean(steps_per_period: usize, restitution: f64) -> MarchOptions {
    MarchOptions {
        steps_per_period,
        scheme: MarchScheme::MoreauJean {
            theta: 0.5,
            restitution,
        },
        ..MarchOptions::default()
    }
}
