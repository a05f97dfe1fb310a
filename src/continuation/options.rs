//! Options of the continuation: step control, bounds, metric, predictor.

use super::ContinuationError;
use crate::linesearch::LineSearchOptions;
use crate::newton::StateFloor;

/// In which direction of the parameter the branch is followed from the starting point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Direction {
    /// The first step increases the parameter (default).
    #[default]
    Increasing,
    /// The first step decreases the parameter.
    Decreasing,
}

impl Direction {
    /// `+1` for [`Direction::Increasing`], `-1` for [`Direction::Decreasing`].
    pub fn sign(self) -> f64 {
        match self {
            Direction::Increasing => 1.0,
            Direction::Decreasing => -1.0,
        }
    }
}

/// How the next point is predicted from the last accepted one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Predictor {
    /// Along the secant through the last two accepted points (default; the first step
    /// always uses the tangent).
    #[default]
    Secant,
    /// Along the tangent at the last accepted point (from the corrector's last
    /// factorization, no extra cost).
    Tangent,
}

/// Options of the pseudo-arclength continuation. Build with struct update syntax from
/// [`Default`] and check with [`ContinuationOptions::validate`] (done by
/// [`Continuation::new`](super::Continuation::new)).
///
/// Step lengths are measured in the `theta`-weighted norm of the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationOptions {
    /// First step length `ds`. Default `0.01`.
    pub initial_step: f64,
    /// Smallest step length; a failure at this step ends the run. Default `0.002`
    /// (NLvib's habit: `ds/5 .. 5 ds` around the initial step).
    pub min_step: f64,
    /// Largest step length. Default `0.05`.
    pub max_step: f64,
    /// Corrector iterations the step control aims at: after `k` iterations the step is
    /// multiplied by `sqrt(target / k)` clamped to `[1/2, 2]`. Default `3`.
    pub target_iterations: usize,
    /// Corrector iterations (factorizations) allowed per attempted step. Default `10`.
    pub max_corrector_iterations: usize,
    /// The corrector has converged when the 2-norm `|F(x, p)| <= corrector_tolerance`
    /// (after at least one Newton correction). Default `1e-10`.
    pub corrector_tolerance: f64,
    /// The round-off floor in proportion to the corrected state's size (its parameter not
    /// counted): the corrector's tolerance is at least [`StateFloor::at`] of the state.
    /// Default [`StateFloor::OFF`].
    pub corrector_state_floor: StateFloor,
    /// The corrector gives up (stalled) when a correction has `|dy|_θ <= step_tolerance
    /// (1 + |y|_θ)` while `|F|` is still above the tolerance. Default `1e-14`.
    pub step_tolerance: f64,
    /// Lower bound of the parameter: the run stops when the branch goes below it.
    /// Default `-inf` (no bound).
    pub parameter_min: f64,
    /// Upper bound of the parameter: the run stops when the branch goes above it.
    /// Default `+inf` (no bound).
    pub parameter_max: f64,
    /// Largest number of accepted points, the starting point included. Default `1000`.
    pub max_points: usize,
    /// Corrector iterations allowed over the whole run: every attempt, accepted or not,
    /// the start, segment starts after restarts and corner passes. An attempt gets at most
    /// what is left, and the run ends
    /// ([`ContinuationTermination::IterationBudgetSpent`](super::ContinuationTermination::IterationBudgetSpent))
    /// once it is spent, so a run never does more. Default `None` (no limit).
    pub max_total_corrector_iterations: Option<usize>,
    /// Failed attempts in a row (each halving the step) after which the run stops.
    /// Default `3` (NLvib).
    pub max_consecutive_failures: usize,
    /// Weight `θ` in `(0, 1)` between the state (`θ/n` per component) and the parameter
    /// (`1 - θ`) in the arclength. Default `0.5`.
    pub theta: f64,
    /// Typical magnitude `s_i > 0` of each unknown (length `n`): the state part of the
    /// inner product becomes `(θ/n) Σ a_i b_i / s_i^2`, so that unknowns of different
    /// units (displacements and contact forces) weigh alike. Default `None` (all `1`).
    pub state_scale: Option<Vec<f64>>,
    /// Typical magnitude `s_p > 0` of the parameter: the parameter part of the inner product
    /// becomes `(1 - θ) α β / s_p^2`. Default `1`.
    pub parameter_scale: f64,
    /// Direction of the parameter on the first step. Default [`Direction::Increasing`].
    pub direction: Direction,
    /// Predictor after the first step. Default [`Predictor::Secant`].
    pub predictor: Predictor,
    /// Backtracking (Armijo) on the corrector's merit `(|F|^2 + N^2) / 2` along each
    /// bordered Newton correction; `None` takes full steps. Default `None` (the predictor
    /// is usually close enough; a line search helps nonsmooth problems whose full steps
    /// jump between active sets, and a poor starting guess).
    pub corrector_line_search: Option<LineSearchOptions>,
    /// Locate folds by cubic Hermite interpolation of `p(s)` between the two points that
    /// bracket the sign change (otherwise the fold is reported at the extreme point of the
    /// accepted points). Default `true`.
    pub refine_folds: bool,
    /// Smallest excursion of the parameter, as a θ-length (`sqrt(1 - θ) |Δp| / s_p`), by
    /// which the branch must leave an extremum of `p` for it to be a fold; a smaller turn
    /// back and forth is a zigzag of a piecewise-smooth branch
    /// ([`ContinuationEvent::Zigzag`](super::ContinuationEvent::Zigzag)). `0` makes every
    /// reversal a fold. Default `0.002` (the default `min_step`: a turn the steps cannot
    /// resolve is no fold).
    pub fold_excursion: f64,
    /// When the step has been halved to its end (the run would stop), try once to pass a
    /// corner of a piecewise-smooth branch (see the module documentation, *Corners*)
    /// before giving up. Default `true`.
    pub pass_corners: bool,
    /// With `pass_corners` and `restarts`, when a restart from a corner the passes could
    /// not turn goes back along the branch (the run would end `Retraced`), follow the
    /// tangent of the piece that leaves that corner instead (the generalized Jacobian just
    /// past it; module documentation, *Corners*). Default `false`.
    pub exit_tangents: bool,
    /// The corrector may not leave the θ-ball of radius `trust_factor` times the largest
    /// step the next attempt can take (twice the last step, at most `max_step`) around the
    /// last accepted point: an iterate outside it is rejected like one outside the
    /// problem's domain, and the step is halved. On piecewise-smooth branches Newton can
    /// otherwise converge on the far side of an overhang and skip both folds. Default
    /// `None` (no ball).
    pub trust_factor: Option<f64>,
    /// What to do when the steps fail for good (module documentation, *Restarts*);
    /// `None` ends the run there. Default `None`.
    pub restarts: Option<RestartPolicy>,
}

/// Restarts after the steps from a point failed for good: the branch is taken up again
/// from that point with a state-heavy metric for a few points, heading the way the
/// parameter last moved (the other way when a restart could not make a single step).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestartPolicy {
    /// `θ` of a restarted segment, in `(0, 1)`: close to 1, the arclength measures mostly
    /// the state, so the constraint still cuts a branch that reverses in `p` at a corner
    /// while its state moves on. Default `0.95`.
    pub theta: f64,
    /// Points of a restarted segment before the options' `θ` is taken again (`>= 1`).
    /// Default `4`.
    pub points: usize,
    /// Restarts allowed per run. Default `20`.
    pub max_restarts: usize,
    /// Points before the restart point against which a restarted segment is checked for
    /// going back along the branch: a point within a quarter of `|y_j - y_restart|` of one
    /// of them `y_j` (a genuine turn that close is sharper than 165°) ends the run there
    /// ([`ContinuationTermination::Retraced`](super::ContinuationTermination::Retraced)).
    /// `0` disables the check. Default `8`.
    pub retrace_window: usize,
}

impl Default for RestartPolicy {
    fn default() -> Self {
        Self {
            theta: 0.95,
            points: 4,
            max_restarts: 20,
            retrace_window: 8,
        }
    }
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self {
            initial_step: 0.01,
            min_step: 0.002,
            max_step: 0.05,
            target_iterations: 3,
            max_corrector_iterations: 10,
            corrector_tolerance: 1e-10,
            corrector_state_floor: StateFloor::OFF,
            step_tolerance: 1e-14,
            parameter_min: f64::NEG_INFINITY,
            parameter_max: f64::INFINITY,
            max_points: 1000,
            max_total_corrector_iterations: None,
            max_consecutive_failures: 3,
            theta: 0.5,
            state_scale: None,
            parameter_scale: 1.0,
            direction: Direction::Increasing,
            predictor: Predictor::Secant,
            corrector_line_search: None,
            refine_folds: true,
            fold_excursion: 0.002,
            pass_corners: true,
            exit_tangents: false,
            trust_factor: None,
            restarts: None,
        }
    }
}

impl ContinuationOptions {
    /// [`ContinuationOptions::fold_excursion`] in parameter units: `δ s_p / sqrt(1 - θ)`.
    pub fn fold_parameter_excursion(&self) -> f64 {
        self.fold_excursion * self.parameter_scale / (1.0 - self.theta).sqrt()
    }

    /// NLvib-like step settings around `ds`: `initial_step = ds`, `min_step = ds / 5`,
    /// `max_step = 5 ds`, other fields at their defaults.
    pub fn with_step(ds: f64) -> Self {
        Self {
            initial_step: ds,
            min_step: ds / 5.0,
            max_step: 5.0 * ds,
            ..Self::default()
        }
    }

    /// Checks every field; the error names the field, its value and what is allowed.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        self.validate_steps()?;
        self.validate_range()?;
        let open_unit = |name, v: f64| {
            if v > 0.0 && v < 1.0 {
                Ok(())
            } else {
                Err(invalid(name, v, "in the open interval (0, 1)"))
            }
        };
        open_unit("theta", self.theta)?;
        positive_finite("parameter_scale", self.parameter_scale)?;
        if let Some(factor) = self.trust_factor {
            positive_finite("trust_factor", factor)?;
        }
        if let Some(policy) = &self.restarts {
            open_unit("restarts.theta", policy.theta)?;
            if policy.points == 0 {
                return Err(invalid("restarts.points", 0.0, ">= 1"));
            }
        }
        if let Some(scale) = &self.state_scale {
            if let Some(&bad) = scale.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
                return Err(invalid("state_scale", bad, "finite and > 0 entries"));
            }
        }
        if let Some(ls) = &self.corrector_line_search {
            ls.validate().map_err(|e| {
                let e = crate::linesearch::within("corrector_line_search", e);
                invalid(e.name, e.value, e.allowed)
            })?;
        }
        Ok(())
    }

    /// Checks the steps, the iteration and point counts and the corrector's tolerance.
    fn validate_steps(&self) -> Result<(), ContinuationError> {
        positive_finite("min_step", self.min_step)?;
        positive_finite("max_step", self.max_step)?;
        positive_finite("initial_step", self.initial_step)?;
        if self.max_step < self.min_step {
            return Err(invalid("max_step", self.max_step, ">= min_step"));
        }
        if self.initial_step < self.min_step || self.initial_step > self.max_step {
            return Err(invalid(
                "initial_step",
                self.initial_step,
                "within [min_step, max_step]",
            ));
        }
        for (name, count) in [
            ("target_iterations", self.target_iterations),
            ("max_corrector_iterations", self.max_corrector_iterations),
            ("max_points", self.max_points),
            ("max_consecutive_failures", self.max_consecutive_failures),
            (
                "max_total_corrector_iterations",
                self.max_total_corrector_iterations.unwrap_or(1),
            ),
        ] {
            if count == 0 {
                return Err(invalid(name, 0.0, ">= 1"));
            }
        }
        positive_finite("corrector_tolerance", self.corrector_tolerance)
    }

    /// Checks the fold excursion, the step tolerance and the parameter's range.
    fn validate_range(&self) -> Result<(), ContinuationError> {
        if !(self.fold_excursion.is_finite() && self.fold_excursion >= 0.0) {
            return Err(invalid(
                "fold_excursion",
                self.fold_excursion,
                "finite and >= 0",
            ));
        }
        if let Some((field, value, allowed)) = self.corrector_state_floor.invalid_field() {
            let name = match field {
                "per_unit" => "corrector_state_floor.per_unit",
                _ => "corrector_state_floor.cap",
            };
            return Err(invalid(name, value, allowed));
        }
        if !(self.step_tolerance.is_finite() && self.step_tolerance >= 0.0) {
            return Err(invalid(
                "step_tolerance",
                self.step_tolerance,
                "finite and >= 0",
            ));
        }
        if self.parameter_min.is_nan() || self.parameter_min == f64::INFINITY {
            return Err(invalid(
                "parameter_min",
                self.parameter_min,
                "a number or -inf",
            ));
        }
        if self.parameter_max.is_nan() || self.parameter_max == f64::NEG_INFINITY {
            return Err(invalid(
                "parameter_max",
                self.parameter_max,
                "a number or +inf",
            ));
        }
        if self.parameter_max <= self.parameter_min {
            return Err(invalid(
                "parameter_max",
                self.parameter_max,
                "> parameter_min",
            ));
        }
        Ok(())
    }
}

/// The error of the option `name` whose `value` is not `allowed`.
fn invalid(name: &'static str, value: f64, allowed: &'static str) -> ContinuationError {
    ContinuationError::InvalidOption {
        name,
        value,
        allowed,
    }
}

/// `Err` naming `name` unless `v` is finite and > 0.
fn positive_finite(name: &'static str, v: f64) -> Result<(), ContinuationError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(name, v, "finite and > 0"))
    }
}
