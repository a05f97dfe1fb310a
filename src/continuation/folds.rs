//! Folds: reversals of the parameter along a branch, told apart from the zigzags of a
//! piecewise-smooth branch by their excursion, and located by Hermite interpolation.

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
/// A fold is a local extremum of the parameter along the branch that the branch leaves by
/// more than a minimal excursion `δ` ([`FoldDetector::with_min_excursion`], `0` by
/// default) before passing it again: a detector with hysteresis. On a piecewise-smooth
/// branch the parameter can turn back by a tiny amount at a corner and forward again at
/// the next one (a discretisation's active set changing sample by sample where the branch
/// is nearly vertical); such a turn, back and forth within `δ`, is a zigzag
/// ([`ContinuationEvent::Zigzag`], one event per reversal of the increments), not a fold.
///
/// A confirmed fold is located at the extreme point `p_k`, or, when refinement is asked
/// for and the tangent's parameter component `t_p` changes sign on `[k - 1, k]` or
/// `[k, k + 1]`, by cubic Hermite interpolation of `p(s)` on that interval (kept when the
/// interpolated extremum lies beyond `p_k`, within the reach of the neighbouring steps).
/// A sign change of `t_p` without a reversal of the increments (a generalized Jacobian
/// taken on the other side of a corner) is no fold.
///
/// A fold is confirmed by the first point more than `δ` back from the extremum, so it is
/// reported late; a fold the branch does not leave by `δ` before it ends is not reported,
/// and [`FoldDetector::finish`] reports the reversals still undecided as zigzags.
#[derive(Clone, Debug)]
pub struct FoldDetector {
    refine: bool,
    /// Smallest excursion `δ >= 0` of the parameter that confirms a fold.
    min_excursion: f64,
    /// Every point pushed.
    samples: Vec<FoldSample>,
    /// Direction of travel of the parameter since the last fold (`0` before the first
    /// non-zero increment).
    travel: f64,
    /// Index of the farthest point along `travel` since the last fold (the candidate).
    extreme: usize,
    /// Index of the farthest point against `travel` after the candidate.
    counter: usize,
    /// Sign of the last non-zero increment.
    increment_sign: f64,
    /// Reversals of the increments (index of the extreme point) not yet decided.
    undecided: Vec<usize>,
}

impl FoldDetector {
    /// A detector that confirms every reversal (`δ = 0`); `refine` locates folds by
    /// Hermite interpolation.
    pub fn new(refine: bool) -> Self {
        Self {
            refine,
            min_excursion: 0.0,
            samples: Vec::new(),
            travel: 0.0,
            extreme: 0,
            counter: 0,
            increment_sign: 0.0,
            undecided: Vec::new(),
        }
    }

    /// The same detector with the minimal excursion `δ` (in parameter units, `>= 0`) that
    /// tells a fold from a zigzag.
    pub fn with_min_excursion(mut self, min_excursion: f64) -> Self {
        self.min_excursion = min_excursion.max(0.0);
        self
    }

    /// Replaces the parameter and the tangent's parameter component of the last point
    /// pushed (the same point corrected again on another discretisation, across the
    /// branch, [`Continuation::resume`](super::Continuation::resume)): the decisions taken
    /// on it stay, later points are compared with, and folds located from, its new values.
    pub fn replace_last(&mut self, parameter: f64, tangent_parameter: f64) {
        if let Some(last) = self.samples.last_mut() {
            last.parameter = parameter;
            last.tangent_parameter = tangent_parameter;
        }
    }

    /// Adds the next accepted point: its parameter, the parameter component of its unit
    /// tangent oriented along the branch, and the θ-length of the chord from the previous
    /// point (ignored for the first). Returns the events this point decides (a fold it
    /// confirms, zigzags it rules out), in branch order; their `index` counts the points
    /// pushed (from 0).
    pub fn push(
        &mut self,
        parameter: f64,
        tangent_parameter: f64,
        chord: f64,
    ) -> Vec<ContinuationEvent> {
        let k = self.samples.len();
        self.samples.push(FoldSample {
            parameter,
            tangent_parameter,
            chord,
        });
        let mut events = Vec::new();
        if k == 0 {
            return events;
        }
        let increment = parameter - self.samples[k - 1].parameter;
        if increment != 0.0 {
            let sign = increment.signum();
            let previous = std::mem::replace(&mut self.increment_sign, sign);
            if previous != 0.0 && previous != sign {
                self.undecided.push(k - 1);
            }
        }
        if self.travel == 0.0 {
            if increment != 0.0 {
                self.travel = increment.signum();
                self.extreme = k;
                self.counter = k;
            }
            return events;
        }
        let extreme = self.samples[self.extreme].parameter;
        if (parameter - extreme) * self.travel > 0.0 {
            // Beyond the candidate: every reversal since it was a zigzag.
            let undecided = std::mem::take(&mut self.undecided);
            events.extend(undecided.into_iter().map(|i| self.zigzag(i)));
            self.extreme = k;
            self.counter = k;
            return events;
        }
        if (parameter - self.samples[self.counter].parameter) * self.travel <= 0.0 {
            self.counter = k;
        }
        if (extreme - parameter) * self.travel > self.min_excursion {
            let fold = self.extreme;
            let before: Vec<usize> = self
                .undecided
                .iter()
                .copied()
                .filter(|&i| i < fold)
                .collect();
            self.undecided.retain(|&i| i > fold);
            events.extend(before.into_iter().map(|i| self.zigzag(i)));
            events.push(self.fold(fold));
            self.travel = -self.travel;
            self.extreme = self.counter;
            // The farthest point against the new travel after the new candidate.
            let travel = self.travel;
            self.counter = (self.extreme..=k)
                .min_by(|&a, &b| {
                    (self.samples[a].parameter * travel)
                        .total_cmp(&(self.samples[b].parameter * travel))
                })
                .unwrap_or(k);
        }
        events
    }

    /// Ends the sequence: the reversals still undecided (the branch ended within `δ` of
    /// them) are reported as zigzags.
    pub fn finish(&mut self) -> Vec<ContinuationEvent> {
        let undecided = std::mem::take(&mut self.undecided);
        undecided.into_iter().map(|i| self.zigzag(i)).collect()
    }

    fn zigzag(&self, index: usize) -> ContinuationEvent {
        ContinuationEvent::Zigzag {
            index,
            parameter: self.samples[index].parameter,
        }
    }

    /// The fold at the extreme point `k` (`0 < k < len - 1`), refined on a bracketing
    /// interval where `t_p` changes sign from the travel before to the travel after.
    fn fold(&self, k: usize) -> ContinuationEvent {
        let s = &self.samples;
        let extreme = s[k];
        let (before, after) = (self.travel, -self.travel);
        let brackets = [(k - 1, k), (k, k + 1)];
        let bracket = brackets.into_iter().find(|&(a, b)| {
            s[a].tangent_parameter.signum() == before && s[b].tangent_parameter.signum() == after
        });
        let reach = (extreme.parameter - s[k - 1].parameter)
            .abs()
            .max((s[k + 1].parameter - extreme.parameter).abs());
        let (index, parameter) = match bracket {
            Some((a, b)) if self.refine && s[b].chord > 0.0 => {
                let p = hermite_fold(
                    s[a].parameter,
                    s[a].tangent_parameter,
                    s[b].parameter,
                    s[b].tangent_parameter,
                    s[b].chord,
                );
                let beyond = (p - extreme.parameter) * before;
                if (0.0..=reach).contains(&beyond) {
                    (b, p)
                } else {
                    (b, extreme.parameter)
                }
            }
            _ => (k, extreme.parameter),
        };
        ContinuationEvent::Fold { index, parameter }
    }
}

#[cfg(test)]
mod tests {
    use super::{hermite_fold, FoldDetector};
    use crate::continuation::ContinuationEvent;

    #[test]
    fn turns_back_and_forth_within_the_excursion_are_zigzags_around_the_folds() {
        // Up to 1.0277 with two small zigzags, back to 1.0178 with one, then on to 2; the
        // excursion 2e-3 separates the two turning points (0.0099 and 0.98 beyond them)
        // from the turns of at most 5e-4.
        let p = [
            0.5, 1.0, 1.0272, 1.0271, 1.0276, 1.0275, 1.0277, 1.0263, 1.0264, 1.0178, 1.5, 2.0,
        ];
        let mut detector = FoldDetector::new(false).with_min_excursion(2e-3);
        let mut events: Vec<_> = p.iter().flat_map(|&p| detector.push(p, 0.0, 0.1)).collect();
        events.extend(detector.finish());
        let fold = |index, parameter| ContinuationEvent::Fold { index, parameter };
        let zigzag = |index, parameter| ContinuationEvent::Zigzag { index, parameter };
        assert_eq!(
            events,
            [
                zigzag(2, 1.0272),
                zigzag(3, 1.0271),
                zigzag(4, 1.0276),
                zigzag(5, 1.0275),
                fold(6, 1.0277),
                zigzag(7, 1.0263),
                zigzag(8, 1.0264),
                fold(9, 1.0178),
            ]
        );
        // A monotone branch with one small turn back and forth has no fold, and a turn the
        // branch ends on is a zigzag.
        let mut detector = FoldDetector::new(false).with_min_excursion(2e-3);
        let mut events: Vec<_> = [0.5, 1.0, 0.9999, 1.5, 1.4995]
            .iter()
            .flat_map(|&p| detector.push(p, 0.0, 0.1))
            .collect();
        events.extend(detector.finish());
        assert_eq!(events, [zigzag(1, 1.0), zigzag(2, 0.9999), zigzag(3, 1.5)]);
    }

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
