//! The interface couplings of a cyclic sector whose right interface dofs were eliminated
//! ([`crate::cyclic`]): each coupling matrix enters harmonic `k` of the harmonic operator
//! with the coefficient of its source (`K`, `M` or `D`) times `e^{i sign k phi}`.

use super::{ContactRow, SparseMatrix};

/// Which source of the harmonic operator a coupling matrix follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CouplingSource {
    /// Coefficient 1.
    Stiffness,
    /// Coefficient `-(k w)^2 - i k w xi`.
    Mass,
    /// Coefficient `i k w`.
    Damping,
}

impl CouplingSource {
    /// The index of the source in the operator's `[K, M, D]`.
    pub(crate) fn index(self) -> usize {
        match self {
            Self::Stiffness => 0,
            Self::Mass => 1,
            Self::Damping => 2,
        }
    }
}

/// One coupling matrix: `matrix` enters harmonic `k` as `c_source(k) e^{i sign k phi}`.
#[derive(Debug, Clone)]
pub struct CouplingTerm {
    /// The source whose coefficient it takes.
    pub source: CouplingSource,
    /// `N x N`, on the model's dofs.
    pub matrix: SparseMatrix,
    /// `+1` or `-1`.
    pub sign: f64,
}

/// The phase-shifted interface couplings of a reduced cyclic sector: harmonic `k` of the
/// operator is `Z_k = sum_s c_s(k) A_s + sum_t c_t(k) e^{i sign_t k phi} B_t`.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CyclicCoupling {
    /// The inter-sector phase `phi = 2 pi EO / N` of harmonic 1.
    pub phase_step: f64,
    /// The number of sectors `N` of the disk.
    pub sectors: usize,
    /// The coupling matrices.
    pub terms: Vec<CouplingTerm>,
    /// The rows of `G` that also take the next sector's dofs (contacts between sectors).
    pub neighbour_rows: Vec<NeighbourRow>,
}

/// The part of one row of `G` on the next sector's dofs: the row measures
/// `g . u(t) + n . u_next(t)` with `u_next(t) = u(t - EO T / N)`, so harmonic `k` of the
/// neighbour's dofs is this sector's rotated by `k phi` (`e^{-i k phi}` on `a - i b`), and
/// the force `lambda` acts on the next sector through `n^T` (on this sector's dofs, the
/// previous sector's force: rotated back, `e^{+i k phi}`).
#[derive(Debug, Clone, PartialEq)]
pub struct NeighbourRow {
    /// The row's index in [`super::StructuralModel::rows`] (contacts, friction points,
    /// frictional contacts' rows).
    pub row: usize,
    /// The coefficients on the next sector's dofs (numbered as this sector's).
    pub part: ContactRow,
}

impl CyclicCoupling {
    /// The couplings `terms` of a disk of `sectors` sectors with the phase `phase_step` per
    /// harmonic.
    pub fn new(phase_step: f64, sectors: usize, terms: Vec<CouplingTerm>) -> Self {
        Self {
            phase_step,
            sectors,
            terms,
            neighbour_rows: Vec::new(),
        }
    }

    /// The couplings with the rows `neighbour_rows` between this sector and the next.
    pub fn with_neighbour_rows(mut self, neighbour_rows: Vec<NeighbourRow>) -> Self {
        self.neighbour_rows = neighbour_rows;
        self
    }

    /// The amplitude `max_t |u_s(t)|` of one dof in every sector `s = 0..N` from its
    /// harmonic coefficients in sector 0 (`[u_0, a_1, b_1, ..., a_H, b_H]`), sector `s`
    /// delayed by `s EO T / N`, sampled at `samples` instants of the period.
    pub fn sector_amplitudes(&self, coefficients: &[f64], samples: usize) -> Vec<f64> {
        let samples = samples.max(1);
        let phases: Vec<f64> = (0..samples)
            .map(|n| 2.0 * std::f64::consts::PI * n as f64 / samples as f64)
            .collect();
        (0..self.sectors)
            .map(|s| {
                (self.sector_series(coefficients, s, &phases).iter())
                    .fold(0.0f64, |m, u| m.max(u.abs()))
            })
            .collect()
    }

    /// One dof's displacement in sector `sector` at the phases `theta = omega t` (radians)
    /// from its harmonic coefficients in sector 0 (`[u_0, a_1, b_1, ..., a_H, b_H]`):
    /// `u_s(t) = u_0(t - s EO T / N)`, i.e. harmonic `k` at the angle `k (theta - s phi)`.
    pub fn sector_series(&self, coefficients: &[f64], sector: usize, phases: &[f64]) -> Vec<f64> {
        let harmonics = coefficients.len().saturating_sub(1) / 2;
        let constant = coefficients.first().copied().unwrap_or(0.0);
        let delay = sector as f64 * self.phase_step;
        (phases.iter())
            .map(|theta| {
                (1..=harmonics).fold(constant, |u, k| {
                    let angle = k as f64 * (theta - delay);
                    let (a, b) = (coefficients[2 * k - 1], coefficients[2 * k]);
                    u + a * angle.cos() + b * angle.sin()
                })
            })
            .collect()
    }
}
