//! Mesh sequencing for the semismooth Newton method on the periodic LCP: coarse levels
//! first, each finer level warm-started by the interpolated coarser solution.

use semismooth::newton::{self, NewtonError, NewtonOptions, NewtonReport};

use super::{ActiveSetSolver, LcpError, PeriodicLcp, PeriodicLcpOptions, MIN_LCP_TIME_SAMPLES};
use crate::model::StructuralModel;

impl PeriodicLcp {
    /// Periodic linear interpolation of a contact-force history `z_other` of another
    /// discretisation (time-major, `m Nt'` entries for any `Nt' >= 1`) onto this LCP's
    /// nodes: a warm start for semismooth Newton (mesh sequencing). On the canonical rod
    /// with the modified mass, Newton from `z = 0` needs 13 / 64 / 126 / 282 iterations at
    /// `Nt` = 128 / 256 / 512 / 1024 (the active set creeps), from the interpolated coarser
    /// solution 5 to 8 up to `Nt = 1024`.
    pub fn interpolate_forces(&self, z_other: &[f64]) -> Result<Vec<f64>, LcpError> {
        let m = self.contacts;
        if z_other.is_empty() || z_other.len() % m != 0 {
            return Err(LcpError::WrongLength {
                what: "z_other (a positive multiple of the contact count)",
                expected: self.dim(),
                found: z_other.len(),
            });
        }
        let other = z_other.len() / m;
        let mut z = vec![0.0; self.dim()];
        for n in 0..self.nt {
            let position = n as f64 * other as f64 / self.nt as f64;
            let left = (position.floor() as usize).min(other - 1);
            let fraction = position - left as f64;
            let right = (left + 1) % other;
            for c in 0..m {
                z[n * m + c] =
                    (1.0 - fraction) * z_other[left * m + c] + fraction * z_other[right * m + c];
            }
        }
        Ok(z)
    }
}

/// Coarsest `Nt` of [`solve_min_map_sequenced`]'s level sequence.
pub const SEQUENCING_COARSEST_TIME_SAMPLES: usize = 128;

/// One level of [`solve_min_map_sequenced`].
#[derive(Debug, Clone, PartialEq)]
pub struct SequencingLevel {
    /// `Nt` of the level.
    pub time_samples: usize,
    /// The Newton run on that level.
    pub report: NewtonReport,
}

/// Result of [`solve_min_map_sequenced`]: the finest LCP, its solution and every level.
#[derive(Debug, Clone)]
pub struct SequencedSolution {
    /// The LCP at the requested `Nt`.
    pub lcp: PeriodicLcp,
    /// Best iterate on the finest level (the solution when its report converged).
    pub z: Vec<f64>,
    /// Levels from coarsest to finest; the last one is the requested `Nt`.
    pub levels: Vec<SequencingLevel>,
}

impl SequencedSolution {
    /// `true` when Newton converged on the finest level.
    pub fn converged(&self) -> bool {
        self.levels.last().is_some_and(|l| l.report.converged())
    }

    /// Newton iterations summed over the levels.
    pub fn total_iterations(&self) -> usize {
        self.levels.iter().map(|l| l.report.iterations).sum()
    }
}

/// Semismooth Newton on `min(z, q + A z) = 0` by mesh sequencing (method `"lcp-ssn"`
/// at large `Nt`): the LCP is solved at `Nt / 2^j` (halving while even and not below
/// [`SEQUENCING_COARSEST_TIME_SAMPLES`]) from `z = 0`, then each finer level starts from
/// the previous solution interpolated in time ([`PeriodicLcp::interpolate_forces`]), with
/// the [`ActiveSetSolver`]. A level that does not converge still passes its best iterate
/// on; `Ok` whenever every level ran (check [`SequencedSolution::converged`]).
///
/// Why: with a damped massless contact node the high-frequency receptances tend to 0, so
/// `A` is ill-conditioned and from `z = 0` the active set creeps one node at a time (on
/// the canonical rod with the modified mass: 13 / 64 / 126 / 282 iterations at
/// `Nt = 128 .. 1024` with the default non-monotone line search, no convergence in 300 at
/// 2048); from the interpolated coarser solution 5 / 7 / 8 / 42 iterations.
pub fn solve_min_map_sequenced(
    model: &StructuralModel,
    options: PeriodicLcpOptions,
    newton_options: &NewtonOptions,
) -> Result<SequencedSolution, LcpError> {
    newton_options.validate()?;
    options.validate(model.contact_count(), model.dofs())?;
    let mut sizes = vec![options.time_samples];
    while let Some(&nt) = sizes.last() {
        if nt % 2 != 0 || nt / 2 < SEQUENCING_COARSEST_TIME_SAMPLES.max(MIN_LCP_TIME_SAMPLES) {
            break;
        }
        sizes.push(nt / 2);
    }
    sizes.reverse();
    let mut levels = Vec::with_capacity(sizes.len());
    let mut previous: Option<Vec<f64>> = None;
    let mut finest = None;
    for (index, &nt) in sizes.iter().enumerate() {
        let last = index + 1 == sizes.len();
        let level_options = PeriodicLcpOptions {
            time_samples: nt,
            observed_dofs: if last {
                options.observed_dofs.clone()
            } else {
                Vec::new()
            },
        };
        let lcp = PeriodicLcp::new(model, level_options)?;
        let mut z = match &previous {
            Some(coarse) => lcp.interpolate_forces(coarse)?,
            None => vec![0.0; lcp.dim()],
        };
        let report = {
            let mut problem = lcp.min_map();
            let mut solver = ActiveSetSolver::new();
            newton::solve(&mut problem, &mut solver, &mut z, newton_options)
                .or_else(NewtonError::into_report)?
        };
        levels.push(SequencingLevel {
            time_samples: nt,
            report,
        });
        if last {
            finest = Some(lcp);
        }
        previous = Some(z);
    }
    Ok(SequencedSolution {
        lcp: finest.expect("at least one level"),
        z: previous.expect("at least one level"),
        levels,
    })
}
