//! # semismooth
//!
//! A problem-agnostic toolkit for nonsmooth equations `F(x) = 0` where `F` is Lipschitz
//! but not everywhere differentiable (it contains `max`/`min` of smooth pieces), as
//! arising from complementarity and unilateral-contact problems.
//!
//! ```
//! use semismooth::faer::Mat;
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::newton::{solve, NewtonOptions};
//! use semismooth::{EvaluationError, GeneralizedJacobian, Residual};
//!
//! /// A spring of stiffness 2 pushed by a force 3 towards a wall at distance 1: the
//! /// displacement u and the wall's force l >= 0 satisfy 2 u + l = 3 and
//! /// min(l, 1 - u) = 0 (contact: u = 1, l = 1).
//! struct Spring;
//! impl Residual for Spring {
//!     fn dim(&self) -> usize { 2 }
//!     fn residual(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
//!         f[0] = 2.0 * x[0] + x[1] - 3.0;
//!         f[1] = x[1].min(1.0 - x[0]);
//!         Ok(())
//!     }
//! }
//! impl GeneralizedJacobian for Spring {
//!     type Jacobian = Mat<f64>;
//!     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(2, 2) }
//!     fn jacobian(&mut self, x: &[f64], j: &mut Mat<f64>) -> Result<(), EvaluationError> {
//!         (j[(0, 0)], j[(0, 1)]) = (2.0, 1.0);
//!         // The min picks l where l <= 1 - u, else 1 - u: one element of the B-Jacobian.
//!         (j[(1, 0)], j[(1, 1)]) = if x[1] <= 1.0 - x[0] { (0.0, 1.0) } else { (-1.0, 0.0) };
//!         Ok(())
//!     }
//! }
//!
//! let mut x = [0.0, 0.0];
//! // Err only if the solver could not run (bad options, x of the wrong length).
//! let report = solve(&mut Spring, &mut FaerDenseLu::new(), &mut x, &NewtonOptions::default())
//!     .unwrap();
//! assert!(report.converged());
//! assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12);
//! assert!(report.iterations <= 3);
//! ```
//!
//! The crate separates three things:
//! - the **problem**: a [`Residual`] and an element of its generalized (Clarke/B-)
//!   Jacobian, [`GeneralizedJacobian`], written into the problem's own matrix type;
//! - the **linear algebra**: [`Factorize`] factors a Jacobian once and [`LinearSolve`]
//!   solves many right-hand sides with it (Newton step, continuation tangent, bordered
//!   solves);
//! - the **drivers**, in layers, each using only those below it:
//!   - one Newton iteration kernel with a pluggable direction and step rule (internal),
//!     the [`WorkCounters`](newton::WorkCounters) every driver keeps and the
//!     [`NewtonReport`](newton::NewtonReport) of a run;
//!   - [`newton`]: semismooth Newton with line-search globalization ([`newton::solve`]);
//!   - [`continuation`]: pseudo-arclength continuation (its corrector is the same kernel
//!     on the bordered system; trust ball, restarts, exact corners of piecewise-affine
//!     branches), a natural-parameter sweep and homotopy;
//!   - [`polyalgorithm`]: solving from a poor guess by Newton runs and continuation paths
//!     ([`polyalgorithm::solve`], and [`polyalgorithm::solve_smoothing`] for a problem that
//!     implements [`Smoothing`]);
//!
//!   and beside them Lemke's algorithm for linear complementarity problems ([`lemke`]),
//!   complementarity functions, the harmonic machinery (Fourier basis, AFT) and Floquet
//!   multipliers of a periodic orbit's monodromy matrix ([`floquet`]).
//!
//! Every driver returns `Err` only when it could not run (invalid options, inputs of the
//! wrong size); a run that ran returns its report, whose typed termination says why it
//! stopped.
//!
//! Nothing in this crate knows about rods, contact or any particular model: those live
//! in the `semismooth-contact` crate, which uses only this crate's public API.

pub mod complementarity;
pub mod continuation;
mod error;
pub mod floquet;
pub mod harmonic;
mod invalid_option;
mod iteration;
pub mod lemke;
pub mod linalg;
pub mod linesearch;
pub mod newton;
pub mod polyalgorithm;
mod traits;
pub mod trigonometric;

pub use error::Error;
pub use invalid_option::InvalidOption;
pub use traits::{
    EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent,
    ProblemCounters, Residual, Smoothing, MAX_PROBLEM_COUNTERS,
};

/// The linear-algebra crates of the public API (matrix types of Jacobians, sparse
/// patterns): use these re-exports so that a problem's matrices are the versions the
/// solvers expect.
pub use faer;
pub use nalgebra;
