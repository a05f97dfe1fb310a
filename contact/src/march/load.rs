//! The load at the step times `t_j = j T / s` of one period (`s` steps per period), for
//! the schemes' right-hand sides: `f cos(w t)` through the tabulated `cos(w t_j)` (the
//! march's arithmetic since it was written), any other [`HarmonicLoad`] evaluated at each
//! step into kept buffers (no allocation per step).

use std::f64::consts::PI;

use crate::model::HarmonicLoad;

/// The sampled load of a march (module documentation).
#[derive(Debug)]
pub(super) enum SampledLoad {
    /// `f cos(w t)`: the amplitude `f` and `cos(w t_j)`, `j = 0..=s + 1` (`j + 1` is read
    /// at `j = s` too).
    Cosine {
        amplitude: Vec<f64>,
        cosines: Vec<f64>,
    },
    /// Any other load, with `f(t_j)` and `f(t_{j+1})` buffers.
    General {
        load: HarmonicLoad,
        steps: usize,
        at: Vec<f64>,
        next: Vec<f64>,
    },
}

impl SampledLoad {
    /// The load of a march with `steps` steps per period.
    pub(super) fn new(load: &HarmonicLoad, steps: usize) -> Self {
        match load.as_cosine() {
            Some(amplitude) => Self::Cosine {
                amplitude,
                cosines: (0..=steps + 1)
                    .map(|j| (2.0 * PI * j as f64 / steps as f64).cos())
                    .collect(),
            },
            None => Self::General {
                load: load.clone(),
                steps,
                at: vec![0.0; load.dofs()],
                next: vec![0.0; load.dofs()],
            },
        }
    }

    /// `out = scale (weight_next f(t_{j+1}) + weight f(t_j))`.
    pub(super) fn write(
        &mut self,
        j: usize,
        (weight, weight_next): (f64, f64),
        scale: f64,
        out: &mut [f64],
    ) {
        match self {
            Self::Cosine { amplitude, cosines } => {
                let f = weight_next * cosines[j + 1] + weight * cosines[j];
                for (o, a) in out.iter_mut().zip(amplitude.iter()) {
                    *o = scale * f * a;
                }
            }
            Self::General {
                load,
                steps,
                at,
                next,
            } => {
                let phase = |j: usize| 2.0 * PI * j as f64 / *steps as f64;
                load.at_phase(phase(j), at);
                load.at_phase(phase(j + 1), next);
                for ((o, a), b) in out.iter_mut().zip(at.iter()).zip(next.iter()) {
                    *o = scale * (weight_next * b + weight * a);
                }
            }
        }
    }
}
