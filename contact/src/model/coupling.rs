//! The interface couplings of a cyclic sector whose right interface dofs were eliminated
//! ([`crate::cyclic`]): each coupling matrix enters harmonic `k` of the harmonic operator
//! with the coefficient of its source (`K`, `M` or `D`) times `e^{i sign k phi}`.

use super::SparseMatrix;

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
    /// The coupling matrices.
    pub terms: Vec<CouplingTerm>,
}

impl CyclicCoupling {
    /// The couplings `terms` with the phase `phase_step` per harmonic.
    pub fn new(phase_step: f64, terms: Vec<CouplingTerm>) -> Self {
        Self { phase_step, terms }
    }
}
