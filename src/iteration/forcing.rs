//! The inexact-Newton forcing term: how accurately each direction's linear solve must be
//! carried out (Eisenstat & Walker 1996, SIAM J. Sci. Comput. 17, choice 2, with the
//! safeguards of Kelley 1995, "Iterative Methods for Linear and Nonlinear Equations", 6.3).
//!
//! At iterate `k` the solve of `J d = -G` may stop at `|J d + G| <= eta_k |G_k|` with
//! `eta_0 = ETA_MAX` and `eta_k = min(ETA_MAX, max(GAMMA (|G_k| / |G_{k-1}|)^2, GAMMA
//! eta_{k-1}^2 when that exceeds 0.1))`; never tighter than [`OUTER_SHARE`] of the run's
//! tolerance, which is all the outer test needs (a full step then leaves `|G|` at about the
//! linear residual). Direct solvers ignore it and solve exactly
//! ([`LinearSolve::solve_in_place_to`](crate::LinearSolve::solve_in_place_to)).

use crate::linalg::SolveAccuracy;

/// Largest forcing term: a tenth of the residual, so that early directions still choose the
/// active set of an exact step (semismooth Newton's switching is decided by the direction).
pub(crate) const ETA_MAX: f64 = 0.1;
/// Eisenstat–Walker's `gamma` of choice 2.
const GAMMA: f64 = 0.9;
/// The linear residual asked for is at least this share of the outer tolerance.
pub(crate) const OUTER_SHARE: f64 = 0.1;

/// The forcing term's memory over one run: the last term and the residual norm it was
/// taken at (NaN before the first direction).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Forcing {
    eta: f64,
    norm: f64,
}

impl Default for Forcing {
    fn default() -> Self {
        Self {
            eta: ETA_MAX,
            norm: f64::NAN,
        }
    }
}

impl Forcing {
    /// The accuracy of the direction at an iterate with `|G| = norm`, in a run whose
    /// convergence test is `|G| <= tolerance`.
    pub(crate) fn next(&mut self, norm: f64, tolerance: f64) -> SolveAccuracy {
        let eta = if self.norm.is_finite() && self.norm > 0.0 {
            let ratio = norm / self.norm;
            let mut eta = GAMMA * ratio * ratio;
            let safeguard = GAMMA * self.eta * self.eta;
            if safeguard > 0.1 {
                eta = eta.max(safeguard);
            }
            eta.min(ETA_MAX)
        } else {
            ETA_MAX
        };
        self.eta = eta;
        self.norm = norm;
        SolveAccuracy::new(eta, OUTER_SHARE * tolerance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forcing_starts_at_its_largest_and_tightens_like_the_square_of_the_residual_ratio() {
        let mut forcing = Forcing::default();
        let first = forcing.next(1.0, 1e-10);
        assert_eq!(first.relative, ETA_MAX);
        assert_eq!(first.absolute, OUTER_SHARE * 1e-10);
        // |G| fell tenfold: 0.9 * 0.01, below the safeguard's threshold (0.9 * 0.1^2).
        let second = forcing.next(0.1, 1e-10);
        assert!((second.relative - 0.009).abs() < 1e-15);
        // A stagnating residual loosens it back to ETA_MAX.
        assert_eq!(forcing.next(0.1, 1e-10).relative, ETA_MAX);
    }
}
