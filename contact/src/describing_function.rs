//! The single-harmonic (describing-function) reference of friction damping: the first
//! harmonic of a Jenkins element's force in closed form, and the nonlinear mode it gives a
//! linear structure, computed without the harmonic balance (a secular equation on the
//! structure's linear modes). EPMC's backbones of friction-damped structures are checked
//! against it: the two differ only through the harmonics above the first.
//!
//! **Jenkins element** (a spring `k_t` in series with a Coulomb slider of slip force
//! `f_s`) under `x = a cos(theta)`. It sticks while `a <= a_s = f_s / k_t` (force `k_t x`).
//! Beyond, each half period it sticks from the turning point until `theta_s`,
//! `cos(theta_s) = 1 - 2 r` with `r = f_s / (k_t a)`, then slides at `-+ f_s`. The first
//! harmonic of the force is `(k_eq + i eta) x_1` in complex form (`x = Re(x_1 e^{i theta})`):
//!
//! ```text
//! k_eq = k_t (theta_s - sin(2 theta_s) / 2) / pi,      eta = 4 k_t r (1 - r) / pi.
//! ```
//!
//! `eta` is the equivalent viscous `c_eq w`: `pi eta a^2 = 4 f_s (a - f_s / k_t)`, the area of
//! the hysteresis loop.
//!
//! **Single-harmonic mode.** A structure `M, K, D` carrying the element on the displacement
//! `g . u`, `u = Re(phi e^{i w t})`: EPMC's equation on harmonic 1,
//! `(K - w^2 M + i w (D - xi M) + (k_eq + i eta) g g^T) phi = 0`, expanded on the
//! mass-normalised modes `(omega_r, phi_r)` of `K, M` (`D` diagonal on them, `d_r`), with
//! `p_r = g . phi_r`, has a solution if and only if the secular equation
//!
//! ```text
//! 1 + (k_eq + i eta) sum_r p_r^2 / (omega_r^2 - w^2 + i w (d_r - xi)) = 0
//! ```
//!
//! holds: one complex equation for the real `w` and `xi` at the element's amplitude
//! `a = |g . phi|` (`k_eq`, `eta` depend on `a` alone). With the element stuck it is the
//! linear mode of `K + k_t g g^T`, whose frequency lies between two consecutive `omega_r`
//! (a positive rank-one update interlaces): found by bisection, then followed in `a` by
//! Newton on `(w, xi)`.
//!
//! Reference: C.-H. Menq, J. H. Griffin, *A comparison of transient and steady state finite
//! element analyses of the forced response of a frictionally damped beam*, J. Vib. Acoust.
//! Stress Reliab. Des. 107 (1985) 19-25 (the Jenkins element's describing function).

use nalgebra::{Complex, DMatrix};

use crate::model::SparseMatrix;

/// The first harmonic of a Jenkins element's force per unit displacement amplitude.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct JenkinsHarmonic {
    /// `k_eq`: the part in phase with the displacement.
    pub stiffness: f64,
    /// `eta = c_eq w`: the part in phase with the velocity.
    pub loss: f64,
}

/// The describing function of a Jenkins element of stiffness `kt` and slip force
/// `slip_force` at the displacement amplitude `amplitude` (module documentation).
pub fn jenkins_first_harmonic(kt: f64, slip_force: f64, amplitude: f64) -> JenkinsHarmonic {
    let r = slip_force / (kt * amplitude);
    if r >= 1.0 {
        return JenkinsHarmonic {
            stiffness: kt,
            loss: 0.0,
        };
    }
    let theta = (1.0 - 2.0 * r).acos();
    JenkinsHarmonic {
        stiffness: kt * (theta - (2.0 * theta).sin() / 2.0) / std::f64::consts::PI,
        loss: 4.0 * kt * r * (1.0 - r) / std::f64::consts::PI,
    }
}

/// One mass-normalised linear mode of the structure without the element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModalTerm {
    /// Natural frequency `omega_r`.
    pub omega: f64,
    /// Modal damping `d_r = phi_r^T D phi_r` (`2 zeta_r omega_r`).
    pub damping: f64,
    /// `p_r = g . phi_r`: the mode's displacement across the element.
    pub participation: f64,
}

/// The modes of `K, M` (dense, `M` positive definite) with the Rayleigh damping
/// `D = alpha M + beta K` (`d_r = alpha + beta omega_r^2`) and their participations
/// `g . phi_r`, in increasing frequency; `None` when `M` is not positive definite.
pub fn modal_terms(
    stiffness: &DMatrix<f64>,
    mass: &DMatrix<f64>,
    (alpha, beta): (f64, f64),
    g: &[f64],
) -> Option<Vec<ModalTerm>> {
    let l = mass.clone().cholesky()?.l();
    let l_inv = l.clone().try_inverse()?;
    let a = &l_inv * stiffness * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eigen = a.symmetric_eigen();
    // phi_r = L^-T v_r, so g . phi_r = (L^-1 g) . v_r.
    let lg = &l_inv * nalgebra::DVector::from_column_slice(g);
    let mut terms: Vec<ModalTerm> = (0..eigen.eigenvalues.len())
        .map(|r| {
            let omega2 = eigen.eigenvalues[r];
            ModalTerm {
                omega: omega2.max(0.0).sqrt(),
                damping: alpha + beta * omega2,
                participation: eigen.eigenvectors.column(r).dot(&lg),
            }
        })
        .collect();
    terms.sort_by(|a, b| a.omega.total_cmp(&b.omega));
    Some(terms)
}

/// The modal terms of a structure whose Jenkins element is a spring from dof `attached`
/// to a massless slider dof `slider` (its only spring; the Coulomb law acts on it): the
/// structure without the slider and its spring (`k_t = K[slider, slider]` comes off
/// `K[attached, attached]`), damping `alpha M + beta K` of what remains, participations
/// those of `attached` ([`modal_terms`]). With `beta = 0` it is the model's own
/// `D = alpha M` (a `beta K` of the whole model would damp the spring too). Returns the
/// terms and `k_t`; `None` for indices out of range or equal, or a singular remaining `M`.
pub fn terms_without_slider(
    stiffness: &SparseMatrix,
    mass: &SparseMatrix,
    rayleigh: (f64, f64),
    attached: usize,
    slider: usize,
) -> Option<(Vec<ModalTerm>, f64)> {
    let n = stiffness.nrows();
    if attached >= n || slider >= n || attached == slider || mass.nrows() != n {
        return None;
    }
    // Dof i of the model is dof `i - (i > slider)` of the structure without the slider.
    let index = |i: usize| if i > slider { i - 1 } else { i };
    let dense = |a: &SparseMatrix| {
        let mut out = DMatrix::zeros(n - 1, n - 1);
        let a = a.as_ref();
        for j in (0..n).filter(|&j| j != slider) {
            for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                if i != slider {
                    out[(index(i), index(j))] += *v;
                }
            }
        }
        out
    };
    let kt = crate::model::diagonal_entry(stiffness, slider);
    let mut k = dense(stiffness);
    k[(index(attached), index(attached))] -= kt;
    let mut g = vec![0.0; n - 1];
    g[index(attached)] = 1.0;
    Some((modal_terms(&k, &dense(mass), rayleigh, &g)?, kt))
}

/// One point of a single-harmonic nonlinear mode.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SingleHarmonicPoint {
    /// The amplitude `a` of the element's displacement.
    pub amplitude: f64,
    /// The frequency `w`.
    pub omega: f64,
    /// EPMC's modal damping `xi`.
    pub modal_damping: f64,
    /// NLvib's damping ratio `xi / (2 w)`.
    pub damping_ratio: f64,
}

/// Why [`jenkins_mode`] gave no answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DescribingFunctionError {
    /// Amplitudes must be positive and increasing, `kt` and the slip force positive.
    #[error("amplitudes positive and increasing, k_t and the slip force positive: {what}")]
    BadInput {
        /// What is wrong.
        what: &'static str,
    },
    /// Mode `mode` has no interval between two participating modes (or above the last).
    #[error("no stuck mode {mode}: {participating} modes participate")]
    NoSuchMode {
        /// The mode asked for (1-based).
        mode: usize,
        /// Modes with a nonzero participation.
        participating: usize,
    },
    /// Newton on the secular equation did not converge.
    #[error("the secular equation did not converge at amplitude {amplitude}")]
    NotConverged {
        /// Where.
        amplitude: f64,
    },
}

/// Ratio between consecutive amplitudes of the internal march (Newton's warm starts).
const MARCH_RATIO: f64 = 1.02;

/// The single-harmonic nonlinear mode `mode` (1-based: the stuck mode in the `mode`-th
/// interval of the participating `omega_r`) of the structure of `terms` carrying a Jenkins
/// element (`kt`, `slip_force`), at the element's `amplitudes` (positive, increasing).
pub fn jenkins_mode(
    terms: &[ModalTerm],
    kt: f64,
    slip_force: f64,
    mode: usize,
    amplitudes: &[f64],
) -> Result<Vec<SingleHarmonicPoint>, DescribingFunctionError> {
    let bad = |what| Err(DescribingFunctionError::BadInput { what });
    if !(kt > 0.0 && slip_force > 0.0 && kt.is_finite() && slip_force.is_finite()) {
        return bad("k_t, slip force");
    }
    if amplitudes.is_empty()
        || amplitudes[0].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        || amplitudes
            .windows(2)
            .any(|w| w[1].partial_cmp(&w[0]).is_none() || w[1] < w[0])
    {
        return bad("amplitudes");
    }
    let terms: Vec<ModalTerm> = terms
        .iter()
        .copied()
        .filter(|t| t.participation != 0.0)
        .collect();
    let mut state = stuck_mode(&terms, kt, mode)?;
    // The stuck mode holds up to a_s: march from there (or from the first amplitude).
    let mut a = amplitudes[0].min(slip_force / kt);
    let mut points = Vec::with_capacity(amplitudes.len());
    for &target in amplitudes {
        while a < target {
            a = (a * MARCH_RATIO).min(target);
            state = secular_newton(&terms, jenkins_first_harmonic(kt, slip_force, a), state)
                .ok_or(DescribingFunctionError::NotConverged { amplitude: a })?;
        }
        let (omega, xi) = state;
        points.push(SingleHarmonicPoint {
            amplitude: target,
            omega,
            modal_damping: xi,
            damping_ratio: xi / (2.0 * omega),
        });
    }
    Ok(points)
}

/// The stuck mode's `(w, xi)`: `w^2` the root of `1 + k_t sum_r p_r^2 / (omega_r^2 - w^2)`
/// in the `mode`-th interval (bisection: the function increases in `w^2` there), `xi` its
/// start `d_r` of the mode below, then Newton on the complex equation with damping.
fn stuck_mode(
    terms: &[ModalTerm],
    kt: f64,
    mode: usize,
) -> Result<(f64, f64), DescribingFunctionError> {
    let no_mode = DescribingFunctionError::NoSuchMode {
        mode,
        participating: terms.len(),
    };
    let Some(below) = mode.checked_sub(1).and_then(|i| terms.get(i)) else {
        return Err(no_mode);
    };
    let lower = below.omega * below.omega;
    let upper = terms.get(mode).map_or_else(
        // Above the last mode the root is below omega_last^2 + k_t sum p_r^2.
        || lower + kt * terms.iter().map(|t| t.participation.powi(2)).sum::<f64>(),
        |t| t.omega * t.omega,
    );
    let secular = |w2: f64| {
        1.0 + kt
            * terms
                .iter()
                .map(|t| t.participation.powi(2) / (t.omega * t.omega - w2))
                .sum::<f64>()
    };
    let (mut lo, mut hi) = (lower, upper);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if secular(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let stuck = JenkinsHarmonic {
        stiffness: kt,
        loss: 0.0,
    };
    secular_newton(terms, stuck, ((0.5 * (lo + hi)).sqrt(), below.damping)).ok_or(
        DescribingFunctionError::NotConverged {
            amplitude: f64::NAN,
        },
    )
}

/// Newton on `F(w, xi) = 1 + kappa S(w, xi)` (real and imaginary parts) from `(w, xi)`,
/// `kappa = k_eq + i eta`; `None` when it does not converge in 50 iterations.
fn secular_newton(
    terms: &[ModalTerm],
    element: JenkinsHarmonic,
    (mut w, mut xi): (f64, f64),
) -> Option<(f64, f64)> {
    let kappa = Complex::new(element.stiffness, element.loss);
    for _ in 0..50 {
        let (mut s, mut ds_dw, mut ds_dxi) =
            (Complex::from(0.0), Complex::from(0.0), Complex::from(0.0));
        for t in terms {
            let den = Complex::new(t.omega * t.omega - w * w, w * (t.damping - xi));
            let p2 = t.participation * t.participation;
            let inv2 = p2 / (den * den);
            s += p2 / den;
            ds_dw -= inv2 * Complex::new(-2.0 * w, t.damping - xi);
            ds_dxi -= inv2 * Complex::new(0.0, -w);
        }
        let f = Complex::from(1.0) + kappa * s;
        let (fw, fx) = (kappa * ds_dw, kappa * ds_dxi);
        let det = fw.re * fx.im - fx.re * fw.im;
        let dw = -(f.re * fx.im - fx.re * f.im) / det;
        let dxi = -(fw.re * f.im - f.re * fw.im) / det;
        if !(dw.is_finite() && dxi.is_finite()) {
            return None;
        }
        w += dw;
        xi += dxi;
        if dw.abs() <= 1e-14 * w && dxi.abs() <= 1e-14 * w {
            return Some((w, xi));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jenkins_loss_is_the_hysteresis_loop_area_and_the_stiffness_falls_to_zero() {
        let (kt, fs) = (3.0, 0.6);
        for a in [0.1, 0.2, 0.3, 1.0, 10.0, 1e4] {
            let h = jenkins_first_harmonic(kt, fs, a);
            let loop_area = if a > fs / kt {
                4.0 * fs * (a - fs / kt)
            } else {
                0.0
            };
            assert!(
                (std::f64::consts::PI * h.loss * a * a - loop_area).abs()
                    < 1e-12 * (1.0 + loop_area)
            );
            assert!(h.stiffness <= kt && h.stiffness > 0.0);
        }
        // Continuous at the onset of slip; k_eq falls like a^(-3/2) at large a (theta_s ~ 2 sqrt(r)).
        assert!((jenkins_first_harmonic(kt, fs, 0.2 * (1.0 + 1e-12)).stiffness - kt).abs() < 1e-5);
        assert!(jenkins_first_harmonic(kt, fs, 1e6).stiffness < 1e-5);
    }

    #[test]
    fn one_dof_mode_is_the_describing_function_in_closed_form() {
        // m = k = 1, c = 0.01: w^2 = 1 + k_eq, xi = c + eta / w (single harmonic).
        let (kt, fs, c) = (3.0, 0.5, 0.01);
        let terms = [ModalTerm {
            omega: 1.0,
            damping: c,
            participation: 1.0,
        }];
        let amplitudes = [0.05, 0.2, 0.5, 1.0, 3.0];
        let points = jenkins_mode(&terms, kt, fs, 1, &amplitudes).unwrap();
        for p in points {
            let h = jenkins_first_harmonic(kt, fs, p.amplitude);
            let w = (1.0 + h.stiffness).sqrt();
            assert!((p.omega - w).abs() < 1e-13, "{} {w}", p.omega);
            assert!((p.modal_damping - (c + h.loss / w)).abs() < 1e-13);
        }
    }
}
