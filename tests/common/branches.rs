//! Continuation test problems whose branches are known independently: a problem `F(x, p)`
//! from closures and the closed-form branches built from it (S-curve, circle, Duffing's
//! first harmonic, a kink, a plateau, a residual that ends in NaN), with the counters
//! identity every block-eliminated branch satisfies.

use faer::Mat;
use semismooth::continuation::{Branch, Continuation, ContinuationEvent, ContinuationOptions};
use semismooth::linalg::FaerDenseLu;
use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};

pub type ResidualFn = Box<dyn Fn(&[f64], f64, &mut [f64])>;
pub type JacobianFn = Box<dyn Fn(&[f64], f64, &mut Mat<f64>)>;

/// A test problem `F(x, p)` from closures, with an analytic `F_p` when given (the trait's
/// central difference otherwise), counting `set_parameter` calls.
pub struct Closure {
    pub n: usize,
    pub p: f64,
    pub f: ResidualFn,
    pub j: JacobianFn,
    pub fp: Option<ResidualFn>,
}

impl Residual for Closure {
    fn dim(&self) -> usize {
        self.n
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        (self.f)(x, self.p, out);
        Ok(())
    }
}

impl GeneralizedJacobian for Closure {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.n, self.n)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        (self.j)(x, self.p, jac);
        Ok(())
    }
}

impl ParameterDependent for Closure {
    fn parameter(&self) -> f64 {
        self.p
    }
    fn set_parameter(&mut self, p: f64) {
        self.p = p;
    }
    fn residual_parameter_derivative(
        &mut self,
        x: &[f64],
        out: &mut [f64],
        minus: &mut [f64],
    ) -> Result<(), EvaluationError> {
        match &self.fp {
            Some(fp) => fp(x, self.p, out),
            None => {
                let p = self.p;
                let h = 1e-7 * (1.0 + p.abs());
                (self.f)(x, p + h, out);
                (self.f)(x, p - h, minus);
                for (o, m) in out.iter_mut().zip(minus.iter()) {
                    *o = (*o - m) / (2.0 * h);
                }
            }
        }
        Ok(())
    }
}

/// The branch of `problem` from `(x0, p0)` with `options`, followed with the dense LU.
pub fn follow(problem: &mut Closure, x0: &[f64], p0: f64, options: ContinuationOptions) -> Branch {
    Continuation::new(problem, &mut FaerDenseLu::new(), x0, p0, options)
        .unwrap()
        .run()
}

/// The default continuation options over the parameter range `[min, max]`.
pub fn between(min: f64, max: f64) -> ContinuationOptions {
    ContinuationOptions {
        parameter_min: min,
        parameter_max: max,
        ..Default::default()
    }
}

/// The S-curve's fold parameter `2 / (3 √3)`.
pub const FOLD_S: f64 = 0.384_900_179_459_750_5;

/// `x^3 - x - p = 0`: folds at `x = ±1/√3`, `p = ∓2/(3√3)`.
pub fn s_curve() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0].powi(3) - x[0] - p),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

/// `x^2 + p^2 - 1 = 0`: folds at `p = ±1`.
pub fn circle() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0] * x[0] + p * p - 1.0),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 2.0 * x[0]),
        fp: Some(Box::new(|_, p, out| out[0] = 2.0 * p)),
    }
}

/// Duffing `u'' + 2 ζ u' + u + γ u^3 = f cos(ω t)`, one harmonic `u = a cos + b sin`,
/// parameter `ω`; `F_p` by the trait's central difference.
pub const ZETA: f64 = 0.05;
pub const GAMMA: f64 = 1.0;
pub const FORCE: f64 = 0.1;
pub fn duffing() -> Closure {
    Closure {
        n: 2,
        p: 0.0,
        f: Box::new(|x, w, out| {
            let k = 1.0 - w * w + 0.75 * GAMMA * (x[0] * x[0] + x[1] * x[1]);
            out[0] = k * x[0] + 2.0 * ZETA * w * x[1] - FORCE;
            out[1] = -2.0 * ZETA * w * x[0] + k * x[1];
        }),
        j: Box::new(|x, w, jac| {
            let (a, b) = (x[0], x[1]);
            let k = 1.0 - w * w + 0.75 * GAMMA * (a * a + b * b);
            let c = 1.5 * GAMMA;
            jac[(0, 0)] = k + c * a * a;
            jac[(0, 1)] = c * a * b + 2.0 * ZETA * w;
            jac[(1, 0)] = c * a * b - 2.0 * ZETA * w;
            jac[(1, 1)] = k + c * b * b;
        }),
        fp: None,
    }
}

/// `x + k max(0, x - 1) - p = 0`: slope 1 below the kink at `x = 1`, `1/(1+k)` above.
pub const KINK: f64 = 4.0;
pub fn kink() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0] + KINK * (x[0] - 1.0).max(0.0) - p),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 1.0 + if x[0] > 1.0 { KINK } else { 0.0 }),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

pub fn kink_closed_form(p: f64) -> f64 {
    if p <= 1.0 {
        p
    } else {
        1.0 + (p - 1.0) / (1.0 + KINK)
    }
}

/// `p - min(max(x, 0), 1) = 0`: `x = p` on `(0, 1)`, then the vertical segment `p = 1`,
/// `x > 1`, where the Jacobian is exactly zero (singular) and only the bordered system is
/// regular.
pub fn plateau() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = p - x[0].clamp(0.0, 1.0)),
        j: Box::new(|x, _, jac| jac[(0, 0)] = if x[0] > 0.0 && x[0] < 1.0 { -1.0 } else { 0.0 }),
        fp: Some(Box::new(|_, _, out| out[0] = 1.0)),
    }
}

/// `x - p = 0`, but the residual is NaN for `p > 1` (a model outside its domain).
pub fn ends_at_one() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = if p > 1.0 { f64::NAN } else { x[0] - p }),
        j: Box::new(|_, _, jac| jac[(0, 0)] = 1.0),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

pub fn fold_count(branch: &Branch) -> usize {
    branch
        .events
        .iter()
        .filter(|e| matches!(e, ContinuationEvent::Fold { .. }))
        .count()
}

/// The counters identity of the block elimination: one Jacobian and one factorization per
/// corrector iteration, two solves (`J a = F_p`, `J b = F`) per factorization.
pub fn assert_one_factorization_per_iteration(branch: &Branch) {
    let c = branch.counters;
    let accepted: u64 = branch.points.iter().map(|q| q.iterations as u64).sum();
    assert_eq!(c.corrector_iterations, accepted + c.rejected_iterations);
    assert_eq!(c.work.factorizations, c.corrector_iterations);
    assert_eq!(c.work.jacobian_evaluations, c.corrector_iterations);
    assert_eq!(c.parameter_derivative_evaluations, c.corrector_iterations);
    assert_eq!(c.work.linear_solves, 2 * c.work.factorizations);
    // Without line search: one residual per iteration plus the final convergence check of
    // each attempt that did not stop on a non-finite value.
    assert!(c.work.residual_evaluations >= c.corrector_iterations);
    assert_eq!(c.dense_bordered_factorizations, 0);
}
