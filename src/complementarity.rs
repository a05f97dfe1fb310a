//! Complementarity functions: scalar `phi(a, b)` whose zeros are exactly the solutions of
//! a complementarity condition, with one element of their generalized gradient.
//!
//! | function | formula | `phi(a, b) = 0` exactly when |
//! |---|---|---|
//! | [`min_function`] | `min(a, b)` | `a >= 0, b >= 0, a b = 0` |
//! | [`max_form`] | `a + max(0, c b - a)`, `c > 0` | `a <= 0, b <= 0, a b = 0` |
//! | [`fischer_burmeister`] | `sqrt(a^2 + b^2) - a - b` | `a >= 0, b >= 0, a b = 0` |
//!
//! The max form is the one of Shi & Legrand's semismooth harmonic balance (eq. (3)):
//! with `a = lambda` (contact force, `<= 0`) and `b = G u - g` (signed gap, `<= 0`),
//! `lambda + max(0, c (G u - g) - lambda) = 0` states the unilateral contact law; `c`
//! converts a length into a force and only affects globalization, not the solution.
//! For a sign convention `z >= 0, w >= 0` use `max_form(-z, -w, c)`.
//!
//! All three are piecewise smooth, hence semismooth (strongly: their pieces are
//! quadratic at most), which gives local Q-quadratic convergence of semismooth Newton
//! at a BD-regular solution (Qi & Sun 1993; De Luca, Facchinei & Kanzow 1996).
//!
//! At a kink each function returns one element of its Bouligand subdifferential (a limit
//! of gradients from one side), documented per function.

/// `phi(a, b)` and one element `(da, db)` of its generalized gradient at `(a, b)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhiValue {
    /// `phi(a, b)`.
    pub value: f64,
    /// Generalized partial derivative with respect to `a`.
    pub da: f64,
    /// Generalized partial derivative with respect to `b`.
    pub db: f64,
}

/// `min(a, b)`: zero exactly when `a >= 0, b >= 0, a b = 0`.
///
/// Gradient `(1, 0)` where `a < b`, `(0, 1)` where `a > b`; at the kink `a = b` the
/// element `(1, 0)` is returned (the limit from the side `a < b`).
///
/// ```
/// use semismooth::complementarity::min_function;
/// assert_eq!(min_function(0.0, 3.0).value, 0.0);
/// assert_eq!((min_function(2.0, -1.0).da, min_function(2.0, -1.0).db), (0.0, 1.0));
/// ```
pub fn min_function(a: f64, b: f64) -> PhiValue {
    if a <= b {
        PhiValue {
            value: a,
            da: 1.0,
            db: 0.0,
        }
    } else {
        PhiValue {
            value: b,
            da: 0.0,
            db: 1.0,
        }
    }
}

/// The paper's max form `a + max(0, c b - a)` (`c > 0`): zero exactly when
/// `a <= 0, b <= 0, a b = 0`.
///
/// With `s = c b - a`: gradient `(1, 0)` where `s < 0` (value `a`) and `(0, c)` where
/// `s > 0` (value `c b`); at the kink `s = 0` the element `(1, 0)` is returned, i.e. the
/// switch is `h = 1 if s > 0 else 0`, matching the AFT Jacobian `P diag(h) E`.
///
/// `c` is not checked here (it is a hot-loop function); a non-positive `c` changes the
/// zero set. Use [`ComplementarityFunction::max_form`] for a validated constant.
///
/// ```
/// use semismooth::complementarity::max_form;
/// // Open contact (force 0, gap -0.1) and closed contact (force -2, gap 0) are zeros.
/// assert_eq!(max_form(0.0, -0.1, 10.0).value, 0.0);
/// assert_eq!(max_form(-2.0, 0.0, 10.0).value, 0.0);
/// ```
pub fn max_form(a: f64, b: f64, c: f64) -> PhiValue {
    let s = c * b - a;
    if s > 0.0 {
        PhiValue {
            value: c * b,
            da: 0.0,
            db: c,
        }
    } else {
        PhiValue {
            value: a,
            da: 1.0,
            db: 0.0,
        }
    }
}

/// Fischer–Burmeister `sqrt(a^2 + b^2) - a - b`: zero exactly when `a >= 0, b >= 0,
/// a b = 0`.
///
/// Gradient `(a / r - 1, b / r - 1)` with `r = hypot(a, b) > 0`; at the kink
/// `(0, 0)` the element `(1/sqrt(2) - 1, 1/sqrt(2) - 1)` is returned (the limit along
/// the diagonal `a = b > 0`). `hypot` avoids overflow for large arguments, and the
/// value is computed as `-2 a b / (r + a + b)` where `a + b > 0` to avoid cancellation.
///
/// ```
/// use semismooth::complementarity::fischer_burmeister;
/// assert_eq!(fischer_burmeister(0.0, 5.0).value, 0.0);
/// assert!(fischer_burmeister(1.0, 1.0).value < 0.0);
/// ```
pub fn fischer_burmeister(a: f64, b: f64) -> PhiValue {
    let r = a.hypot(b);
    if r > 0.0 {
        // Where a + b > 0, `r - a - b` cancels; the equal form -2 a b / (r + a + b) does
        // not (so a zero is returned only where a = 0 or b = 0).
        let sum = a + b;
        let value = if sum > 0.0 {
            -2.0 * a * (b / (r + sum))
        } else {
            r - sum
        };
        PhiValue {
            value,
            da: a / r - 1.0,
            db: b / r - 1.0,
        }
    } else {
        let d = std::f64::consts::FRAC_1_SQRT_2 - 1.0;
        PhiValue {
            value: 0.0,
            da: d,
            db: d,
        }
    }
}

/// An invalid constant for a complementarity function.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("complementarity constant c = {value} is not allowed: c must be finite and > 0")]
pub struct InvalidComplementarityConstant {
    /// The rejected value.
    pub value: f64,
}

/// A choice of complementarity function, for problems that let the user pick one.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum ComplementarityFunction {
    /// [`min_function`] (convention `a >= 0, b >= 0`).
    Min,
    /// [`max_form`] with constant `c > 0` (convention `a <= 0, b <= 0`).
    MaxForm {
        /// Scale `c` converting the units of `b` into those of `a`.
        c: f64,
    },
    /// [`fischer_burmeister`] (convention `a >= 0, b >= 0`).
    FischerBurmeister,
}

impl ComplementarityFunction {
    /// The max form with a validated constant (`c` finite and positive).
    pub fn max_form(c: f64) -> Result<Self, InvalidComplementarityConstant> {
        if c.is_finite() && c > 0.0 {
            Ok(Self::MaxForm { c })
        } else {
            Err(InvalidComplementarityConstant { value: c })
        }
    }

    /// Evaluates the chosen function and a generalized gradient at `(a, b)`.
    pub fn eval(&self, a: f64, b: f64) -> PhiValue {
        match *self {
            Self::Min => min_function(a, b),
            Self::MaxForm { c } => max_form(a, b, c),
            Self::FischerBurmeister => fischer_burmeister(a, b),
        }
    }

    /// Whether the zeros are `a <= 0, b <= 0, a b = 0` (max form) rather than
    /// `a >= 0, b >= 0, a b = 0`.
    pub fn nonpositive_convention(&self) -> bool {
        matches!(self, Self::MaxForm { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const C: f64 = 3.5;

    fn all() -> [ComplementarityFunction; 3] {
        [
            ComplementarityFunction::Min,
            ComplementarityFunction::MaxForm { c: C },
            ComplementarityFunction::FischerBurmeister,
        ]
    }

    /// A nonzero argument far below any other value, on either side of a kink.
    const BESIDE_KINK: f64 = 1e-300;

    /// Grid of points including exact zeros, negatives and kinks.
    fn grid() -> Vec<f64> {
        let t = BESIDE_KINK;
        vec![-3.0, -1.0, -0.25, -t, 0.0, t, 0.25, 1.0, 2.0, 3.0]
    }

    fn is_complementary(f: &ComplementarityFunction, a: f64, b: f64) -> bool {
        if f.nonpositive_convention() {
            a <= 0.0 && b <= 0.0 && (a == 0.0 || b == 0.0)
        } else {
            a >= 0.0 && b >= 0.0 && (a == 0.0 || b == 0.0)
        }
    }

    #[test]
    fn zeros_are_exactly_the_complementarity_solutions() {
        for f in all() {
            for &a in &grid() {
                for &b in &grid() {
                    let zero = f.eval(a, b).value == 0.0;
                    assert_eq!(zero, is_complementary(&f, a, b), "{f:?} at ({a}, {b})");
                }
            }
        }
    }

    /// Central differences with h = 1e-6: truncation h^2/6 |phi'''| <= 1e-12 / r^2 (FB; all
    /// points have r >= 0.4; min and max form are linear there) and round-off
    /// eps |phi| / h ~ 1e-9, so 1e-7 absolute is a safe bound.
    #[test]
    fn gradients_match_central_differences_away_from_kinks() {
        let h = 1e-6;
        let points: [(f64, f64); 7] = [
            (0.3, 1.7),
            (1.7, 0.3),
            (-0.8, 0.4),
            (0.4, -0.8),
            (-1.1, -0.5),
            (-0.5, -1.1),
            (2.0, -2.5),
        ];
        for f in all() {
            for &(a, b) in &points {
                let near_kink = match f {
                    ComplementarityFunction::Min => (a - b).abs() < 0.1,
                    ComplementarityFunction::MaxForm { c } => (c * b - a).abs() < 0.1,
                    ComplementarityFunction::FischerBurmeister => a.hypot(b) < 0.1,
                };
                assert!(!near_kink);
                let g = f.eval(a, b);
                let da = (f.eval(a + h, b).value - f.eval(a - h, b).value) / (2.0 * h);
                let db = (f.eval(a, b + h).value - f.eval(a, b - h).value) / (2.0 * h);
                assert!(
                    (g.da - da).abs() < 1e-7,
                    "{f:?} da at ({a}, {b}): {} vs {da}",
                    g.da
                );
                assert!(
                    (g.db - db).abs() < 1e-7,
                    "{f:?} db at ({a}, {b}): {} vs {db}",
                    g.db
                );
            }
        }
    }

    /// At a kink the returned element is the gradient of one of the adjacent smooth
    /// pieces (a B-subdifferential element), the one documented.
    #[test]
    fn kink_elements_are_one_sided_limits_as_documented() {
        let eps = 1e-9;
        // min at a = b = 1: the side a < b.
        let k = min_function(1.0, 1.0);
        let side = min_function(1.0 - eps, 1.0);
        assert_eq!((k.da, k.db), (side.da, side.db));
        // max form at c b = a: the side s < 0.
        let (a, b) = (-C * 0.5, -0.5);
        let k = max_form(a, b, C);
        let side = max_form(a + eps, b, C);
        assert_eq!((k.da, k.db), (side.da, side.db));
        assert_eq!((k.da, k.db), (1.0, 0.0));
        // FB at the origin: the limit along a = b > 0.
        let k = fischer_burmeister(0.0, 0.0);
        let side = fischer_burmeister(eps, eps);
        assert!((k.da - side.da).abs() < 1e-15 && (k.db - side.db).abs() < 1e-15);
    }

    #[test]
    fn max_form_rejects_non_positive_or_non_finite_constant() {
        for c in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = ComplementarityFunction::max_form(c).unwrap_err();
            assert!(e.value.to_bits() == c.to_bits());
        }
        assert_eq!(
            ComplementarityFunction::max_form(2.0),
            Ok(ComplementarityFunction::MaxForm { c: 2.0 })
        );
    }

    /// No overflow for large arguments (hypot), no NaN from finite input.
    #[test]
    fn fischer_burmeister_is_finite_for_large_arguments() {
        let v = fischer_burmeister(1e200, 0.0);
        assert_eq!(v.value, 0.0);
        assert!(v.da.is_finite() && v.db.is_finite());
    }
}
