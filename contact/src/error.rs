//! The crate's one error type: every reason a function of this crate could not run. Each
//! module keeps its own typed error (an [`HbError`], an [`ImportError`], ...); [`Error`]
//! wraps them all, and the core's errors through [`semismooth::Error`], so that a caller
//! that builds a model, a formulation and a run in a row writes `?` on each:
//!
//! ```
//! use semismooth_contact::hb::{HbOptions, SsnHb};
//! use semismooth_contact::rod::{build_rod, RodSpec};
//! use semismooth_contact::Error;
//!
//! fn harmonic_balance(harmonics: usize) -> Result<usize, Error> {
//!     let rod = build_rod(&RodSpec::canonical())?;
//!     let options = HbOptions { harmonics, ..HbOptions::default() };
//!     Ok(SsnHb::new(&rod.model, rod.omega(), &options)?.dofs())
//! }
//! assert!(harmonic_balance(5).is_ok());
//! assert!(matches!(harmonic_balance(0), Err(Error::HarmonicBalance(_))));
//! ```

use crate::builder::StructureError;
use crate::hb::HbError;
use crate::lcp::LcpError;
use crate::march::MarchError;
use crate::matrix_market::ImportError;
use crate::model::{InvalidModel, InvalidRow};
use crate::rod::ModelError;
use crate::stability::{PhaseError, StabilityError};

/// Any error of this crate; the message is the wrapped error's, except for the two kinds
/// that belong to a run itself ([`Error::InvalidSetting`], [`Error::Unsupported`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The rod could not be built, or a model's natural frequencies not computed.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A structural model is not usable (sizes, non-finite data, contacts).
    #[error(transparent)]
    InvalidModel(#[from] InvalidModel),
    /// A row of `G` is not usable.
    #[error(transparent)]
    InvalidRow(#[from] InvalidRow),
    /// A structure could not be built from its model.
    #[error(transparent)]
    Structure(#[from] StructureError),
    /// An imported model's files could not be read or assembled.
    #[error(transparent)]
    Import(#[from] ImportError),
    /// The harmonic-balance problem could not be built.
    #[error(transparent)]
    HarmonicBalance(#[from] HbError),
    /// The periodic LCP could not be built.
    #[error(transparent)]
    Lcp(#[from] LcpError),
    /// Lemke's algorithm could not run.
    #[error(transparent)]
    Lemke(#[from] semismooth::lemke::LemkeError),
    /// Newton's method could not run.
    #[error(transparent)]
    Newton(#[from] semismooth::newton::NewtonError),
    /// The continuation could not run (an error the sweep settings do not name).
    #[error(transparent)]
    Continuation(semismooth::continuation::ContinuationError),
    /// Time marching could not run (or did not reach a steady state).
    #[error(transparent)]
    March(#[from] MarchError),
    /// Stability could not be computed.
    #[error(transparent)]
    Stability(#[from] StabilityError),
    /// The contact phases of a solution could not be located.
    #[error(transparent)]
    Phases(#[from] PhaseError),
    /// Any other error of the core (a linear solve, a Fourier basis, Floquet multipliers).
    #[error(transparent)]
    Core(#[from] semismooth::Error),
    /// A run setting (e.g. a `sweep.*` field) is outside its allowed range.
    #[error("invalid {name} = {value}: allowed {allowed}")]
    InvalidSetting {
        /// Which setting (the scene's field name).
        name: &'static str,
        /// The value received.
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
    /// The method needs something the scene does not declare.
    #[error("method {method} needs {what}")]
    Unsupported {
        /// The method.
        method: &'static str,
        /// What is missing.
        what: &'static str,
    },
}

/// The core errors that have no variant of their own go through [`Error::Core`].
macro_rules! through_core {
    ($($error:ty),*) => {$(
        impl From<$error> for Error {
            fn from(error: $error) -> Self {
                Self::Core(error.into())
            }
        }
    )*};
}

through_core!(
    semismooth::linalg::LinearSolveError,
    semismooth::harmonic::HarmonicError,
    semismooth::floquet::FloquetError,
    semismooth::EvaluationError,
    semismooth::InvalidOption
);

/// What kind of failure an [`Error`] is, for callers that react by kind (the program's exit
/// codes, the Python package's exception classes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The input (a model, an option, a setting) is not usable: change it.
    InvalidInput,
    /// A matrix of the problem is singular, e.g. the dynamic stiffness of an undamped model
    /// forced at one of its natural frequencies ([`Error::linear_solve`] holds the pivot).
    SingularMatrix,
    /// The computation could not be carried out for another reason.
    Failed,
}

impl Error {
    /// The kind of this error ([`ErrorKind`]).
    pub fn kind(&self) -> ErrorKind {
        use semismooth::Error as Core;
        if matches!(
            self.linear_solve(),
            Some(semismooth::linalg::LinearSolveError::Singular { .. })
        ) {
            return ErrorKind::SingularMatrix;
        }
        match self {
            Error::InvalidSetting { .. }
            | Error::Unsupported { .. }
            | Error::InvalidModel(_)
            | Error::InvalidRow(_)
            | Error::Import(_)
            | Error::Structure(StructureError::Invalid(_))
            | Error::Core(Core::InvalidOption(_) | Core::ComplementarityConstant(_))
            | Error::HarmonicBalance(
                HbError::InvalidOption(_)
                | HbError::Model(_)
                | HbError::Unsupported { .. }
                | HbError::IndexOutOfRange { .. }
                | HbError::DimensionMismatch { .. }
                | HbError::Harmonic(_),
            )
            | Error::Lcp(LcpError::InvalidOption(_) | LcpError::Unsupported { .. })
            | Error::March(MarchError::InvalidOption(_))
            | Error::Stability(StabilityError::InvalidOption { .. })
            | Error::Newton(_) => ErrorKind::InvalidInput,
            _ => ErrorKind::Failed,
        }
    }

    /// The failed factorization or solve behind this error, if there is one.
    pub fn linear_solve(&self) -> Option<&semismooth::linalg::LinearSolveError> {
        use semismooth::linalg::LinearSolveError;
        if let Error::Core(semismooth::Error::LinearSolve(e)) = self {
            return Some(e);
        }
        // Transparent variants hand on their inner error's source: the chain below `self`.
        let mut source = std::error::Error::source(self);
        while let Some(e) = source {
            if let Some(linear) = e.downcast_ref::<LinearSolveError>() {
                return Some(linear);
            }
            source = e.source();
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use semismooth::linalg::LinearSolveError;

    const SINGULAR: LinearSolveError = LinearSolveError::Singular {
        index: 3,
        pivot: 0.0,
        max_pivot: 2.0,
    };

    #[test]
    fn a_singular_pivot_is_found_through_every_layer_that_wraps_it() {
        for error in [
            Error::from(SINGULAR),
            Error::from(HbError::Linear(SINGULAR)),
            Error::from(StabilityError::Hb(HbError::Linear(SINGULAR))),
        ] {
            assert_eq!(error.linear_solve(), Some(&SINGULAR), "{error:?}");
            assert_eq!(error.kind(), ErrorKind::SingularMatrix, "{error:?}");
        }
    }

    #[test]
    fn options_and_settings_out_of_range_are_invalid_input_and_other_failures_are_not() {
        let option = semismooth::InvalidOption::new("c", -1.0, "c > 0");
        assert_eq!(Error::from(option).kind(), ErrorKind::InvalidInput);
        assert_eq!(
            Error::from(HbError::InvalidOption(option)).kind(),
            ErrorKind::InvalidInput
        );
        let not_factored = Error::from(HbError::Linear(LinearSolveError::NotFactored));
        assert_eq!(not_factored.kind(), ErrorKind::Failed);
        assert_eq!(
            not_factored.linear_solve(),
            Some(&LinearSolveError::NotFactored)
        );
    }
}
