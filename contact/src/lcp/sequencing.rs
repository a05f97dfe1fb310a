//! Mesh sequencing for the semismooth Newton method on the periodic LCP: coarse levels
//! first, each finer level warm-started by the interpolated coarser solution.

use semismooth::newton::NewtonReport;
use semismooth::polyalgorithm::{SmoothingOf, SolveOptions};

use super::{
    ActiveSetSolver, LcpError, PeriodicLcp, PeriodicLcpOptions, DEFAULT_ACTIVE_SET_REGULARIZATION,
    MIN_LCP_TIME_SAMPLES,
};
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
        Ok(interpolate_periodic(z_other, m, self.nt))
    }
}

/// A time-major history of `m` series over one period (`m Nt'` entries, `Nt' >= 1`)
/// interpolated linearly and periodically onto `nt` equally spaced nodes (`m nt` entries):
/// node `n` sits at `n Nt' / nt` of the given nodes.
pub fn interpolate_periodic(z_other: &[f64], m: usize, nt: usize) -> Vec<f64> {
    let other = z_other.len() / m.max(1);
    let mut z = vec![0.0; m * nt];
    if other == 0 {
        return z;
    }
    for n in 0..nt {
        let position = n as f64 * other as f64 / nt as f64;
        let left = (position.floor() as usize).min(other - 1);
        let fraction = position - left as f64;
        let right = (left + 1) % other;
        for c in 0..m {
            z[n * m + c] =
                (1.0 - fraction) * z_other[left * m + c] + fraction * z_other[right * m + c];
        }
    }
    z
}

/// Coarsest `Nt` of [`solve_min_map_sequenced`]'s level sequence.
pub(crate) const SEQUENCING_COARSEST_TIME_SAMPLES: usize = 128;

/// One level of [`solve_min_map_sequenced`].
#[derive(Debug, Clone, PartialEq)]
pub struct SequencingLevel {
    /// `Nt` of the level.
    pub time_samples: usize,
    /// The Newton run on that level.
    pub report: NewtonReport,
}

/// Result of [`solve_min_map_sequenced`]: the solution of the finest LCP (the caller's)
/// and every level.
#[derive(Debug, Clone)]
pub struct SequencedSolution {
    /// Best iterate on the finest level (the solution when its report converged).
    pub z: Vec<f64>,
    /// Levels from coarsest to finest; the last one is the finest LCP's `Nt`.
    pub levels: Vec<SequencingLevel>,
}

impl SequencedSolution {
    /// `true` when Newton converged on the finest level.
    pub fn converged(&self) -> bool {
        self.levels.last().is_some_and(|l| l.report.converged())
    }
}

/// Semismooth Newton on `min(z, q + A z) = 0` of `finest` by mesh sequencing (method
/// `"lcp-ssn"` at large `Nt`): the LCP of `model` forced at `omega` is solved at `Nt / 2^j`
/// (halving while
/// even and not below `SEQUENCING_COARSEST_TIME_SAMPLES`) from `z = 0` (offering the
/// polyalgorithm the min-map's smoothing, [`super::MinMapLcp`]'s `Smoothing`), then each finer
/// level starts from the previous solution interpolated in time
/// ([`PeriodicLcp::interpolate_forces`]); the last level is `finest` itself (built by the
/// caller, with whatever observed dofs it needs; only the coarser levels are built here).
/// The linear solver is the [`ActiveSetSolver`] regularised by
/// [`DEFAULT_ACTIVE_SET_REGULARIZATION`], so that a singular first Jacobian (every node
/// in contact at `z = 0`) does not stop the run. A level that does not converge still
/// passes its best iterate on; `Ok` whenever every level ran (check
/// [`SequencedSolution::converged`]). `finest` must be an LCP of `model` at `omega`
/// ([`LcpError::ForeignLcp`] otherwise).
///
/// Why: with a damped massless contact node the high-frequency receptances tend to 0, so
/// `A` is ill-conditioned and from `z = 0` the active set creeps one node at a time (on
/// the canonical rod with the modified mass: 13 / 64 / 126 / 282 iterations at
/// `Nt = 128 .. 1024` with the default non-monotone line search, no convergence in 300 at
/// 2048); from the interpolated coarser solution 5 / 7 / 8 / 42 iterations.
pub fn solve_min_map_sequenced(
    model: &StructuralModel,
    omega: f64,
    finest: &PeriodicLcp,
    newton_options: &SolveOptions,
) -> Result<SequencedSolution, LcpError> {
    newton_options.validate()?;
    check_same_model(model, omega, finest)?;
    // The coarser levels, finest first: Nt / 2, Nt / 4, ... (the finest is the caller's).
    let mut sizes = Vec::new();
    let mut nt = finest.time_samples();
    while nt % 2 == 0 && nt / 2 >= SEQUENCING_COARSEST_TIME_SAMPLES.max(MIN_LCP_TIME_SAMPLES) {
        nt /= 2;
        sizes.push(nt);
    }
    sizes.reverse();
    let mut solver =
        ActiveSetSolver::new().with_regularization(DEFAULT_ACTIVE_SET_REGULARIZATION)?;
    let mut levels = Vec::with_capacity(sizes.len() + 1);
    let mut z: Option<Vec<f64>> = None;
    let mut solve_level = |lcp: &PeriodicLcp, previous: Option<Vec<f64>>| {
        // The level started from zero offers the smoothing path to the polyalgorithm; the
        // finer ones start near their solution.
        let (mut z, smoothing) = match &previous {
            Some(coarse) => (lcp.interpolate_forces(coarse)?, None),
            None => (vec![0.0; lcp.dim()], Some(SmoothingOf::new())),
        };
        let mut problem = lcp.min_map();
        let report = newton_options.solve(&mut problem, &mut solver, &mut z, smoothing)?;
        levels.push(SequencingLevel {
            time_samples: lcp.time_samples(),
            report,
        });
        Ok::<_, LcpError>(z)
    };
    for nt in sizes {
        let options = PeriodicLcpOptions {
            time_samples: nt,
            observed_dofs: Vec::new(),
            scheme: finest.scheme(),
        };
        z = Some(solve_level(&PeriodicLcp::new(model, omega, options)?, z)?);
    }
    let z = solve_level(finest, z)?;
    Ok(SequencedSolution { z, levels })
}

/// `Err(ForeignLcp)` unless `lcp` was built for `model` at `omega` (same frequency and
/// contacts).
fn check_same_model(
    model: &StructuralModel,
    omega: f64,
    lcp: &PeriodicLcp,
) -> Result<(), LcpError> {
    let foreign = |what, lcp: f64, model: f64| Err(LcpError::ForeignLcp { what, lcp, model });
    if lcp.omega() != omega {
        return foreign("omega", lcp.omega(), omega);
    }
    if lcp.contact_count() != model.contact_count() {
        let (a, b) = (lcp.contact_count(), model.contact_count());
        return foreign("contact count", a as f64, b as f64);
    }
    for ((&dof, gap), c) in lcp
        .contact_dofs()
        .iter()
        .zip(lcp.gaps())
        .zip(&model.contacts)
    {
        if dof != c.dof() {
            return foreign("contact dof", dof as f64, c.dof() as f64);
        }
        if *gap != c.gap {
            return foreign("contact gap", *gap, c.gap);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::{build_rod, MassModel, RodSpec};

    #[test]
    fn the_finest_lcp_must_be_the_models() {
        let mut spec = RodSpec::canonical();
        spec.mass = MassModel::Modified;
        let rod = build_rod(&spec).unwrap();
        let (model, omega) = (&rod.model, rod.omega());
        let options = PeriodicLcpOptions {
            time_samples: 16,
            ..Default::default()
        };
        let lcp = PeriodicLcp::new(model, omega, options).unwrap();
        let newton = SolveOptions::default();
        let solved = solve_min_map_sequenced(model, omega, &lcp, &newton).unwrap();
        // Nt = 16 is below the coarsest level: one level, the caller's LCP.
        assert_eq!(solved.levels.len(), 1);
        assert_eq!(solved.levels[0].time_samples, 16);
        assert_eq!(solved.z.len(), lcp.dim());
        // Nt = 512: 128, 256, then the caller's 512.
        let options = PeriodicLcpOptions {
            time_samples: 512,
            ..Default::default()
        };
        let fine = PeriodicLcp::new(model, omega, options).unwrap();
        let solved = solve_min_map_sequenced(model, omega, &fine, &newton).unwrap();
        let sizes: Vec<usize> = solved.levels.iter().map(|l| l.time_samples).collect();
        assert_eq!(sizes, [128, 256, 512]);
        assert!(solved.converged());
        assert_eq!(
            solve_min_map_sequenced(model, 2.0 * omega, &lcp, &newton).unwrap_err(),
            LcpError::ForeignLcp {
                what: "omega",
                lcp: omega,
                model: 2.0 * omega
            }
        );
        let mut other = model.clone();
        other.contacts[0].gap = 0.25;
        assert!(matches!(
            solve_min_map_sequenced(&other, omega, &lcp, &newton),
            Err(LcpError::ForeignLcp {
                what: "contact gap",
                ..
            })
        ));
    }
}
