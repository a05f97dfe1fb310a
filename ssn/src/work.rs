//! Up-front work estimates of whole commands, next to [`crate::limits`]' memory and dense
//! factorization estimates of one solve: time marching (steps x periods x dofs) and the
//! branches of `ssn sweep` and `ssn solutions` (their fewest points x the work of one
//! point), so that a run that would take hours is refused (exit code 2, naming the keys
//! and the estimate) instead of running.
//!
//! Work is counted in floating-point operations at the rate of faer's dense LU, 2.3e10 per
//! second on 2 cores ([`crate::limits::OPERATIONS_PER_SECOND`]); the per-unit costs below
//! are measured and converted at that rate.

use crate::limits::{compared, counted_newton_iterations, size_work, solve_work, WorkEstimate};
use crate::scene::{Scene, SolverSettings};

/// Operations of one time step of one dof of time marching: 1e8 dof-steps (a 10,000-element
/// rod, 2,000 steps for 5 periods) took 6.5 s on 2 loaded cores, 1,500 operations at
/// 2.3e10 per second.
pub const MARCH_FLOPS_PER_DOF_STEP: f64 = 1500.0;

/// Operations of one branch point beyond its corrector iterations, per dof and harmonic
/// function: the point's stability and outputs (fitted with the two constants below on the
/// beam sweeps of their documentation).
pub const BRANCH_FLOPS_PER_DOF_FUNCTION: f64 = 3e4;

/// Corrector iterations counted per branch point (the step control aims at 4; the beam
/// sweeps below took 2.6 to 3.7).
pub const CORRECTOR_ITERATIONS_PER_POINT: f64 = 4.0;

/// Branch points counted per harmonic, at least: the step control shortens the steps where
/// the contact opens and closes as `H` grows (the instants of contact move over more time
/// samples per step). `ssn sweep scenes/beam_tip_stop.toml` (window [0.5, 1.5], max_step
/// 0.05: 20 points by the window) took 74, 74, 83, 130 and 189 points at H = 50, 100, 200,
/// 400 and 600: 0.3 per harmonic from H = 400 on.
pub const BRANCH_POINTS_PER_HARMONIC: f64 = 0.3;

/// Operations of one corrector iteration of a harmonic-balance branch per contact and
/// `S^2 log2 S` (`S = 2H + 1`), beyond the solve's own iteration (`size_work`: the
/// condensed LU `(2/3) (m S)^3` and the per-harmonic solves): the dense `S x S` contact
/// block of the Jacobian, formed a column at a time by FFTs, and the products with it.
/// Fitted on `ssn sweep scenes/beam_tip_stop.toml` (41 dofs, one contact; CPU time at a
/// load of 6 on 2 cores, 2.3e10 operations per second) with its measured points and
/// corrector iterations: 0.31, 0.72, 2.5, 19 and 79 s at H = 50, 100, 200, 400 and 600
/// (194 to 697 iterations), which the model with the counted points and iterations puts
/// within 0.6 to 2.1 times (0.6 at H = 50, where the step control takes more points than
/// 0.3 per harmonic).
pub const BRANCH_FLOPS_PER_CONTACT_JACOBIAN: f64 = 200.0;

/// What a command runs on a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Workload {
    /// One solve (`solve`, `export-model`).
    Solve,
    /// `scene-check`: the natural frequencies it prints (it solves nothing).
    Check,
    /// `export-model`: the structure only (it solves and factors nothing).
    Export,
    /// A branch over a frequency window (`sweep`, `solutions`).
    Branch,
    /// `compare`'s runs.
    Compare,
}

/// The work of the command `workload` on `scene`'s structure of `dofs` dofs and
/// `contacts` contacts: the largest of the dense factorizations of one solve
/// (`size_work`, with the error estimate's solve for `solve`: `solve_work`), time
/// marching and, for a branch, its points; for `scene-check` only its natural frequencies
/// and for `export-model` nothing (they solve nothing).
pub fn scene_work(scene: &Scene, dofs: usize, contacts: usize, workload: Workload) -> WorkEstimate {
    scene_work_at(scene, (dofs, contacts), None, workload)
}

/// [`scene_work`] of a structure whose first natural frequency `omega_1` is known (an
/// imported model once built): the time marching's settling periods follow from it.
pub fn scene_work_at(
    scene: &Scene,
    (dofs, contacts): (usize, usize),
    omega_1: Option<f64>,
    workload: Workload,
) -> WorkEstimate {
    let settings = compared(&scene.solver, workload == Workload::Compare);
    let size_key = if scene.model.is_some() {
        "the model's size"
    } else {
        "rod.elements"
    };
    match workload {
        Workload::Check => return eigen_work(dofs, size_key),
        Workload::Export => {
            return WorkEstimate {
                flops: 0.0,
                what: "no solve".into(),
                keys: "",
            }
        }
        Workload::Solve | Workload::Branch | Workload::Compare => {}
    }
    let dense_keys = if scene.model.is_some() {
        "solver.linear_solver, solver.harmonics, the model's size"
    } else {
        "solver.linear_solver, solver.harmonics, rod.elements"
    };
    let mut one = match workload {
        Workload::Solve => solve_work(dofs, contacts, &settings, dense_keys),
        _ => size_work(dofs, contacts, &settings, dense_keys),
    };
    if workload != Workload::Branch {
        let counted = counted_newton_iterations(contacts, &settings);
        let expected = counted_solve_iterations(scene, contacts, &settings);
        if expected > counted {
            one.flops *= expected / counted;
            one.what += &format!(
                "; each solve counted at {expected} iterations, not {counted}: Newton stagnates \
                 on a contact dof with mass from H = {MASS_CARRYING_SMOOTHING_HARMONICS} and \
                 smoothing takes over"
            );
        }
    }
    if workload == Workload::Compare {
        return compare_work(scene, (dofs, contacts), one, omega_1, size_key);
    }
    let mut estimates = vec![one];
    if settings.method.marches() {
        estimates.push(march_work(scene, dofs, &settings, omega_1, size_key));
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

/// Harmonics from which plain Newton stagnates on an SSN-HB solve whose contact dof carries
/// mass and the smoothing strategy takes over: the rod with consistent mass and a tip stop
/// took 10 and 12 Newton iterations at H = 20 and 30, 46 at H = 40 (smoothing).
pub const MASS_CARRYING_SMOOTHING_HARMONICS: usize = 40;

/// Newton iterations counted for such a solve (and for its error estimate's solve, which
/// meets the same stagnation): measured 46, 56 and 66 at H = 40, 60 and 80 on 20 elements,
/// 46 and 47 at H = 40 and 80 on 3,000 elements.
pub const MASS_CARRYING_NEWTON_ITERATIONS: f64 = 60.0;

/// Newton iterations expected of one solve of `scene` with `settings` and `contacts`
/// contacts: [`MASS_CARRYING_NEWTON_ITERATIONS`] for SSN-HB (off the dense solver, whose
/// estimate counts its own factorizations) on a rod whose contacts carry
/// mass (consistent or lumped mass, or a stop away from the modified mass's massless tip)
/// from [`MASS_CARRYING_SMOOTHING_HARMONICS`] on, else what [`crate::limits`] counts. An
/// imported model's contact masses are not known before it is read: its count is the
/// latter.
pub fn counted_solve_iterations(scene: &Scene, contacts: usize, settings: &SolverSettings) -> f64 {
    let counted = counted_newton_iterations(contacts, settings);
    let carries_mass = rod_contact_carries_mass(scene, contacts);
    let smoothing = settings.method.carries_contact_forces()
        && settings.linear_solver != crate::scene::LinearSolverChoice::Dense
        && settings.harmonics >= MASS_CARRYING_SMOOTHING_HARMONICS;
    if carries_mass && smoothing {
        counted.max(MASS_CARRYING_NEWTON_ITERATIONS)
    } else {
        counted
    }
}

/// Operations per dof of the natural frequencies `scene-check` prints (subspace iteration
/// of 18 vectors, up to 200 iterations of 18 sparse solves and a Rayleigh-Ritz step):
/// measured on the rod, 11.2 s for 1e5 elements and 88 s for 1e6 on 2 loaded cores (load
/// 10), 2.6e6 and 2.0e6 operations per dof at 2.3e10 per second.
pub const EIGEN_FLOPS_PER_DOF: f64 = 2.6e6;

/// The natural frequencies of `dofs` dofs ([`EIGEN_FLOPS_PER_DOF`]).
fn eigen_work(dofs: usize, size_key: &'static str) -> WorkEstimate {
    WorkEstimate {
        flops: dofs as f64 * EIGEN_FLOPS_PER_DOF,
        what: format!("the natural frequencies of {dofs} dofs"),
        keys: size_key,
    }
}

/// `ssn compare`: the SSN-HB solve at [`crate::accuracy_cost::REFERENCE_HARMONICS`] (`hb`,
/// the largest of its harmonic-balance runs) plus every march it runs, which dominate:
/// [`compare_march_steps`] steps of every dof.
fn compare_work(
    scene: &Scene,
    (dofs, contacts): (usize, usize),
    hb: WorkEstimate,
    omega_1: Option<f64>,
    size_key: &'static str,
) -> WorkEstimate {
    let steps = compare_march_steps(scene, contacts, omega_1);
    let march = steps * dofs as f64 * MARCH_FLOPS_PER_DOF_STEP;
    WorkEstimate {
        flops: hb.flops + march,
        what: format!(
            "{}; and time marching of {dofs} dofs over about {steps:.1e} time steps (the \
             reference at {} and {} steps per period, the study's marches at {:?})",
            hb.what,
            crate::accuracy_cost::REFERENCE_STEPS,
            crate::accuracy_cost::REFERENCE_STEPS / 2,
            crate::accuracy_cost::MARCH_STEPS
        ),
        keys: match size_key {
            "rod.elements" => "solver.harmonics, solver.max_periods, rod.elements",
            _ => "solver.harmonics, solver.max_periods, the model's size",
        },
    }
}

/// The time steps `ssn compare` marches ([`crate::accuracy_cost`]): each of its march
/// entries ([`crate::accuracy_cost::MARCH_STEPS`] steps per period) over
/// [`counted_march_periods`], and its reference at `REFERENCE_STEPS` and half of them over
/// the periods counted at the first reference tolerance (1e-10, at most 1,000 periods). A
/// rod whose contact carries mass marches with the Moreau–Jean scheme, which chatters and
/// settles at neither tolerance: every entry runs `solver.max_periods` and the reference
/// the periods of both tolerances at `REFERENCE_STEPS` (it stops before the half).
pub fn compare_march_steps(scene: &Scene, contacts: usize, omega_1: Option<f64>) -> f64 {
    use crate::accuracy_cost::{MARCH_STEPS, REFERENCE_STEPS, REFERENCE_TOLERANCES};
    let settings = &scene.solver;
    let ladder = MARCH_STEPS.iter().sum::<usize>() as f64;
    if rod_contact_carries_mass(scene, contacts) {
        let reference: usize = REFERENCE_TOLERANCES.iter().map(|(_, p)| p).sum();
        return ladder * settings.max_periods as f64 + (REFERENCE_STEPS * reference) as f64;
    }
    let (tolerance, most) = REFERENCE_TOLERANCES[0];
    let reference_settings = SolverSettings {
        march_tolerance: tolerance,
        max_periods: most,
        ..settings.clone()
    };
    let reference = counted_march_periods(scene, &reference_settings, omega_1);
    ladder * counted_march_periods(scene, settings, omega_1)
        + (REFERENCE_STEPS + REFERENCE_STEPS / 2) as f64 * reference
}

/// Whether `scene` is a rod with `contacts` contacts one of which carries mass (consistent
/// or lumped mass, or a stop away from the modified mass's massless tip); an imported
/// model's contact masses are not known before it is read (false).
fn rod_contact_carries_mass(scene: &Scene, contacts: usize) -> bool {
    use semismooth_contact::rod::MassModel;
    let rod = &scene.rod;
    scene.model.is_none()
        && contacts > 0
        && (rod.mass != MassModel::Modified || rod.contacts.iter().any(|c| c.node != rod.elements))
}

/// Time marching: [`counted_march_periods`] of `steps_per_period` steps of every dof (the
/// error estimate's march, at half the steps from the settled state, took 0.18 to 0.24 of
/// the march's time on the rod and the beam: within the margin).
fn march_work(
    scene: &Scene,
    dofs: usize,
    settings: &SolverSettings,
    omega_1: Option<f64>,
    size_key: &'static str,
) -> WorkEstimate {
    let periods = counted_march_periods(scene, settings, omega_1);
    let steps = periods * settings.steps_per_period as f64;
    WorkEstimate {
        flops: steps * dofs as f64 * MARCH_FLOPS_PER_DOF_STEP,
        what: format!(
            "time marching of {dofs} dofs over about {periods:.0} periods (of at most {}) of {} \
             steps",
            settings.max_periods, settings.steps_per_period
        ),
        keys: match size_key {
            "rod.elements" => "solver.max_periods, solver.steps_per_period, rod.elements",
            _ => "solver.max_periods, solver.steps_per_period, the model's size",
        },
    }
}

/// Periods counted beyond the decay of the slowest free vibration: from rest the transient
/// off resonance is larger than the response it is measured against. The rod of 10
/// elements without contact (zeta 0.003 to 0.05, 0.8 to 1.3 `omega_1`) settled in 1.0 to
/// 1.33 times the decay's periods; with a stop at 0.27 to 1.0 times (a stop at resonance
/// dissipates: the estimate is then up to 4.8 times the count, on the safe side).
pub const MARCH_SETTLING_MARGIN: f64 = 1.3;

/// The periods a march from rest takes to settle on `scene` with `settings` (the first
/// natural frequency `omega_1` where known, else the clamped rod's
/// `(pi / 2) sqrt(EA / rho A) / L`): its slowest free vibration decays as `exp(-sigma t)`
/// (`sigma = zeta omega_1` for stiffness-proportional damping, `(alpha + beta omega_1^2) / 2`
/// for Rayleigh's), so the period-to-period change `x exp(-k x)`, `x = sigma T`, falls below
/// `solver.march_tolerance` after `k = ln(x / tol) / x` periods; times
/// [`MARCH_SETTLING_MARGIN`], at most `solver.max_periods`, which it is where the decay is
/// unknown (a damping matrix file) or zero.
pub fn counted_march_periods(
    scene: &Scene,
    settings: &SolverSettings,
    omega_1: Option<f64>,
) -> f64 {
    use semismooth_contact::rod::DampingSpec;
    let most = settings.max_periods as f64;
    let (damping, omega_1) = match &scene.model {
        Some(model) => (model.damping, omega_1),
        None => {
            let clamped = clamped_rod_omega_1(&scene.rod);
            (scene.rod.damping, omega_1.or(Some(clamped)))
        }
    };
    let (Some(damping), Some(omega_1)) = (damping, omega_1) else {
        return most;
    };
    let sigma = match damping {
        DampingSpec::StiffnessProportional { zeta } => zeta * omega_1,
        DampingSpec::Rayleigh { alpha, beta } => 0.5 * (alpha + beta * omega_1 * omega_1),
    };
    let x = sigma * 2.0 * std::f64::consts::PI / scene.omega(omega_1);
    let tolerance = settings.march_tolerance;
    if !(x > 0.0 && x.is_finite() && tolerance > 0.0) {
        return most;
    }
    let periods = MARCH_SETTLING_MARGIN * (x / tolerance).ln().max(1.0) / x;
    periods.ceil().clamp(2.0, most)
}

/// The first natural frequency of the continuous clamped-free rod, `(pi / 2) c / L` with the
/// wave speed `c = sqrt(EA / rho A)`: the estimate of a rod scene's `omega_1` before it is
/// built.
fn clamped_rod_omega_1(rod: &semismooth_contact::rod::RodSpec) -> f64 {
    let wave_speed = (rod.axial_stiffness / rod.mass_per_length).sqrt();
    std::f64::consts::FRAC_PI_2 * wave_speed / rod.length
}

/// A branch over the `[sweep]` window (for `ssn solutions` without one: half to twice the
/// scene's frequency): [`counted_branch_points`], each
/// [`CORRECTOR_ITERATIONS_PER_POINT`] iterations of one solve's linear algebra (a
/// factorization, or the matrix-free path's GMRES) and contact blocks
/// ([`BRANCH_FLOPS_PER_CONTACT_JACOBIAN`] `m S^2 log2 S`), and
/// [`BRANCH_FLOPS_PER_DOF_FUNCTION`] per dof and harmonic function.
fn branch_work(
    scene: &Scene,
    dofs: usize,
    contacts: usize,
    settings: &SolverSettings,
) -> WorkEstimate {
    let points = counted_branch_points(scene, settings);
    let one = size_work(dofs, contacts, settings, "");
    let factorization = one.flops / counted_newton_iterations(contacts, settings);
    let functions = if settings.method.is_harmonic_balance() {
        2.0 * settings.harmonics as f64 + 1.0
    } else {
        settings.time_samples as f64
    };
    let contact_jacobian = if settings.method.is_harmonic_balance() {
        BRANCH_FLOPS_PER_CONTACT_JACOBIAN
            * contacts as f64
            * functions
            * functions
            * functions.log2()
    } else {
        0.0
    };
    let stability = point_stability_work(scene, dofs, settings);
    let per_point = CORRECTOR_ITERATIONS_PER_POINT * (factorization + contact_jacobian)
        + BRANCH_FLOPS_PER_DOF_FUNCTION * dofs as f64 * functions
        + stability;
    WorkEstimate {
        flops: points * per_point,
        what: format!(
            "a branch of at least {points:.0} points (the window over sweep.max_step, and \
             {BRANCH_POINTS_PER_HARMONIC} per harmonic), each {per_point:.1e} operations \
             ({stability:.1e} its stability)"
        ),
        keys: "sweep.max_step, sweep.omega_ratio_from/to, solver.harmonics, the structure's size",
    }
}

/// Operations of one point's stability per cubed state dimension `(2N)^3`: the products of
/// the phase propagators (`10 d^3` each, two phases for a contact that opens and closes)
/// and the monodromy's eigenvalues (`25 d^3`), the library's own count
/// ([`semismooth_contact::stability::MAX_WORK`]'s).
pub const STABILITY_FLOPS_PER_CUBED_STATE: f64 = 45.0;

/// The stability analysis of one branch point of a harmonic-balance sweep that asks for it
/// ([`STABILITY_FLOPS_PER_CUBED_STATE`] `(2N)^3`), at most the library's limit
/// [`semismooth_contact::stability::MAX_WORK`] (above it the point is left undecided), and
/// none above [`semismooth_contact::stability::MAX_DOFS`] dofs or with friction (not
/// analysed).
fn point_stability_work(scene: &Scene, dofs: usize, settings: &SolverSettings) -> f64 {
    use semismooth_contact::stability::{MAX_DOFS, MAX_WORK};
    let asked = scene.sweep.as_ref().is_some_and(|s| s.stability);
    let friction = (scene.model.as_ref())
        .is_some_and(|m| !m.friction.is_empty() || !m.frictional_contacts.is_empty());
    if !asked || friction || dofs > MAX_DOFS || !settings.method.is_harmonic_balance() {
        return 0.0;
    }
    (STABILITY_FLOPS_PER_CUBED_STATE * (2.0 * dofs as f64).powi(3)).min(MAX_WORK)
}

/// Points counted for the branch of `scene` with `settings` (`sweep` and `solutions`): its
/// window over `sweep.max_step` and, for harmonic balance, [`BRANCH_POINTS_PER_HARMONIC`]
/// `H`, whichever is more, at most `sweep.max_points`; each
/// [`CORRECTOR_ITERATIONS_PER_POINT`] corrector iterations.
pub fn counted_branch_points(scene: &Scene, settings: &SolverSettings) -> f64 {
    let (range, max_step, max_points) = match &scene.sweep {
        Some(s) => {
            // Bounds not yet resolved to ratios (a rod before it is built): the continuum's
            // omega_1, within 0.03 % of the discrete rod's at 20 elements.
            let (from, to) = scene.sweep_ratio_window(s, clamped_rod_omega_1(&scene.rod));
            ((to - from).abs(), s.max_step, s.max_points)
        }
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
    let by_harmonics = if settings.method.is_harmonic_balance() {
        BRANCH_POINTS_PER_HARMONIC * settings.harmonics as f64
    } else {
        0.0
    };
    (range / max_step)
        .ceil()
        .max(by_harmonics)
        .clamp(1.0, max_points as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scene `text` at `harmonics`.
    fn at_harmonics(text: &str, harmonics: usize) -> Scene {
        let mut scene = Scene::from_toml(text, "scene.toml").unwrap();
        scene.solver.harmonics = harmonics;
        scene
    }

    /// `scenes/paper_fig1.toml` (20 elements, one contact at the tip) at `harmonics`.
    fn paper_fig1(harmonics: usize) -> Scene {
        at_harmonics(include_str!("../../scenes/paper_fig1.toml"), harmonics)
    }

    /// `scenes/beam_tip_stop.toml` (41 dofs, one contact) at `harmonics`.
    fn beam(harmonics: usize) -> Scene {
        at_harmonics(include_str!("../../scenes/beam_tip_stop.toml"), harmonics)
    }

    #[test]
    fn beam_sweeps_are_estimated_within_a_factor_three_of_their_measured_work() {
        // `ssn sweep scenes/beam_tip_stop.toml --set solver.harmonics=H`, CPU seconds at a
        // load of 6 on 2 cores (the constants' documentation), at 2.3e10 operations per
        // second; every branch reached the end of its window.
        for (harmonics, seconds) in [(100, 0.72), (200, 2.46), (400, 19.19), (600, 79.16)] {
            let e = scene_work(&beam(harmonics), 41, 1, Workload::Branch);
            let measured = seconds * 2.3e10;
            assert!(
                (measured / 3.0..3.0 * measured).contains(&e.flops),
                "H = {harmonics}: {e:?} against {measured:e}"
            );
        }
        // H = 1000 ran more than 1,247 s of CPU (stopped there): refused by default.
        let e = scene_work(&beam(1000), 41, 1, Workload::Branch);
        assert!(e.flops > crate::limits::DEFAULT_WORK_LIMIT, "{e:?}");
        assert!(e.what.contains("300 points"), "{e:?}");
    }

    #[test]
    fn the_paper_rods_solutions_are_estimated_above_a_third_of_their_measured_work() {
        // `ssn solutions` measured in CPU seconds at a load of 5 to 6 on 2 cores: 4.1 s at
        // H = 200 (63 points), 43 s at H = 400 (107), 172 s at H = 1000 (68). Each branch
        // stopped before the end of its window (`incomplete`), so these are lower bounds of
        // the work of a whole branch, which the estimate counts: at least a third of them.
        for (harmonics, seconds) in [(200, 4.11), (400, 42.9), (1000, 172.4)] {
            let e = scene_work(&paper_fig1(harmonics), 20, 1, Workload::Branch);
            let measured = seconds * 2.3e10;
            assert!(e.flops >= measured / 3.0, "H = {harmonics}: {e:?}");
        }
        // H = 2000 ran more than 1,058 s: the estimate is at least that.
        let e = scene_work(&paper_fig1(2000), 20, 1, Workload::Branch);
        assert!(e.flops >= 1058.0 * 2.3e10, "{e:?}");
        assert!(e.what.contains("points"), "{e:?}");
    }
}
