//! The three core traits: a residual, one element of its generalized Jacobian, and a
//! linear solver that factors a Jacobian once and solves many right-hand sides.

use crate::linalg::LinearSolveError;

/// A square system `F(x) = 0`, `F: R^n -> R^n`, Lipschitz continuous.
///
/// Evaluation fills a caller-owned buffer and may use problem-owned workspace (hence
/// `&mut self`), so that repeated evaluations allocate nothing.
///
/// ```
/// use semismooth::Residual;
/// /// F(x) = x^2 - 2 on R^1.
/// struct Sqrt2;
/// impl Residual for Sqrt2 {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], out: &mut [f64]) { out[0] = x[0] * x[0] - 2.0; }
/// }
/// let mut f = [0.0];
/// Sqrt2.residual(&[1.0], &mut f);
/// assert_eq!(f[0], -1.0);
/// ```
pub trait Residual {
    /// Number of unknowns `n` (and of equations).
    fn dim(&self) -> usize;

    /// Writes `F(x)` into `out` (both of length [`Residual::dim`]).
    fn residual(&mut self, x: &[f64], out: &mut [f64]);

    /// Number of fast Fourier transforms performed so far, for problems that count them
    /// (harmonic balance through alternating frequency/time); 0 otherwise.
    fn fft_count(&self) -> u64 {
        0
    }
}

/// One element `J` of the generalized Jacobian `∂F(x)` (Clarke or Bouligand), written
/// into the problem's own matrix type [`GeneralizedJacobian::Jacobian`] (dense, sparse or
/// structured), so that the linear solver can be chosen without touching the problem.
///
/// Where `F` is differentiable at `x`, `J` must be the ordinary Jacobian.
pub trait GeneralizedJacobian: Residual {
    /// The matrix type the Jacobian is written into.
    type Jacobian;

    /// Allocates a Jacobian of the right shape (called once per solve, not per iteration).
    fn new_jacobian(&self) -> Self::Jacobian;

    /// Writes an element of `∂F(x)` into `jac`.
    fn jacobian(&mut self, x: &[f64], jac: &mut Self::Jacobian);
}

/// A residual that depends on a scalar parameter `p` (a forcing frequency, a load
/// factor): `F(x, p)`. Needed by continuation.
pub trait ParameterDependent: Residual {
    /// Current value of the parameter.
    fn parameter(&self) -> f64;

    /// Sets the parameter used by subsequent evaluations.
    fn set_parameter(&mut self, p: f64);

    /// Writes `∂F/∂p (x, p)` into `out`.
    ///
    /// The default is a central finite difference with step `1e-7 (1 + |p|)`; problems
    /// with an analytic derivative should override it.
    fn residual_parameter_derivative(&mut self, x: &[f64], out: &mut [f64]) {
        let p = self.parameter();
        let h = 1e-7 * (1.0 + p.abs());
        let mut minus = vec![0.0; out.len()];
        self.set_parameter(p + h);
        self.residual(x, out);
        self.set_parameter(p - h);
        self.residual(x, &mut minus);
        self.set_parameter(p);
        for (o, m) in out.iter_mut().zip(&minus) {
            *o = (*o - m) / (2.0 * h);
        }
    }
}

/// Factor once, solve many: the linear-algebra half of a Newton step.
///
/// `factor` may be called again with a new matrix of the same shape; implementations
/// reuse their storage. `solve_in_place` overwrites `rhs` with `J^{-1} rhs` using the
/// most recent successful factorization.
pub trait LinearSolve<J: ?Sized> {
    /// Factors `jac`. A singular or non-finite matrix is a typed error.
    fn factor(&mut self, jac: &J) -> Result<(), LinearSolveError>;

    /// Solves `J x = rhs` in place with the last factorization.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError>;
}
