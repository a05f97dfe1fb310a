//! Up-front work estimates of whole commands, next to [`crate::limits`]' memory and dense
//! factorization estimates of one solve: time marching (steps x periods x dofs) and the
//! branches of `ssn sweep` and `ssn solutions` (their fewest points x the work of one
//! point), so that a run that would take hours is refused (exit code 2, naming the keys
//! and the estimate) instead of running.
//!
//! Work is counted in floating-point operations at the rate of faer's dense LU, 2.3e10 per
//! second on 2 cores ([`crate::limits::DEFAULT_WORK_LIMIT`]); the per-unit costs below are
//! measured and converted at that rate.

use crate::limits::{compared, size_work, WorkEstimate};
use crate::scene::{Method, Scene, SolverSettings};

/// Operations of one time step of one dof of time marching: 1e8 dof-steps (a 10,000-element
/// rod, 2,000 steps for 5 periods) took 6.5 s on 2 loaded cores, 1,500 operations at
/// 2.3e10 per second.
pub const MARCH_FLOPS_PER_DOF_STEP: f64 = 1500.0;

/// Operations of one branch point beyond its condensed factorizations, per dof and harmonic
/// function: the per-harmonic factorizations, residuals and the point's outputs (the
/// paper's Fig. 2 sweeps take about 5 ms a point on 20 elements at H = 5).
pub const BRANCH_FLOPS_PER_DOF_FUNCTION: f64 = 5e5;

/// Corrector iterations counted per branch point (the step control aims at 4).
pub const CORRECTOR_ITERATIONS_PER_POINT: f64 = 4.0;

/// What a command runs on a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Workload {
    /// One solve (`solve`, `scene-check`, `export-model`).
    Solve,
    /// A branch over a frequency window (`sweep`, `solutions`).
    Branch,
    /// `compare`'s runs.
    Compare,
}

/// The work of the command `workload` on `scene`'s structure of `dofs` dofs and
/// `contacts` contacts: the largest of the dense factorizations of one solve
/// ([`size_work`]), time marching and, for a branch, its points.
pub fn scene_work(scene: &Scene, dofs: usize, contacts: usize, workload: Workload) -> WorkEstimate {
    let settings = compared(&scene.solver, workload == Workload::Compare);
    let size_key = if scene.model.is_some() {
        "the model's size"
    } else {
        "rod.elements"
    };
    let dense_keys = if scene.model.is_some() {
        "solver.linear_solver, solver.harmonics, the model's size"
    } else {
        "solver.linear_solver, solver.harmonics, rod.elements"
    };
    let mut estimates = vec![size_work(dofs, contacts, &settings, dense_keys)];
    if settings.method == Method::March || workload == Workload::Compare {
        estimates.push(march_work(dofs, &settings, size_key));
    }
    if workload == Workload::Branch {
        estimates.push(branch_work(scene, dofs, contacts, &settings));
    }
    estimates
        .into_iter()
        .fold(None::<WorkEstimate>, |best, e| match best {
            Some(b) if e.flops.is_nan() || e.flops <= b.flops => Some(b),
            _ => Some(e),
        })
        .expect("at least one estimate")
}

/// Time marching: at most `max_periods x steps_per_period` steps of every dof.
fn march_work(dofs: usize, settings: &SolverSettings, size_key: &'static str) -> WorkEstimate {
    let steps = settings.max_periods as f64 * settings.steps_per_period as f64;
    WorkEstimate {
        flops: steps * dofs as f64 * MARCH_FLOPS_PER_DOF_STEP,
        what: format!(
            "time marching of {dofs} dofs over up to {} periods of {} steps",
            settings.max_periods, settings.steps_per_period
        ),
        keys: match size_key {
            "rod.elements" => "solver.max_periods, solver.steps_per_period, rod.elements",
            _ => "solver.max_periods, solver.steps_per_period, the model's size",
        },
    }
}

/// A branch over the `[sweep]` window (for `ssn solutions` without one: half to twice the
/// scene's frequency): at least `range / max_step` points, each
/// [`CORRECTOR_ITERATIONS_PER_POINT`] factorizations of one solve's system and
/// [`BRANCH_FLOPS_PER_DOF_FUNCTION`] per dof and harmonic function.
fn branch_work(
    scene: &Scene,
    dofs: usize,
    contacts: usize,
    settings: &SolverSettings,
) -> WorkEstimate {
    let (range, max_step, max_points) = match &scene.sweep {
        Some(s) => (
            (s.omega_ratio_to - s.omega_ratio_from).abs(),
            s.max_step,
            s.max_points,
        ),
        None => {
            let defaults = crate::scene::SweepSettings::new(0.5, 2.0);
            // [0.5 r, 2 r] around the scene's ratio r (1 when given as omega).
            let r = match scene.frequency() {
                semismooth_contact::rod::FrequencySpec::Ratio(r) => r,
                semismooth_contact::rod::FrequencySpec::Absolute(_) => 1.0,
            };
            (1.5 * r, defaults.max_step, defaults.max_points)
        }
    };
    let points = (range / max_step).ceil().clamp(1.0, max_points as f64);
    let one = size_work(dofs, contacts, settings, "");
    let factorization = if settings.method == Method::PenaltyHb {
        one.flops / settings.max_iterations as f64
    } else {
        one.flops / 10.0
    };
    let functions = if settings.method.is_harmonic_balance() {
        2.0 * settings.harmonics as f64 + 1.0
    } else {
        settings.time_samples as f64
    };
    let per_point = CORRECTOR_ITERATIONS_PER_POINT * factorization
        + BRANCH_FLOPS_PER_DOF_FUNCTION * dofs as f64 * functions;
    WorkEstimate {
        flops: points * per_point,
        what: format!(
            "a branch of at least {points:.0} points (the window over sweep.max_step), each \
             {per_point:.1e} operations"
        ),
        keys: "sweep.max_step, sweep.omega_ratio_from/to, solver.harmonics, the structure's size",
    }
}
