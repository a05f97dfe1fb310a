//! 3-D frictional contacts (a normal row and two tangent rows under the Coulomb disk) in
//! SSN-HB, against closed forms that need no code of ours.
//!
//! - A point sliding on a circle of radius `r` under a constant normal force `N` feels a
//!   force of constant magnitude `mu N` opposite to its velocity: it dissipates
//!   `2 pi mu N r` per cycle and the force is a pure first harmonic, so harmonic balance is
//!   exact at any `H >= 1`. The isotropic oscillator `m x'' + c x' + k x = F e^{i w t} +
//!   lambda_t` then slides on the circle of radius `r` with
//!   `((k - m w^2)^2 + c^2 w^2) r^2 + 2 c w b r + b^2 - F^2 = 0`, `b = mu N`.
//! - On an ellipse of semi-axes `a >= b_e` the dissipated energy is `mu N` times the
//!   perimeter, `4 mu N a E(e)` with `e^2 = 1 - b_e^2 / a^2` and `E` the complete elliptic
//!   integral of the second kind (computed here by the arithmetic-geometric mean).
//! - With a spring `k_t` in series with the slider (3-D Jenkins element, the slider a
//!   massless internal pair of dofs), a circle of radius `r` drags the slider on a circle
//!   of radius `sqrt(r^2 - (mu N / k_t)^2)` (the spring, stretched by `mu N / k_t`, pulls
//!   the slider along its velocity, at right angles to the radius of the slider's circle):
//!   the energy is `2 pi mu N sqrt(r^2 - (mu N / k_t)^2)`.
//! - Two independent one-dimensional laws on the same circle give a square wave in each
//!   direction: `8 mu N r`, a factor `4 / pi` too much.
//!
//! The ellipse, the Jenkins element and the two 1-D laws are driven kinematically: the
//! point is tied to an imposed orbit `X(t)` by a stiff spring `K_d` (load `K_d X(t)`), so
//! its orbit is `X` up to `mu N / K_d`; the closed forms are evaluated on the orbit the
//! solver returns (its first harmonic).

use semismooth::linalg::FaerDenseLu;
use semismooth::{Factorize, Residual};
use semismooth_contact::hb::{CondensedSolve, HbJacobian, HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::model::{
    ContactPoint, ContactRow, FrictionPoint, FrictionalContact, HarmonicLoad, SparseMatrix,
    StructuralModel,
};
use std::f64::consts::PI;

#[path = "common/rotating_oscillator.rs"]
mod rotating_oscillator;
use rotating_oscillator::{circle_radius, diagonal, max_difference, solved_from_zero};
use rotating_oscillator::{DAMPING, FORCE, MASS, OMEGA, STIFFNESS};

/// A model with diagonal `M`, `D`, `K`, `load` and no contact.
fn model(
    mass: &[f64],
    damping: &[f64],
    stiffness: SparseMatrix,
    load: HarmonicLoad,
) -> StructuralModel {
    StructuralModel {
        mass: diagonal(mass),
        damping: Some(diagonal(damping)),
        stiffness,
        load,
        contacts: Vec::new(),
        friction: Vec::new(),
        frictional_contacts: Vec::new(),
        cyclic: None,
    }
}

/// SSN-HB on `model` at `omega` solved from zero with `solver` to `|F| <= tolerance`
/// (the model's default complementarity constant).
fn solve(
    model: &StructuralModel,
    at: (f64, usize, f64),
    solver: &mut dyn Factorize<HbJacobian>,
) -> (SsnHb, Vec<f64>) {
    solve_with_c(model, at, None, solver)
}

/// [`solve`] with the complementarity constant `c` (`None`: the model's default).
fn solve_with_c(
    model: &StructuralModel,
    (omega, harmonics, tolerance): (f64, usize, f64),
    c: Option<f64>,
    solver: &mut dyn Factorize<HbJacobian>,
) -> (SsnHb, Vec<f64>) {
    let options = HbOptions {
        harmonics,
        c,
        ..HbOptions::default()
    };
    let mut hb = SsnHb::new(model, omega, &options).unwrap();
    let x = solved_from_zero(&mut hb, solver, tolerance);
    (hb, x)
}

/// SSN-HB on `model` through the dense LU, the condensed dense LU and matrix-free GMRES on
/// the condensed system, each to `|F| <= 1e-12`; asserts that they agree within
/// `agreement` and returns the dense path's problem and solution.
fn solve_on_every_path(
    model: &StructuralModel,
    (omega, harmonics): (f64, usize),
    agreement: f64,
) -> (SsnHb, Vec<f64>) {
    let at = (omega, harmonics, 1e-12);
    let (hb, dense) = solve(model, at, &mut FaerDenseLu::new());
    let condensed = StructuredHbSolver::new().with_condensed_solve(CondensedSolve::Dense);
    let (_, condensed) = solve(model, at, &mut { condensed });
    let krylov = StructuredHbSolver::new().with_condensed_solve(CondensedSolve::Krylov);
    let (_, krylov) = solve(model, at, &mut { krylov });
    for other in [&condensed, &krylov] {
        let gap = max_difference(&dense, other);
        assert!(gap < agreement, "H = {harmonics}: paths differ by {gap:e}");
    }
    (hb, dense)
}

/// The first-harmonic amplitude of `dof` (`U` index `j N + dof`).
fn first_harmonic(x: &[f64], dofs: usize, dof: usize) -> (f64, f64) {
    (x[dofs + dof], x[2 * dofs + dof])
}

/// The complete elliptic integral of the second kind `E(e)` by the arithmetic-geometric
/// mean: `E = K (1 - sum_n 2^(n-1) c_n^2)`, `K = pi / (2 AGM(1, sqrt(1 - e^2)))`
/// (quadratic convergence: ten steps reach round-off).
fn elliptic_e(e: f64) -> f64 {
    let (mut a, mut b, mut c) = (1.0f64, (1.0 - e * e).sqrt(), e);
    let (mut sum, mut weight) = (0.5 * c * c, 0.5);
    for _ in 0..10 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        c = 0.5 * (a - b);
        weight *= 2.0;
        sum += weight * c * c;
        (a, b) = (an, bn);
    }
    PI / (2.0 * a) * (1.0 - sum)
}

#[test]
fn the_elliptic_integral_has_its_known_values() {
    // E(0) = pi / 2 and E(1 / sqrt 2) = 1.3506438810476755 (Abramowitz & Stegun 17.3).
    assert!((elliptic_e(0.0) - PI / 2.0).abs() < 1e-15);
    assert!((elliptic_e(0.5f64.sqrt()) - 1.350_643_881_047_675_5).abs() < 1e-14);
}

// The circle under the normal law: an oscillator (x, y, z) pressed along z against an
// obstacle at `z <= GAP` by a constant load, driven in (x, y) by a rotating load.
const MU: f64 = 0.3;
const PRESS: f64 = 2.0;
const GAP: f64 = 0.5;

/// The pressed rotating oscillator: the normal force is `-(PRESS - STIFFNESS GAP)`.
fn pressed_rotor() -> StructuralModel {
    let mut load = HarmonicLoad::zero(3);
    load.add_harmonic(0, &[0.0, 0.0, PRESS], &[0.0; 3]).unwrap();
    load.add_harmonic(1, &[FORCE, 0.0, 0.0], &[0.0, FORCE, 0.0])
        .unwrap();
    let mut model = model(&[MASS; 3], &[DAMPING; 3], diagonal(&[STIFFNESS; 3]), load);
    model
        .frictional_contacts
        .push(FrictionalContact::unilateral(
            ContactRow::unit(2, 1.0),
            GAP,
            [ContactRow::unit(0, 1.0), ContactRow::unit(1, 1.0)],
            MU,
        ));
    model
}

/// A point pressed by the normal law slides on the circle of the closed form, through the
/// dense, condensed and matrix-free linear paths alike, with a pure first-harmonic force,
/// and dissipates `2 pi mu N r` per cycle: exact at `H = 1` and at `H = 4`.
#[test]
fn a_pressed_point_on_a_circle_dissipates_two_pi_mu_n_r_with_a_first_harmonic_force() {
    let model = pressed_rotor();
    let normal = PRESS - STIFFNESS * GAP;
    let radius = circle_radius(MU * normal);
    for harmonics in [1, 4] {
        // Each path stops at |F| <= 1e-12 on an O(1) problem with an O(10)-conditioned
        // Jacobian: the iterates agree far below 1e-10.
        let (hb, dense) = solve_on_every_path(&model, (OMEGA, harmonics), 1e-10);
        // Every sample of the laws is exact on the circle: only Newton's error remains.
        for dof in 0..2 {
            let (a, b) = first_harmonic(&dense, 3, dof);
            assert!((a.hypot(b) - radius).abs() < 1e-10, "H = {harmonics}");
        }
        let report = hb.frictional_contact_report(&dense, 0, 64).unwrap();
        let expected = 2.0 * PI * MU * normal * radius;
        assert!(
            (report.dissipated_energy - expected).abs() < 1e-10 * expected,
            "H = {harmonics}: {} against {expected}",
            report.dissipated_energy
        );
        assert_eq!(
            (
                report.slip_fraction,
                report.stick_fraction,
                report.separated_fraction
            ),
            (1.0, 0.0, 0.0)
        );
        for f in report.normal_force {
            assert!((f + normal).abs() < 1e-10);
        }
        // The forces (index U_len + j m + row; rows: normal, t1, t2) beyond harmonic 1
        // vanish, and the normal force is constant.
        let (lambda, m) = (&dense[3 * (2 * harmonics + 1)..], 3);
        for (i, value) in lambda.iter().enumerate() {
            let (j, row) = (i / m, i % m);
            let expected_zero = if row == 0 {
                j != 0
            } else {
                !(1..=2).contains(&j)
            };
            if expected_zero {
                assert!(value.abs() < 1e-10, "harmonic {j} of row {row}: {value:e}");
            }
        }
    }
}

// The kinematically driven point: a stiff spring `DRIVE` to the imposed orbit, a unit
// mass, the slip limit `SLIP` (`mu = 0.5` under `N = 2`).
const DRIVE: f64 = 1e6;
const SLIP_MU: f64 = 0.5;
const NORMAL_LOAD: f64 = 2.0;
const SLIP: f64 = SLIP_MU * NORMAL_LOAD;
const DRIVE_OMEGA: f64 = 1.0;

/// Two unit masses tied by springs `drive` to the orbit `(a cos t, b sin t)` (the load
/// `drive (a cos t, b sin t)`), among `dofs` dofs (the others massless) with `stiffness`;
/// no friction yet.
fn driven((a, b, drive): (f64, f64, f64), stiffness: SparseMatrix, dofs: usize) -> StructuralModel {
    let mut load = HarmonicLoad::zero(dofs);
    let (mut cosine, mut sine) = (vec![0.0; dofs], vec![0.0; dofs]);
    cosine[0] = drive * a;
    sine[1] = drive * b;
    load.add_harmonic(1, &cosine, &sine).unwrap();
    let mut mass = vec![0.0; dofs];
    mass[..2].fill(1.0);
    model(&mass, &vec![0.0; dofs], stiffness, load)
}

/// The disk under the prescribed load on the rows of dofs `first`, `first + 1`.
fn prescribed_disk(first: usize) -> FrictionalContact {
    FrictionalContact::prescribed(
        NORMAL_LOAD,
        [
            ContactRow::unit(first, 1.0),
            ContactRow::unit(first + 1, 1.0),
        ],
        SLIP_MU,
    )
}

/// The semi-axes of the orbit `P cos t + Q sin t` of the first harmonics of dofs 0, 1:
/// the singular values of `[P Q]`.
fn semi_axes(x: &[f64], dofs: usize) -> (f64, f64) {
    let (p0, q0) = first_harmonic(x, dofs, 0);
    let (p1, q1) = first_harmonic(x, dofs, 1);
    // Eigenvalues of [P Q]^T [P Q].
    let (a, b, c) = (p0 * p0 + p1 * p1, p0 * q0 + p1 * q1, q0 * q0 + q1 * q1);
    let (mean, half) = (0.5 * (a + c), (0.25 * (a - c) * (a - c) + b * b).sqrt());
    ((mean + half).sqrt(), (mean - half).max(0.0).sqrt())
}

/// A point driven on an ellipse (semi-axes 1 and 0.6) dissipates `mu N` times its
/// perimeter `4 a E(e)`, at every `H` (a table of the relative error against `H`).
#[test]
fn a_point_on_an_ellipse_dissipates_mu_n_times_its_perimeter() {
    let mut model = driven((1.0, 0.6, DRIVE), diagonal(&[DRIVE; 2]), 2);
    model.frictional_contacts.push(prescribed_disk(0));
    for harmonics in [1, 2, 4, 8] {
        // |F| <= 1e-6 on loads of size DRIVE = 1e6 is round-off level.
        let (hb, x) = solve(
            &model,
            (DRIVE_OMEGA, harmonics, 1e-6),
            &mut FaerDenseLu::new(),
        );
        let (major, minor) = semi_axes(&x, 2);
        let e = (1.0 - (minor / major).powi(2)).sqrt();
        let expected = 4.0 * SLIP * major * elliptic_e(e);
        let report = hb.frictional_contact_report(&x, 0, 512).unwrap();
        let error = (report.dissipated_energy / expected - 1.0).abs();
        println!(
            "H = {harmonics}: energy {:.12} closed form {expected:.12} relative error {error:.1e}",
            report.dissipated_energy
        );
        // The orbit is an ellipse up to the friction's pull, SLIP / DRIVE = 1e-6 of its
        // size, in the higher harmonics; the rectangle rule on 512 samples of the smooth
        // force is exact to far below that.
        assert!(error < 1e-5, "H = {harmonics}: relative error {error:e}");
        assert_eq!(report.slip_fraction, 1.0);
    }
}

/// The driven point (drive stiffness `drive`) with a hand-built 3-D Jenkins element: springs
/// `kt` from dofs 0, 1 to the massless sliders 2, 3 written in `K`, the disk on the sliders.
fn hand_built_jenkins(kt: f64, drive: f64) -> StructuralModel {
    let mut entries = Vec::new();
    for d in 0..2 {
        let (x, s) = (d, d + 2);
        for (i, j, v) in [(x, x, drive + kt), (x, s, -kt), (s, x, -kt), (s, s, kt)] {
            entries.push(faer::sparse::Triplet::new(i, j, v));
        }
    }
    let stiffness = SparseMatrix::try_new_from_triplets(4, 4, &entries).unwrap();
    let mut model = driven((1.0, 1.0, drive), stiffness, 4);
    model.frictional_contacts.push(prescribed_disk(2));
    model
}

/// A 3-D Jenkins element (spring `k_t` to a massless slider pair under the disk) driven on
/// a circle dissipates `2 pi mu N sqrt(r^2 - (mu N / k_t)^2)`, exactly at `H = 1`.
#[test]
fn a_jenkins_element_on_a_circle_dissipates_the_closed_form_energy() {
    // On a circle the drive's stiffness does not matter: a soft one keeps every dof's
    // residual O(1), and Newton's tolerance 1e-12 gives the energy to ~1e-11.
    let (kt, drive) = (2.0 * SLIP, 10.0);
    let model = hand_built_jenkins(kt, drive);
    for harmonics in [1, 3] {
        let (hb, x) = solve(
            &model,
            (DRIVE_OMEGA, harmonics, 1e-12),
            &mut FaerDenseLu::new(),
        );
        let (r, minor) = semi_axes(&x, 4);
        assert!((r - minor).abs() < 1e-10, "a circle: {r} and {minor}");
        let expected = 2.0 * PI * SLIP * (r * r - (SLIP / kt).powi(2)).sqrt();
        let report = hb.frictional_contact_report(&x, 0, 64).unwrap();
        // Exact on the circle: Newton's error alone.
        let error = (report.dissipated_energy / expected - 1.0).abs();
        assert!(error < 1e-10, "H = {harmonics}: relative error {error:e}");
    }
}

/// Two independent 1-D Coulomb laws on the same driven circle dissipate `8 mu N r`, the
/// square's `4 / pi` times the disk's `2 pi mu N r`: they are not the disk.
#[test]
fn two_independent_one_dimensional_laws_do_not_dissipate_the_disk_energy() {
    let mut model = driven((1.0, 1.0, DRIVE), diagonal(&[DRIVE; 2]), 2);
    for d in 0..2 {
        model.friction.push(FrictionPoint::prescribed(
            ContactRow::unit(d, 1.0),
            SLIP_MU,
            NORMAL_LOAD,
        ));
    }
    let points = 1024;
    let (hb, x) = solve(&model, (DRIVE_OMEGA, 8, 1e-6), &mut FaerDenseLu::new());
    let (r, _) = semi_axes(&x, 2);
    let period = 2.0 * PI / DRIVE_OMEGA;
    let energy: f64 = (0..2)
        .map(|f| {
            let report = hb.friction_report(&x, f, points).unwrap();
            let power: f64 = report
                .force
                .iter()
                .zip(&report.slip_velocity)
                .map(|(f, v)| f * v)
                .sum();
            -power * period / points as f64
        })
        .sum();
    // The rectangle rule on the square wave's two jumps per period errs by O(1 / points).
    let square = 8.0 * SLIP * r;
    assert!(
        (energy / square - 1.0).abs() < 1e-2,
        "{energy} against {square}"
    );
    let disk = 2.0 * PI * SLIP * r;
    assert!(energy / disk > 1.2, "{energy} against the disk's {disk}");
}

/// A mass on (x, y) pressed on a flat by a massless normal dof z (spring 10, preload
/// through the gap -0.05: `N = 0.5` at rest) under a normal load `0.8 cos(w t)` that lifts
/// it off for part of each period, driven in the plane by `(fx cos w t, fy sin w t)`, with
/// `mu = 0.4`.
fn lifting(fx: f64, fy: f64) -> StructuralModel {
    let mut load = HarmonicLoad::zero(3);
    load.add_harmonic(1, &[fx, 0.0, 0.8], &[0.0, fy, 0.0])
        .unwrap();
    let stiffness = diagonal(&[1.0, 1.0, 10.0]);
    model(&[1.0, 1.0, 0.0], &[0.1, 0.1, 0.0], stiffness, load)
}

/// With the motion along one tangent only, the disk is the interval: the 3-D contact
/// reproduces the 1-D friction point on a unilateral contact (another formulation of the
/// library, checked against time marching elsewhere) through liftoff, to Newton's
/// tolerance.
#[test]
fn a_disk_moving_along_one_tangent_is_the_one_dimensional_law_through_liftoff() {
    let (w, harmonics) = (0.8, 10);
    let mut disk = lifting(0.3, 0.0);
    disk.frictional_contacts.push(FrictionalContact::unilateral(
        ContactRow::unit(2, 1.0),
        -0.05,
        [ContactRow::unit(0, 1.0), ContactRow::unit(1, 1.0)],
        0.4,
    ));
    let mut line = lifting(0.3, 0.0);
    line.contacts.push(ContactPoint::new(2, -0.05));
    line.friction
        .push(FrictionPoint::on_contact(ContactRow::unit(0, 1.0), 0.4, 0));
    // One `c` for both (the truncated equations' solution depends on it; the models'
    // defaults differ by their rows).
    let at = (w, harmonics, 1e-12);
    let (hb, x_disk) = solve_with_c(&disk, at, Some(10.0), &mut FaerDenseLu::new());
    let (_, x_line) = solve_with_c(&line, at, Some(10.0), &mut FaerDenseLu::new());
    // U (3 (2H + 1)) agrees; the disk's forces are (normal, t1, t2), the line's
    // (normal, t1).
    let size = 2 * harmonics + 1;
    let gap = (0..3 * size).fold(0.0f64, |a, i| a.max((x_disk[i] - x_line[i]).abs()));
    assert!(gap < 1e-9, "displacements differ by {gap:e}");
    for j in 0..size {
        let (disk_forces, line_forces) = (&x_disk[3 * size + 3 * j..], &x_line[3 * size + 2 * j..]);
        assert!((disk_forces[0] - line_forces[0]).abs() < 1e-9);
        assert!((disk_forces[1] - line_forces[1]).abs() < 1e-9);
        assert!(disk_forces[2].abs() < 1e-9);
    }
    let report = hb.frictional_contact_report(&x_disk, 0, 512).unwrap();
    assert!(report.separated_fraction > 0.1, "{report:?}");
}

/// With a turning slip and liftoff (the disk's radius follows the normal force to zero),
/// the dense, condensed and matrix-free linear paths give one solution, which slips and
/// separates over parts of the period.
#[test]
fn a_turning_slip_with_liftoff_agrees_across_linear_paths() {
    let mut model = lifting(0.3, 0.2);
    model
        .frictional_contacts
        .push(FrictionalContact::unilateral(
            ContactRow::unit(2, 1.0),
            -0.05,
            [ContactRow::unit(0, 1.0), ContactRow::unit(1, 1.0)],
            0.4,
        ));
    // |F| <= 1e-12 with an O(100)-conditioned Jacobian: agreement far below 1e-9.
    let (hb, dense) = solve_on_every_path(&model, (0.8, 10), 1e-9);
    let report = hb.frictional_contact_report(&dense, 0, 512).unwrap();
    println!(
        "stick {} slip {} separated {} energy {}",
        report.stick_fraction,
        report.slip_fraction,
        report.separated_fraction,
        report.dissipated_energy
    );
    assert!(
        report.separated_fraction > 0.05 && report.slip_fraction > 0.05,
        "{report:?}"
    );
    assert!(report.dissipated_energy > 0.0);
    let total = report.stick_fraction + report.slip_fraction + report.separated_fraction;
    assert!((total - 1.0).abs() < 1e-12);
}

// The point pressed on a moving obstacle: static load, stiffness along z, mean gap, and the
// gap's motion `0.1 cos w t + 0.05 sin 2 w t`.
const MOVING_OMEGA: f64 = 1.3;
const PRESS_Z: f64 = 3.0;
const STIFFNESS_Z: f64 = 4.0;
const GAP_Z: f64 = 0.25;
const MOVING_GAP: (f64, f64) = (0.1, 0.05);

/// Unit masses (damping 0.05) on springs (1, 1, 4), pressed along z on an obstacle whose gap
/// moves by `MOVING_GAP` and which slides past at `velocity` in the (x, y) plane.
fn pressed_on_moving_obstacle(velocity: [f64; 2]) -> StructuralModel {
    let mut load = HarmonicLoad::zero(3);
    load.add_harmonic(0, &[0.0, 0.0, PRESS_Z], &[0.0; 3])
        .unwrap();
    let stiffness = diagonal(&[1.0, 1.0, STIFFNESS_Z]);
    let mut model = model(&[1.0; 3], &[DAMPING; 3], stiffness, load);
    let (a1, b2) = MOVING_GAP;
    model.frictional_contacts.push(
        FrictionalContact::unilateral(
            ContactRow::unit(2, 1.0),
            GAP_Z,
            [ContactRow::unit(0, 1.0), ContactRow::unit(1, 1.0)],
            MU,
        )
        .with_moving_gap(vec![a1, 0.0], vec![0.0, b2])
        .with_sliding_velocity(velocity),
    );
    model
}

/// A point pressed (static load 3, stiffness 4 along z) against an obstacle whose gap moves,
/// `gap(t) = 0.25 + 0.1 cos w t + 0.05 sin 2 w t`, follows it while the contact holds, so
/// its normal force is `m z'' + c z' + k z - P` with `z = gap(t)`: a constant, a first and a
/// second harmonic, exact at `H = 2` through every linear path; undriven in the plane, it
/// sticks with no tangential force.
#[test]
fn a_point_pressed_on_a_moving_obstacle_carries_the_closed_form_normal_force() {
    let (w, press, stiffness, damping, gap) = (MOVING_OMEGA, PRESS_Z, STIFFNESS_Z, DAMPING, GAP_Z);
    let (a1, b2) = MOVING_GAP;
    let model = pressed_on_moving_obstacle([0.0; 2]);
    // Coefficients (constant, cos 1, sin 1, cos 2, sin 2) of the normal force.
    let expected = [
        stiffness * gap - press,
        (stiffness - w * w) * a1,
        -damping * w * a1,
        2.0 * damping * w * b2,
        (stiffness - 4.0 * w * w) * b2,
    ];
    for harmonics in [2, 4] {
        // |F| <= 1e-12 on an O(1) problem: the paths agree far below 1e-10.
        let (hb, dense) = solve_on_every_path(&model, (w, harmonics), 1e-10);
        let size = 2 * harmonics + 1;
        let lambda = &dense[3 * size..];
        for (j, value) in lambda.iter().step_by(3).enumerate() {
            let expected = expected.get(j).copied().unwrap_or(0.0);
            // Every sample of the laws is exact: Newton's error alone.
            assert!(
                (value - expected).abs() < 1e-10,
                "H = {harmonics}, coefficient {j}: {value} against {expected}"
            );
        }
        // The point follows the gap: z's coefficients are the gap's.
        let z = |j: usize| dense[j * 3 + 2];
        let gap_coefficients = [gap, a1, 0.0, 0.0, b2];
        for (j, g) in gap_coefficients.iter().enumerate() {
            assert!(
                (z(j) - g).abs() < 1e-10,
                "H = {harmonics}: z_{j} = {}",
                z(j)
            );
        }
        let report = hb.frictional_contact_report(&dense, 0, 64).unwrap();
        assert_eq!(report.stick_fraction, 1.0);
        assert!(report.dissipated_energy.abs() < 1e-12);
    }
    // A gap on harmonic 2 does not fit a basis of one harmonic.
    let options = HbOptions {
        harmonics: 1,
        ..HbOptions::default()
    };
    assert!(SsnHb::new(&model, w, &options).is_err());
}

/// The same pressed point under an obstacle that also slides past at `v = (2, 1)`, far
/// faster than the point moves: the friction force is `mu N(t) v / |v|` with the closed-form
/// `N(t)`, the point's tangential motion the linear response to it, and the energy
/// `mu |v| N_0 T - mu int N (u' . v / |v|) dt`; all exact at `H = 2`. The residual's
/// `w`-derivative (the obstacle's offset `v / w` moves with `w`) matches central differences.
#[test]
fn a_point_under_a_sliding_moving_obstacle_is_dragged_by_the_closed_form_force() {
    use semismooth::ParameterDependent;
    let (w, press, stiffness, damping, gap) = (MOVING_OMEGA, PRESS_Z, STIFFNESS_Z, DAMPING, GAP_Z);
    let ((a1, b2), velocity) = (MOVING_GAP, [2.0, 1.0]);
    let model = pressed_on_moving_obstacle(velocity);
    // N = -lambda_n: coefficients (constant, cos 1, sin 1, cos 2, sin 2).
    let normal = [
        press - stiffness * gap,
        -(stiffness - w * w) * a1,
        damping * w * a1,
        -2.0 * damping * w * b2,
        -(stiffness - 4.0 * w * w) * b2,
    ];
    let speed = velocity[0].hypot(velocity[1]);
    let direction = [velocity[0] / speed, velocity[1] / speed];
    // The scalar response along `direction` to `mu N(t)`: unit mass, stiffness and damping.
    let mut response = [MU * normal[0], 0.0, 0.0, 0.0, 0.0];
    for h in 1..=2 {
        let (kk, cw) = (1.0 - (h as f64 * w).powi(2), damping * h as f64 * w);
        let (fc, fs) = (MU * normal[2 * h - 1], MU * normal[2 * h]);
        let det = kk * kk + cw * cw;
        response[2 * h - 1] = (kk * fc - cw * fs) / det;
        response[2 * h] = (cw * fc + kk * fs) / det;
    }
    let period = 2.0 * PI / w;
    let mut drag = 0.0;
    for h in 1..=2 {
        let hw = h as f64 * w;
        let (velocity_c, velocity_s) = (hw * response[2 * h], -hw * response[2 * h - 1]);
        drag += 0.5 * period * (normal[2 * h - 1] * velocity_c + normal[2 * h] * velocity_s);
    }
    let energy = MU * speed * normal[0] * period - MU * drag;
    let harmonics = 2;
    let (mut hb, x) = solve(&model, (w, harmonics, 1e-12), &mut FaerDenseLu::new());
    let size = 2 * harmonics + 1;
    for j in 0..size {
        for (a, e) in direction.iter().enumerate() {
            // Every sample of the laws is exact: Newton's error alone.
            let force = x[3 * size + 3 * j + 1 + a];
            assert!(
                (force - MU * normal[j] * e).abs() < 1e-10,
                "force {a} coefficient {j}"
            );
            let displacement = x[3 * j + a];
            assert!(
                (displacement - response[j] * e).abs() < 1e-10,
                "u_{a} coefficient {j}"
            );
        }
    }
    let report = hb.frictional_contact_report(&x, 0, 64).unwrap();
    assert!(
        (report.dissipated_energy - energy).abs() < 1e-10 * energy,
        "{} against {energy}",
        report.dissipated_energy
    );
    assert_eq!(report.slip_fraction, 1.0);
    // dR/dw against central differences (the residual is smooth here: sliding all period).
    let mut derivative = vec![0.0; hb.dim()];
    let mut scratch = vec![0.0; hb.dim()];
    hb.residual_parameter_derivative(&x, &mut derivative, &mut scratch)
        .unwrap();
    let step = 1e-6;
    let mut at = |omega: f64| {
        hb.set_parameter(omega);
        let mut r = vec![0.0; hb.dim()];
        hb.residual(&x, &mut r).unwrap();
        r
    };
    let (plus, minus) = (at(w + step), at(w - step));
    for (i, d) in derivative.iter().enumerate() {
        let fd = (plus[i] - minus[i]) / (2.0 * step);
        // Central differences of an O(10) residual with a step of 1e-6: error ~1e-8.
        assert!((d - fd).abs() < 1e-6, "entry {i}: {d} against {fd}");
    }
}

/// `jenkins::with_tangential_stiffness` on the driven point builds the hand-written Jenkins
/// element of [`a_jenkins_element_on_a_circle_dissipates_the_closed_form_energy`]: the
/// same solution to Newton's tolerance, and `2 pi mu N sqrt(r^2 - (mu N / k_t)^2)` on the
/// circle; a bad stiffness or index is refused.
#[test]
fn the_tangential_stiffness_sugar_is_the_hand_built_jenkins_element() {
    use semismooth_contact::jenkins::with_tangential_stiffness;
    let (kt, drive) = (2.0 * SLIP, 10.0);
    let mut point = driven((1.0, 1.0, drive), diagonal(&[drive; 2]), 2);
    point.frictional_contacts.push(prescribed_disk(0));
    let sugar = with_tangential_stiffness(&point, 0, kt).unwrap();
    assert_eq!(sugar.dofs(), 4);
    assert!(with_tangential_stiffness(&point, 0, 0.0).is_err());
    assert!(with_tangential_stiffness(&point, 1, kt).is_err());
    let (hb, x) = solve(&sugar, (DRIVE_OMEGA, 3, 1e-12), &mut FaerDenseLu::new());
    let (r, minor) = semi_axes(&x, 4);
    // Exact on the circle: Newton's error alone (|F| <= 1e-12 on O(1) residuals).
    assert!((r - minor).abs() < 1e-10, "a circle: {r} and {minor}");
    let expected = 2.0 * PI * SLIP * (r * r - (SLIP / kt).powi(2)).sqrt();
    let report = hb.frictional_contact_report(&x, 0, 64).unwrap();
    assert!((report.dissipated_energy / expected - 1.0).abs() < 1e-10);
    let (_, y) = solve(
        &hand_built_jenkins(kt, drive),
        (DRIVE_OMEGA, 3, 1e-12),
        &mut FaerDenseLu::new(),
    );
    let gap = x
        .iter()
        .zip(&y)
        .fold(0.0f64, |a, (p, q)| a.max((p - q).abs()));
    assert!(gap < 1e-10, "{gap:e}");
}

/// Penalty HB's regularised vector law `-mu N y / max(|y|, eta)` (the library's one-call
/// solve, its penalty and band homotopies) on `model` at `(omega, harmonics)` with the band
/// `relative` times the tangent's static compliance: the solution.
fn penalty_disk(
    model: &StructuralModel,
    (omega, harmonics): (f64, usize),
    relative: f64,
) -> semismooth_contact::solve::Solution {
    use semismooth_contact::settings::{Method, SolverSettings};
    let structure = semismooth_contact::model::Structure::new(model.clone(), 0).unwrap();
    let settings = SolverSettings {
        method: Method::PenaltyHb,
        friction_regularisation: relative,
        tolerance: 1e-11,
        ..SolverSettings::with_harmonics(harmonics)
    };
    let solution = semismooth_contact::solve::solve(&structure, omega, &settings, None).unwrap();
    assert!(solution.converged(), "{:?}", solution.termination);
    solution
}

/// On the pressed point's circle the slip speed never drops below `w r`: once the band is
/// narrower, the regularised law is Coulomb's, and penalty HB gives the closed form's
/// energy `2 pi mu N r` up to the penalty's compliance (`N` is lowered by the relative
/// `STIFFNESS / k_p`, 1e-5 here, and `r` moves with it: agreement within 1e-4).
#[test]
fn the_regularised_disk_of_penalty_hb_on_a_circle_dissipates_two_pi_mu_n_r() {
    let model = pressed_rotor();
    let normal = PRESS - STIFFNESS * GAP;
    let radius = circle_radius(MU * normal);
    let expected = 2.0 * PI * MU * normal * radius;
    for harmonics in [1, 4] {
        let solution = penalty_disk(&model, (OMEGA, harmonics), 1e-3);
        let report = &solution.frictional_contacts[0];
        let error = (report.dissipated_energy - expected).abs() / expected;
        assert!(error < 1e-4, "H = {harmonics}: {error:e}");
        assert_eq!(report.slip_fraction, 1.0);
    }
}

/// A mass on (x, y) pressed on a flat by a massless normal dof z (spring 10, preload
/// through the gap -0.1: `N = 1 + 0.3 cos w t`, never lifting off) and driven in the plane
/// by `(0.45 cos w t, 0.1 sin w t)`, `mu = 0.4`: it sticks near the ends of its slim orbit
/// and slips, turning, between them.
fn pressed_stick_slip() -> StructuralModel {
    let mut load = HarmonicLoad::zero(3);
    load.add_harmonic(1, &[0.45, 0.0, 0.3], &[0.0, 0.1, 0.0])
        .unwrap();
    let stiffness = diagonal(&[1.0, 1.0, 10.0]);
    let mut model = model(&[1.0, 1.0, 0.0], &[0.1, 0.1, 0.0], stiffness, load);
    model
        .frictional_contacts
        .push(FrictionalContact::unilateral(
            ContactRow::unit(2, 1.0),
            -0.1,
            [ContactRow::unit(0, 1.0), ContactRow::unit(1, 1.0)],
            0.4,
        ));
    model
}

/// With stick phases and a turning slip, penalty HB's regularised disk converges to
/// SSN-HB's exact disk (same `H = 20`) as the band shrinks over three decades: the error
/// of the energy per cycle falls (measured 2.0, 0.17, 8.5e-3 relative at bands 1e-1, 1e-2,
/// 1e-3: the stick phases become creep at a speed of the band's order, a band of 1e-3
/// relative leaves a creep error below 1.5 %), the largest tangential force is `mu N_max`
/// in both (within the penalty's compliance, `10 / k_p`). A narrower band is not resolved
/// by 20 harmonics (1e-4: 5e-2, its own truncation error): the band and `H` go together.
#[test]
fn the_regularised_disk_of_penalty_hb_converges_to_the_exact_disk_as_its_band_shrinks() {
    let model = pressed_stick_slip();
    let (w, harmonics) = (0.8, 20);
    let (hb, x) = solve(&model, (w, harmonics, 1e-12), &mut FaerDenseLu::new());
    let exact = hb.frictional_contact_report(&x, 0, 512).unwrap().summary();
    let mut errors = Vec::new();
    for relative in [1e-1, 1e-2, 1e-3] {
        let solution = penalty_disk(&model, (w, harmonics), relative);
        let report = solution.frictional_contacts[0].summary();
        let relative_error = |a: f64, b: f64| (a - b).abs() / b;
        let tangential = relative_error(report.max_tangential_force, exact.max_tangential_force);
        assert!(tangential < 1e-4, "band {relative:e}: {tangential:e}");
        errors.push(relative_error(
            report.dissipated_energy,
            exact.dissipated_energy,
        ));
    }
    assert!(
        errors[1] < 0.5 * errors[0] && errors[2] < 0.5 * errors[1],
        "{errors:?}"
    );
    assert!(errors[2] < 1.5e-2, "{errors:?}");
}
