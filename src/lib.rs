//! # semismooth
//!
//! A problem-agnostic toolkit for nonsmooth equations `F(x) = 0` where `F` is Lipschitz
//! but not everywhere differentiable (it contains `max`/`min` of smooth pieces), as
//! arising from complementarity and unilateral-contact problems.
//!
//! The crate separates three things:
//! - the **problem**: a [`Residual`] and an element of its generalized (Clarke/B-)
//!   Jacobian, [`GeneralizedJacobian`], written into the problem's own matrix type;
//! - the **linear algebra**: [`LinearSolve`] factors a Jacobian once and solves many
//!   right-hand sides (Newton step, continuation tangent, bordered solves);
//! - the **drivers**: semismooth Newton with line-search globalization, pseudo-arclength
//!   continuation, Lemke's algorithm for linear complementarity problems.
//!
//! Nothing in this crate knows about rods, contact or any particular model: those live
//! in the `semismooth-problems` crate, which uses only this crate's public API.

pub mod complementarity;
pub mod continuation;
pub mod harmonic;
pub mod lemke;
pub mod linalg;
pub mod linesearch;
pub mod newton;
mod traits;

pub use traits::{
    EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent,
    ProblemCounters, Residual, MAX_PROBLEM_COUNTERS,
};

/// The linear-algebra crates of the public API (matrix types of Jacobians, sparse
/// patterns): use these re-exports so that a problem's matrices are the versions the
/// solvers expect.
pub use faer;
pub use nalgebra;
