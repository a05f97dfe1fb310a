//! The crate's one error type: every reason a function of this crate could not run, each
//! kind the module's own typed error with the numbers that explain it.
//!
//! Functions return their module's error (a [`NewtonError`], a [`LemkeError`], ...); a
//! caller that runs several of them converts each into [`Error`] with `?`:
//!
//! ```
//! use semismooth::linalg::LinearSolveError;
//! use semismooth::Error;
//!
//! fn factor_twice() -> Result<(), Error> {
//!     Err(LinearSolveError::NotFactored)?;
//!     Ok(())
//! }
//! let error = factor_twice().unwrap_err();
//! assert!(matches!(error, Error::LinearSolve(LinearSolveError::NotFactored)));
//! assert_eq!(error.to_string(), LinearSolveError::NotFactored.to_string());
//! ```

use crate::complementarity::InvalidComplementarityConstant;
use crate::continuation::ContinuationError;
use crate::floquet::FloquetError;
use crate::harmonic::HarmonicError;
use crate::lemke::LemkeError;
use crate::linalg::LinearSolveError;
use crate::newton::NewtonError;
use crate::{EvaluationError, InvalidOption};

/// Any error of this crate; the message is the wrapped error's.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An option outside its allowed range.
    #[error(transparent)]
    InvalidOption(#[from] InvalidOption),
    /// A factorization or a solve could not be carried out.
    #[error(transparent)]
    LinearSolve(#[from] LinearSolveError),
    /// A problem could not be evaluated.
    #[error(transparent)]
    Evaluation(#[from] EvaluationError),
    /// Newton's method could not run.
    #[error(transparent)]
    Newton(#[from] NewtonError),
    /// A continuation could not run.
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
    /// Lemke's algorithm could not run.
    #[error(transparent)]
    Lemke(#[from] LemkeError),
    /// A Fourier basis or transform could not be set up.
    #[error(transparent)]
    Harmonic(#[from] HarmonicError),
    /// Floquet multipliers could not be computed.
    #[error(transparent)]
    Floquet(#[from] FloquetError),
    /// A complementarity function's constant is not allowed.
    #[error(transparent)]
    ComplementarityConstant(#[from] InvalidComplementarityConstant),
}
