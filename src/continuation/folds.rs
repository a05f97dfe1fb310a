//! Folds: reversals of the parameter along a branch, located by Hermite interpolation.

use super::ContinuationEvent;

/// Parameter at the fold between two points, from the cubic Hermite interpolant of `p(s)`
/// with values `p0, p1` and slopes `m0, m1` (opposite signs) over the θ-length `h`.
fn hermite_fold(p0: f64, m0: f64, p1: f64, m1: f64, h: f64) -> f64 {
    // p'(τ) = A τ² + B τ + C on τ in [0, 1]; C = h m0 and p'(1) = h m1 have opposite signs.
    let a = 6.0 * p0 + 3.0 * h * m0 - 6.0 * p1 + 3.0 * h * m1;
    let b = -6.0 * p0 - 4.0 * h * m0 + 6.0 * p1 - 2.0 * h * m1;
    let c = h * m0;
    let dp = |t: f64| (a * t + b) * t + c;
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    let lo_sign = dp(lo).signum();
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if dp(mid).signum() == lo_sign {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    let (t2, t3) = (t * t, t * t * t);
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    let value = h00 * p0 + h10 * h * m0 + h01 * p1 + h11 * h * m1;
    if value.is_finite() {
        value
    } else {
        p1
    }
}

/// One accepted point as the fold detector sees it.
#[derive(Clone, Copy, Debug)]
struct FoldSample {
    parameter: f64,
    tangent_parameter: f64,
    /// θ-length of the chord from the previous point.
    chord: f64,
}

/// Fold detection along a sequence of accepted points.
///
/// A fold is a local extremum of the parameter along the branch: the increments
/// `p_k - p_{k-1}` change sign at the extreme point `k`. On a smooth branch the tangent's
/// parameter component `t_p` changes sign between `k - 1` and `k` or between `k` and `k + 1`;
/// the fold is then located by cubic Hermite interpolation of `p(s)` on that interval (when
/// refinement is asked for and the interpolated extremum lies beyond `p_k`, within the
/// reach of the neighbouring steps), otherwise reported at the extreme point `p_k`. A reversal without such a sign change (a fold at a corner of a
/// piecewise-smooth branch) is reported at `p_k`. A sign change of `t_p` without a reversal
/// of the increments (a generalized Jacobian taken on the other side of a corner, where
/// the tangent of the neighbouring piece points backwards) is no fold.
///
/// A fold is confirmed by the first point after the extremum, so it is reported one point
/// late; a fold at the last point of a branch is not reported.
#[derive(Clone, Debug)]
pub struct FoldDetector {
    refine: bool,
    /// The last three points (oldest first).
    recent: Vec<FoldSample>,
    /// Index of the newest point in `recent`.
    newest: usize,
    /// Sign of the last non-zero parameter increment.
    increment_sign: f64,
}

impl FoldDetector {
    /// A detector; `refine` locates folds by Hermite interpolation.
    pub fn new(refine: bool) -> Self {
        Self {
            refine,
            recent: Vec::with_capacity(3),
            newest: 0,
            increment_sign: 0.0,
        }
    }

    /// Adds the next accepted point: its parameter, the parameter component of its unit
    /// tangent oriented along the branch, and the θ-length of the chord from the previous
    /// point (ignored for the first). Returns the fold this point confirms, if any; its
    /// `index` counts the points pushed (from 0).
    pub fn push(
        &mut self,
        parameter: f64,
        tangent_parameter: f64,
        chord: f64,
    ) -> Option<ContinuationEvent> {
        let sample = FoldSample {
            parameter,
            tangent_parameter,
            chord,
        };
        if self.recent.is_empty() {
            self.recent.push(sample);
            self.newest = 0;
            return None;
        }
        self.newest += 1;
        if self.recent.len() == 3 {
            self.recent.remove(0);
        }
        self.recent.push(sample);
        let m = self.recent.len();
        let increment = parameter - self.recent[m - 2].parameter;
        if increment == 0.0 {
            return None;
        }
        let sign = increment.signum();
        let previous = std::mem::replace(&mut self.increment_sign, sign);
        if previous == 0.0 || previous == sign {
            return None;
        }
        // The extreme point is the one before this increment.
        let extreme = self.recent[m - 2];
        let extreme_index = self.newest - 1;
        // Intervals [k-1, k] and [k, k+1] around the extreme k, as (left, right, index of
        // right); a sign change of t_p from `previous` to `sign` brackets a smooth fold.
        let mut brackets = Vec::with_capacity(2);
        if m == 3 {
            brackets.push((self.recent[0], self.recent[1], extreme_index));
        }
        brackets.push((self.recent[m - 2], self.recent[m - 1], self.newest));
        let bracket = brackets.into_iter().find(|(a, b, _)| {
            a.tangent_parameter.signum() == previous && b.tangent_parameter.signum() == sign
        });
        let reach = if m == 3 {
            (extreme.parameter - self.recent[0].parameter)
                .abs()
                .max(increment.abs())
        } else {
            increment.abs()
        };
        let (index, parameter) = match bracket {
            Some((a, b, index)) if self.refine && b.chord > 0.0 => {
                let p = hermite_fold(
                    a.parameter,
                    a.tangent_parameter,
                    b.parameter,
                    b.tangent_parameter,
                    b.chord,
                );
                let beyond = (p - extreme.parameter) * previous;
                if beyond >= 0.0 && beyond <= reach {
                    (index, p)
                } else {
                    (index, extreme.parameter)
                }
            }
            _ => (extreme_index, extreme.parameter),
        };
        Some(ContinuationEvent::Fold { index, parameter })
    }
}

#[cfg(test)]
mod tests {
    use super::hermite_fold;

    #[test]
    fn hermite_fold_is_exact_for_a_quadratic_turn() {
        // p(s) = 1 - (s - 0.3)^2 / 2 on [0, h] with h = 0.8: values and slopes at both ends;
        // a cubic Hermite interpolant reproduces a quadratic, so the maximum 1 is exact.
        let p = |s: f64| 1.0 - 0.5 * (s - 0.3) * (s - 0.3);
        let dp = |s: f64| -(s - 0.3);
        let h = 0.8;
        let fold = hermite_fold(p(0.0), dp(0.0), p(h), dp(h), h);
        assert!((fold - 1.0).abs() < 1e-15, "{fold}");
    }
}
