//! Backtracking line searches on a merit function, seen only through a closure
//! `alpha -> merit(x + alpha d)`: their options ([`LineSearchOptions`]) are public, the
//! search itself runs inside the crate's Newton iteration.
//!
//! - **Armijo**: accept the first `alpha = shrink^k` with
//!   `m(alpha) <= m(0) + sigma alpha m'(0)`.
//! - **Non-monotone** (Grippo, Lampariello & Lucidi 1986, SIAM J. Numer. Anal. 23(4)):
//!   the same test with `m(0)` replaced by the largest merit among the last `memory`
//!   accepted iterates, which lets the iteration climb out of narrow valleys and accepts
//!   more full steps; `memory = 1` is Armijo.
//!
//! For Newton's direction `d = -J^{-1} F` on the merit `m = 0.5 |F|^2` the slope is
//! `m'(0) = F^T J d = -|F|^2 = -2 m(0)`, so callers pass `slope = -2 m(0)`. For
//! semismooth `F` this is the directional derivative of `m` along `d` whenever `m` is
//! differentiable (e.g. Fischer–Burmeister reformulations) and a model of it otherwise.
//!
//! A trial whose merit is not finite (NaN or infinite residual) is rejected like any
//! other insufficient decrease, so a far step into an overflow region is shortened
//! rather than accepted.

use crate::InvalidOption;

/// Options of the backtracking line search (all validated by
/// [`LineSearchOptions::validate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineSearchOptions {
    /// Armijo constant `sigma` in `(0, 1)`; default `1e-4`.
    pub sufficient_decrease: f64,
    /// Factor applied to the step after a rejected trial, in `(0, 1)`; default `0.5`.
    pub shrink: f64,
    /// Smallest step tried, in `(0, 1]`; a step below it means failure. Default `1e-10`.
    pub min_step: f64,
}

impl Default for LineSearchOptions {
    fn default() -> Self {
        Self {
            sufficient_decrease: 1e-4,
            shrink: 0.5,
            min_step: 1e-10,
        }
    }
}

/// `error` of a line-search field, named inside the options field `within`
/// (`"line_search"` gives `"line_search.shrink"`; the bare name for other prefixes).
pub(crate) fn within(within: &'static str, error: InvalidOption) -> InvalidOption {
    let name = match (within, error.name) {
        ("line_search", "sufficient_decrease") => "line_search.sufficient_decrease",
        ("line_search", "shrink") => "line_search.shrink",
        ("line_search", "min_step") => "line_search.min_step",
        ("corrector_line_search", "sufficient_decrease") => {
            "corrector_line_search.sufficient_decrease"
        }
        ("corrector_line_search", "shrink") => "corrector_line_search.shrink",
        ("corrector_line_search", "min_step") => "corrector_line_search.min_step",
        _ => error.name,
    };
    InvalidOption { name, ..error }
}

/// Checks `lo < value < hi` (open) or `lo < value <= hi` (`closed_hi`).
fn check_range(
    name: &'static str,
    value: f64,
    closed_hi: bool,
    allowed: &'static str,
) -> Result<(), InvalidOption> {
    let ok = value > 0.0 && (value < 1.0 || (closed_hi && value == 1.0));
    InvalidOption::check(ok, name, value, allowed)
}

impl LineSearchOptions {
    /// Checks every field against its range (NaN is rejected).
    pub fn validate(&self) -> Result<(), InvalidOption> {
        check_range(
            "sufficient_decrease",
            self.sufficient_decrease,
            false,
            "(0, 1)",
        )?;
        check_range("shrink", self.shrink, false, "(0, 1)")?;
        check_range("min_step", self.min_step, true, "(0, 1]")?;
        Ok(())
    }
}

/// An accepted step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AcceptedStep {
    /// The accepted step length `alpha`.
    pub step: f64,
    /// `merit(alpha)`; the closure's last call was at this `alpha`.
    pub merit: f64,
    /// Number of rejected trials before acceptance (= merit evaluations - 1).
    pub backtracks: u64,
}

/// No acceptable step at or above `min_step`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LineSearchFailure {
    /// The last step length tried.
    pub last_step: f64,
    /// Its merit (may be infinite).
    pub last_merit: f64,
    /// Number of rejected trials (= merit evaluations).
    pub backtracks: u64,
}

/// Why a backtracking search ended without a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Backtrack<E> {
    /// No acceptable step at or above `min_step`.
    Failed(LineSearchFailure),
    /// The merit could not be evaluated at all (the closure's error), after `backtracks`
    /// rejected trials.
    Aborted {
        /// The closure's error.
        error: E,
        /// Rejected trials before it.
        backtracks: u64,
    },
}

/// Backtracking from `alpha = 1`: accepts the first `alpha = shrink^k >= min_step` with
/// a finite `merit(alpha) <= reference + sufficient_decrease * alpha * slope`; a merit the
/// closure cannot give (`Err`) ends the search ([`Backtrack::Aborted`]).
///
/// `reference` is `m(0)` for Armijo or [`NonMonotoneHistory::reference`]; `slope` is the
/// directional derivative `m'(0) < 0`. The loop ends for any options (it also stops
/// if `alpha` fails to decrease), so invalid options cannot hang it; validate them
/// with [`LineSearchOptions::validate`] for meaningful results.
pub(crate) fn backtrack<E>(
    reference: f64,
    slope: f64,
    options: &LineSearchOptions,
    mut merit: impl FnMut(f64) -> Result<f64, E>,
) -> Result<AcceptedStep, Backtrack<E>> {
    let mut alpha = 1.0_f64;
    let mut backtracks = 0u64;
    loop {
        let m = match merit(alpha) {
            Ok(m) => m,
            Err(error) => return Err(Backtrack::Aborted { error, backtracks }),
        };
        if m.is_finite() && m <= reference + options.sufficient_decrease * alpha * slope {
            return Ok(AcceptedStep {
                step: alpha,
                merit: m,
                backtracks,
            });
        }
        backtracks += 1;
        let next = alpha * options.shrink;
        // Not strictly smaller (shrink >= 1) or incomparable (NaN): stop as well.
        let decreasing = next.partial_cmp(&alpha) == Some(std::cmp::Ordering::Less);
        if next < options.min_step || !decreasing {
            return Err(Backtrack::Failed(LineSearchFailure {
                last_step: alpha,
                last_merit: m,
                backtracks,
            }));
        }
        alpha = next;
    }
}

/// The last `memory` accepted merit values, for the Grippo–Lampariello–Lucidi
/// reference `max_{0 <= j < memory} m_{k-j}`. A ring buffer allocated once.
#[derive(Clone, Debug)]
pub(crate) struct NonMonotoneHistory {
    values: Vec<f64>,
    memory: usize,
    next: usize,
}

impl NonMonotoneHistory {
    /// A history keeping `memory` values (`memory = 0` is treated as 1, i.e. Armijo).
    pub fn new(memory: usize) -> Self {
        let memory = memory.max(1);
        Self {
            values: Vec::with_capacity(memory),
            memory,
            next: 0,
        }
    }

    /// Forgets all values and sets the memory length (reusing the storage when it
    /// is large enough).
    pub fn reset(&mut self, memory: usize) {
        self.memory = memory.max(1);
        self.values.clear();
        self.values.reserve(self.memory);
        self.next = 0;
    }

    /// Records the merit of a newly accepted iterate, dropping the oldest beyond
    /// `memory`.
    pub fn push(&mut self, merit: f64) {
        if self.values.len() < self.memory {
            self.values.push(merit);
        } else {
            self.values[self.next] = merit;
        }
        self.next = (self.next + 1) % self.memory;
    }

    /// The largest recorded merit (`-inf` if none).
    pub fn reference(&self) -> f64 {
        self.values
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_step_is_accepted_without_backtracking_when_it_decreases_enough() {
        // m(alpha) = 0.5 (1 - alpha)^2, the exact Newton model: m(1) = 0.
        let step = backtrack(0.5, -1.0, &LineSearchOptions::default(), |a: f64| {
            Ok::<_, ()>(0.5 * (1.0 - a).powi(2))
        })
        .unwrap();
        assert_eq!(
            step,
            AcceptedStep {
                step: 1.0,
                merit: 0.0,
                backtracks: 0
            }
        );
    }

    #[test]
    fn an_overshooting_full_step_is_halved() {
        // m(alpha) = 0.5 (1 - 3 alpha)^2: the full step overshoots (m(1) = 2 > m(0) = 0.5);
        // alpha = 0.5 gives m = 0.125 <= 0.5 - 1e-4 * 0.5 * 1.0, accepted after 1 backtrack.
        let merit = |alpha: f64| Ok::<_, ()>(0.5 * (1.0 - 3.0 * alpha).powi(2));
        let step = backtrack(0.5, -1.0, &LineSearchOptions::default(), merit).unwrap();
        assert_eq!((step.step, step.backtracks), (0.5, 1));
    }

    #[test]
    fn non_finite_trials_are_rejected_and_counted() {
        let mut calls = 0;
        let step = backtrack(1.0, -2.0, &LineSearchOptions::default(), |a: f64| {
            calls += 1;
            Ok::<_, ()>(if a > 0.2 { f64::NAN } else { 0.0 })
        })
        .unwrap();
        // 1, 0.5, 0.25 rejected; 0.125 accepted.
        assert_eq!((step.step, step.backtracks, calls), (0.125, 3, 4));
    }

    #[test]
    fn failure_below_min_step_reports_trials() {
        let options = LineSearchOptions {
            min_step: 0.1,
            ..Default::default()
        };
        let fail = backtrack(1.0, -2.0, &options, |_| Ok::<_, ()>(5.0)).unwrap_err();
        // Tried 1, 0.5, 0.25, 0.125; next 0.0625 < 0.1.
        assert_eq!(
            fail,
            Backtrack::Failed(LineSearchFailure {
                last_step: 0.125,
                last_merit: 5.0,
                backtracks: 4
            })
        );
    }

    #[test]
    fn a_merit_that_cannot_be_evaluated_ends_the_search() {
        let mut calls = 0;
        let fail = backtrack(1.0, -2.0, &LineSearchOptions::default(), |a: f64| {
            calls += 1;
            if a < 0.3 {
                Err("failed")
            } else {
                Ok(5.0)
            }
        })
        .unwrap_err();
        // 1, 0.5 rejected; the evaluation at 0.25 fails.
        assert_eq!(
            (fail, calls),
            (
                Backtrack::Aborted {
                    error: "failed",
                    backtracks: 2
                },
                3
            )
        );
    }

    #[test]
    fn invalid_shrink_cannot_hang_the_loop() {
        let options = LineSearchOptions {
            shrink: 1.0,
            ..Default::default()
        };
        assert!(backtrack(1.0, -2.0, &options, |_| Ok::<_, ()>(5.0)).is_err());
        let options = LineSearchOptions {
            shrink: f64::NAN,
            ..Default::default()
        };
        assert!(backtrack(1.0, -2.0, &options, |_| Ok::<_, ()>(5.0)).is_err());
    }

    #[test]
    fn validation_names_the_field_and_range() {
        let bad = LineSearchOptions {
            shrink: 1.5,
            ..Default::default()
        };
        assert_eq!(
            bad.validate(),
            Err(InvalidOption {
                name: "shrink",
                value: 1.5,
                allowed: "(0, 1)"
            })
        );
        let bad = LineSearchOptions {
            min_step: 0.0,
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().name, "min_step");
        assert!(LineSearchOptions::default().validate().is_ok());
    }

    /// The reference is the max of the last `memory` values: a trial above the current
    /// merit but below an older one is accepted non-monotonically, rejected by Armijo.
    #[test]
    fn non_monotone_reference_is_max_of_last_memory_values() {
        let mut h = NonMonotoneHistory::new(3);
        assert_eq!(h.reference(), f64::NEG_INFINITY);
        for m in [10.0, 4.0, 2.0] {
            h.push(m);
        }
        assert_eq!(h.reference(), 10.0);
        h.push(1.0); // drops 10
        assert_eq!(h.reference(), 4.0);
        let opts = LineSearchOptions::default();
        let trial = |_: f64| Ok::<_, ()>(3.0); // above the current merit 1.0, below 4.0
        assert!(backtrack(h.reference(), -2.0, &opts, trial).is_ok());
        assert!(backtrack(
            1.0,
            -2.0,
            &LineSearchOptions {
                min_step: 0.5,
                ..opts
            },
            trial
        )
        .is_err());
        h.reset(1);
        h.push(7.0);
        h.push(6.0);
        assert_eq!(h.reference(), 6.0);
    }
}
