//! Closed-form periodic solutions the formulations are checked against.

/// The exact amplitude `X` of Den Hartog's continuous-sliding solution of
/// `m x'' + c x' + k x + F sign(x') = F0 cos(w t)` (`c` below critical).
///
/// Over the half period `(0, T/2)` after a velocity reversal at `x(0) = -X`, `x' > 0` and
/// `x = x_p + x_h`: the particular solution `x_p = A cos(w t + phi) + B sin(w t + phi) - F/k`
/// of the linear response `(A, B)` to `F0`, and the free damped motion `x_h` from
/// `x_h(0) = -X - x_p(0)`, `x_h'(0) = -x_p'(0)`. The half-period symmetry asks
/// `x(T/2) = X`, `x'(T/2) = 0`. With `p = A cos(phi) + B sin(phi)`,
/// `q = B cos(phi) - A sin(phi)` (so `p^2 + q^2 = A^2 + B^2`) and `Phi` the free motion's
/// transition matrix over `T/2`, both conditions are linear in `Y = X + p` and `q`; then
/// `X = Y - p` with `p = -sqrt(A^2 + B^2 - q^2)` (the root with `X > 0`); `None` where
/// `q^2 > A^2 + B^2`: no continuous sliding (the mass sticks).
pub fn den_hartog(m: f64, c: f64, k: f64, f0: f64, friction: f64, w: f64) -> Option<f64> {
    let wn = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let d = (k - m * w * w).powi(2) + (c * w).powi(2);
    let (a, b) = (f0 * (k - m * w * w) / d, f0 * c * w / d);
    let tau = std::f64::consts::PI / w;
    let s = friction / k;
    let (e, cs, sn) = ((-zeta * wn * tau).exp(), (wd * tau).cos(), (wd * tau).sin());
    let p11 = e * (cs + zeta * wn / wd * sn);
    let p12 = e * sn / wd;
    let p21 = -e * wn * wn / wd * sn;
    let p22 = e * (cs - zeta * wn / wd * sn);
    // -(P11 + 1) Y - P12 w q = -(P11 - 1) s;  -P21 Y - (P22 + 1) w q = -P21 s.
    let (a11, a12, b1) = (-(p11 + 1.0), -p12 * w, -(p11 - 1.0) * s);
    let (a21, a22, b2) = (-p21, -(p22 + 1.0) * w, -p21 * s);
    let det = a11 * a22 - a12 * a21;
    let y = (b1 * a22 - a12 * b2) / det;
    let q = (a11 * b2 - a21 * b1) / det;
    let r2 = a * a + b * b;
    (r2 > q * q).then(|| y + (r2 - q * q).sqrt())
}
