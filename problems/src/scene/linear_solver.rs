//! The `[solver] linear_solver` choice.

use serde::Deserialize;

/// Linear solver for the Newton systems of the harmonic-balance methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum LinearSolverChoice {
    /// Condensation onto the contact unknowns (per-harmonic sparse factorizations); the
    /// condensed SSN-HB system is factored dense up to
    /// [`KRYLOV_THRESHOLD`](crate::hb::KRYLOV_THRESHOLD) unknowns `m (2H + 1)` and solved
    /// matrix-free by GMRES above.
    #[default]
    Structured,
    /// Condensation with the condensed system always factored dense.
    CondensedDense,
    /// Condensation with the condensed SSN-HB system always solved matrix-free (GMRES).
    CondensedKrylov,
    /// Dense LU of the full Jacobian (for checking; cubic in the model size).
    Dense,
}

impl LinearSolverChoice {
    /// The scene's name of the choice (`linear_solver = "..."`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Structured => "structured",
            Self::CondensedDense => "condensed-dense",
            Self::CondensedKrylov => "condensed-krylov",
            Self::Dense => "dense",
        }
    }

    /// The condensed solve of the structured choices (`None` for the dense full LU).
    pub fn condensed(self) -> Option<crate::hb::CondensedSolve> {
        use crate::hb::CondensedSolve;
        match self {
            Self::Structured => Some(CondensedSolve::Auto),
            Self::CondensedDense => Some(CondensedSolve::Dense),
            Self::CondensedKrylov => Some(CondensedSolve::Krylov),
            Self::Dense => None,
        }
    }
}
