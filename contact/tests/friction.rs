//! Coulomb friction in SSN-HB against exact solutions.
//!
//! Den Hartog (1931): the single-dof oscillator `m x'' + c x' + k x + F sign(x') =
//! F0 cos(w t)` in continuous sliding has an exact periodic solution, symmetric over half
//! periods, made of the closed-form solutions of the linear equation with the constant
//! friction force `-F` between velocity reversals. [`den_hartog`] computes it from the two
//! matching conditions at the reversals; its amplitude is checked against Den Hartog's own
//! formula for the undamped case, and harmonic balance converges to it as `H` grows.

use semismooth::linalg::FaerDenseLu;
use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::Residual;
use semismooth_contact::hb::{HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::march::{march_to_steady_state, MarchOptions, MarchScheme};
use semismooth_contact::model::{
    ContactPoint, ContactRow, FrictionPoint, SparseMatrix, StructuralModel,
};

/// The single-dof oscillator `m x'' + c x' + k x = F0 cos(w t) + lambda_t` with Coulomb
/// friction `|lambda_t| <= mu N` on its dof.
fn oscillator(m: f64, c: f64, k: f64, f0: f64, friction: f64) -> StructuralModel {
    let one = |v: f64| {
        SparseMatrix::try_new_from_triplets(1, 1, &[faer::sparse::Triplet::new(0, 0, v)]).unwrap()
    };
    StructuralModel {
        mass: one(m),
        damping: (c > 0.0).then(|| one(c)),
        stiffness: one(k),
        load: vec![f0],
        contacts: Vec::new(),
        // mu = 0.5 under N = 2 friction: the slip limit `friction`.
        friction: vec![FrictionPoint::prescribed(
            ContactRow::unit(0, 1.0),
            0.5,
            2.0 * friction,
        )],
    }
}

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
/// `X = Y - p` with `p = -sqrt(A^2 + B^2 - q^2)` (the root with `X > 0`).
fn den_hartog(m: f64, c: f64, k: f64, f0: f64, friction: f64, w: f64) -> f64 {
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
    assert!(r2 > q * q, "no continuous sliding at w = {w}");
    y + (r2 - q * q).sqrt()
}

/// Den Hartog's closed form of the undamped case:
/// `X k / F0 = sqrt(1 / (1 - beta^2)^2 - (F U / F0)^2)`,
/// `U = sin(pi / beta) / (beta (1 + cos(pi / beta)))`, `beta = w / w_n`.
fn den_hartog_undamped(m: f64, k: f64, f0: f64, friction: f64, w: f64) -> f64 {
    let beta = w / (k / m).sqrt();
    let pi_b = std::f64::consts::PI / beta;
    let u = pi_b.sin() / (beta * (1.0 + pi_b.cos()));
    let r = friction * u / f0;
    f0 / k * (1.0 / (1.0 - beta * beta).powi(2) - r * r).sqrt()
}

/// The SSN-HB solution with `h` harmonics from zero (asserted converged).
fn hb_solve(model: &StructuralModel, w: f64, h: usize) -> (SsnHb, Vec<f64>) {
    let options = HbOptions {
        harmonics: h,
        ..HbOptions::default()
    };
    let mut hb = SsnHb::new(model, w, &options).unwrap();
    let mut x = vec![0.0; hb.dim()];
    let newton = PolyalgorithmOptions::default();
    let report = solve_smoothing(&mut hb, &mut StructuredHbSolver::new(), &mut x, &newton).unwrap();
    assert!(report.converged(), "H = {h}: {:?}", report.termination);
    (hb, x)
}

/// The amplitude `sqrt(a_1^2 + b_1^2)` of the first harmonic of `N` equally spaced
/// samples of one period (the trapezoidal rule, exact for a trigonometric polynomial of
/// degree `< N - 1`).
fn first_harmonic(u: &[f64]) -> f64 {
    let n = u.len() as f64;
    let (mut a, mut b) = (0.0, 0.0);
    for (j, v) in u.iter().enumerate() {
        let phase = 2.0 * std::f64::consts::PI * j as f64 / n;
        a += v * phase.cos();
        b += v * phase.sin();
    }
    2.0 * a.hypot(b) / n
}

/// The first-harmonic amplitude of `u[dof]` of the SSN-HB solution with `h` harmonics.
fn hb_first_harmonic(model: &StructuralModel, w: f64, h: usize, dof: usize) -> f64 {
    let (hb, x) = hb_solve(model, w, h);
    first_harmonic(&hb.displacement_samples(&x, dof, 4096).unwrap())
}

/// The first-harmonic amplitude of `u[dof]` over the steady period of the Moreau–Jean
/// march with friction (`steps` per period, `theta`, no restitution), and the fraction of
/// steps on which `dof` does not move (sticks).
fn march_first_harmonic(
    model: &StructuralModel,
    w: f64,
    steps: usize,
    theta: f64,
    dof: usize,
) -> (f64, f64) {
    let options = MarchOptions {
        steps_per_period: steps,
        tolerance: 1e-9,
        scheme: MarchScheme::MoreauJean {
            theta,
            restitution: 0.0,
        },
        ..MarchOptions::default()
    };
    let period = march_to_steady_state(model, w, &options, &[dof]).unwrap();
    let u = &period.displacements[0];
    let peak = u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let still = u
        .windows(2)
        .filter(|p| (p[1] - p[0]).abs() < 1e-12 * peak)
        .count();
    // The series holds both ends of the period: the last sample repeats the first.
    (
        first_harmonic(&u[..u.len() - 1]),
        still as f64 / (u.len() - 1) as f64,
    )
}

/// The amplitude `max |x|` of the SSN-HB solution with `h` harmonics, reconstructed on
/// 4096 points.
fn hb_amplitude(model: &StructuralModel, w: f64, h: usize) -> f64 {
    let (hb, x) = hb_solve(model, w, h);
    let u = hb.displacement_samples(&x, 0, 4096).unwrap();
    let amplitude = u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    // The friction force never exceeds the slip limit by more than the Gibbs overshoot of
    // its truncated series (it is a square wave in continuous sliding).
    let force = hb.contact_force_samples(&x, 0, 4096).unwrap();
    assert!(force.iter().all(|f| f.abs() < 1.2 * 0.3), "H = {h}");
    amplitude
}

#[test]
fn the_exact_continuous_sliding_solution_is_den_hartogs() {
    // The closed form of the two matching conditions against Den Hartog's formula (no
    // viscous damping), below and above resonance: equal to round-off.
    for w in [0.6, 0.7, 1.3, 2.0] {
        let general = den_hartog(1.0, 0.0, 1.0, 1.0, 0.3, w);
        let formula = den_hartog_undamped(1.0, 1.0, 1.0, 0.3, w);
        assert!(
            (general - formula).abs() < 1e-12 * formula,
            "w = {w}: {general} vs {formula}"
        );
    }
    // Friction lowers the amplitude below the linear response's.
    assert!(den_hartog(1.0, 0.02, 1.0, 1.0, 0.3, 0.7) < 1.0 / (1.0 - 0.49));
}

#[test]
fn harmonic_balance_converges_to_den_hartog_as_the_harmonics_grow() {
    // F = 0.3 F0, below (0.7) and above (1.3) resonance, with light viscous damping
    // (zeta = 0.01) and without.
    for (w, c) in [(0.7, 0.0), (1.3, 0.0), (0.7, 0.02)] {
        let model = oscillator(1.0, c, 1.0, 1.0, 0.3);
        let exact = den_hartog(1.0, c, 1.0, 1.0, 0.3, w);
        let mut errors = Vec::new();
        for h in [5, 10, 20, 40] {
            let amplitude = hb_amplitude(&model, w, h);
            errors.push((amplitude - exact).abs() / exact);
            assert!(exact > 0.0);
        }
        eprintln!(
            "w = {w}, c = {c}: X = {exact}, relative errors at H = 5, 10, 20, 40: {errors:?}"
        );
        // The friction force is a square wave in continuous sliding: its series converges
        // like 1/H, and so does the amplitude (not monotonically at small H). Measured:
        // 0.14 % (w = 0.7) and 0.085 % (w = 1.3) at H = 40; each at least halved from
        // H = 10 to 40.
        assert!(errors[3] < errors[1] / 2.0, "w = {w}: {errors:?}");
        assert!(errors[3] < 2e-3, "w = {w}: {errors:?}");
    }
}

#[test]
fn the_dense_and_structured_solves_agree_with_friction() {
    let model = oscillator(1.0, 0.02, 1.0, 1.0, 0.3);
    let options = HbOptions {
        harmonics: 10,
        ..HbOptions::default()
    };
    let newton = PolyalgorithmOptions::default();
    let mut structured = SsnHb::new(&model, 0.7, &options).unwrap();
    let mut xs = vec![0.0; structured.dim()];
    let rs = solve_smoothing(
        &mut structured,
        &mut StructuredHbSolver::new(),
        &mut xs,
        &newton,
    )
    .unwrap();
    let mut dense = SsnHb::new(&model, 0.7, &options).unwrap();
    let mut xd = vec![0.0; dense.dim()];
    let rd = solve_smoothing(&mut dense, &mut FaerDenseLu::new(), &mut xd, &newton).unwrap();
    assert!(rs.converged() && rd.converged());
    let diff = xs
        .iter()
        .zip(&xd)
        .fold(0.0f64, |a, (s, d)| a.max((s - d).abs()));
    assert!(diff < 1e-9, "{diff:e}");
}

#[test]
fn harmonic_balance_converges_to_the_exact_march_through_stick_slip() {
    // Slip limit 0.7 F0 at w = 0.6 w_n, zeta = 0.05: the mass sticks for part of each
    // half period (Den Hartog's continuous sliding does not exist here).
    let model = oscillator(1.0, 0.1, 1.0, 1.0, 0.7);
    let w = 0.6;
    // The march's own error from halving its step: Moreau-Jean (theta = 1/2) is first
    // order at the stick-slip transitions, so the 8000-step peak is within |p8000 -
    // p4000| of the exact one (with margin 2 for the constant).
    let (coarse, _) = march_first_harmonic(&model, w, 4000, 0.5, 0);
    let (reference, stuck) = march_first_harmonic(&model, w, 8000, 0.5, 0);
    let march_error = 2.0 * (reference - coarse).abs();
    assert!(stuck > 0.05, "the march must stick: {stuck}");
    let errors: Vec<f64> = [5, 10, 20, 40, 80, 160]
        .iter()
        .map(|&h| (hb_first_harmonic(&model, w, h, 0) - reference).abs() / reference)
        .collect();
    eprintln!(
        "stick-slip first harmonic {reference}, march error {:e}, HB relative errors at H = 5, \
         10, 20, 40, 80, 160: {errors:?}",
        march_error / reference
    );
    // Sticking makes the friction force jump where the velocity reaches zero: HB
    // converges slowly and not monotonically at small H (measured 1.9, 4.6, 0.43, 0.60,
    // 0.24, 0.090 % at H = 5 ... 160; 0.031 % at 320), about like H^-1.4 from H = 40 on.
    assert!(errors[5] < errors[3] / 4.0, "{errors:?}");
    assert!(
        errors[5] * reference < march_error + 2e-3 * reference,
        "{errors:?}"
    );
}

/// A mass `x` on a spring (`k = 1`, `zeta = 0.05`) pressed on a flat by a massless normal
/// dof `y` (spring `k_y = 10`, preload through the gap `-0.05`, so `N = 0.5` at rest),
/// under `F_x cos(w t)` and a normal force `F_y cos(w t)` larger than the preload: the
/// normal force reaches zero (liftoff) for part of each period, and friction `mu = 0.4`
/// acts through the contact's varying normal force.
fn liftoff_model(fx: f64, fy: f64) -> StructuralModel {
    let diag = |a: f64, b: f64| {
        SparseMatrix::try_new_from_triplets(
            2,
            2,
            &[
                faer::sparse::Triplet::new(0, 0, a),
                faer::sparse::Triplet::new(1, 1, b),
            ],
        )
        .unwrap()
    };
    StructuralModel::new(diag(1.0, 0.0), diag(1.0, 10.0), vec![fx, fy])
        .with_damping(diag(0.1, 0.0))
        .with_contact(ContactPoint::new(1, -0.05))
        .with_friction(FrictionPoint::on_contact(ContactRow::unit(0, 1.0), 0.4, 0))
}

#[test]
fn harmonic_balance_converges_to_the_exact_march_through_liftoff() {
    let model = liftoff_model(0.3, 0.8);
    let w = 0.8;
    // theta = 1: the massless normal dof follows its quasi-static equilibrium exactly at
    // each step (theta = 1/2 would alternate about it); first order, so the 16000-step
    // peak is within twice its difference to the 8000-step one.
    let (coarse, _) = march_first_harmonic(&model, w, 8000, 1.0, 0);
    let (reference, _) = march_first_harmonic(&model, w, 16000, 1.0, 0);
    let march_error = 2.0 * (reference - coarse).abs();
    // The normal force of HB reaches zero over part of the period.
    let (hb, x) = hb_solve(&model, w, 20);
    let normal = hb.contact_force_samples(&x, 0, 512).unwrap();
    let open = normal.iter().filter(|l| **l > -1e-6).count();
    assert!(open > 512 / 10, "liftoff over {open} of 512 samples");
    let errors: Vec<f64> = [5, 10, 20, 40]
        .iter()
        .map(|&h| (hb_first_harmonic(&model, w, h, 0) - reference).abs() / reference)
        .collect();
    eprintln!(
        "liftoff first harmonic {reference}, march error {:e}, HB relative errors at H = 5, 10, 20, \
         40: {errors:?}",
        march_error / reference
    );
    // Measured 11.8, 3.1, 0.60, 0.20 % at H = 5 ... 40 (the march's own error estimate
    // 0.63 %): converging like H^-2.
    assert!(errors[3] < errors[1] / 8.0, "{errors:?}");
    assert!(
        errors[3] * reference < march_error + 2e-3 * reference,
        "{errors:?}"
    );
}

#[test]
fn the_march_with_exact_friction_reproduces_den_hartog() {
    // zeta = 0.01, F = 0.3 F0 at w = 0.7: continuous sliding. The peak of the sampled
    // period against Den Hartog's X. Measured 9.6e-4 at 1000 steps and 4.7e-5 at 4000:
    // second order (theta = 1/2; no stick, so no switch of the law inside a step matters).
    let model = oscillator(1.0, 0.02, 1.0, 1.0, 0.3);
    let exact = den_hartog(1.0, 0.02, 1.0, 1.0, 0.3, 0.7);
    let errors: Vec<f64> = [1000, 4000]
        .iter()
        .map(|&steps| {
            let options = MarchOptions {
                steps_per_period: steps,
                tolerance: 1e-10,
                scheme: MarchScheme::MOREAU_JEAN_DEFAULT,
                ..MarchOptions::default()
            };
            let period = march_to_steady_state(&model, 0.7, &options, &[0]).unwrap();
            let peak = period.displacements[0]
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()));
            (peak - exact).abs() / exact
        })
        .collect();
    eprintln!(
        "march against Den Hartog X = {exact}: relative errors at 1000, 4000 steps: {errors:?}"
    );
    assert!(
        errors[1] < errors[0] / 3.0 && errors[1] < 1e-4,
        "{errors:?}"
    );
}

#[test]
fn a_damper_stuck_all_period_moves_the_two_parts_as_one() {
    // Two undamped oscillators (m = 1; k = 1 and 2) joined by a friction point on their
    // relative displacement, the first forced by cos(w t): with a slip limit far above the
    // force the link carries (0.69 at w = 0.45), they move as one body,
    // x = F0 / (k_0 + k_1 - (m_0 + m_1) w^2) cos(w t), with zero mean slip (the velocity
    // form leaves the mean of a stuck point free; it is anchored at zero). No harmonic
    // k w meets a natural frequency of the free parts (1 and sqrt 2).
    let w = 0.45;
    let amplitude = 1.0 / (3.0 - 2.0 * w * w);
    let diag = |a: f64, b: f64| {
        SparseMatrix::try_new_from_triplets(
            2,
            2,
            &[
                faer::sparse::Triplet::new(0, 0, a),
                faer::sparse::Triplet::new(1, 1, b),
            ],
        )
        .unwrap()
    };
    let link = ContactRow::new(vec![0, 1], vec![1.0, -1.0]).unwrap();
    let model = StructuralModel::new(diag(1.0, 1.0), diag(1.0, 2.0), vec![1.0, 0.0])
        .with_friction(FrictionPoint::prescribed(link, 0.5, 20.0));
    for h in [1, 5] {
        let (hb, x) = hb_solve(&model, w, h);
        for dof in [0, 1] {
            let u = hb.displacement_samples(&x, dof, 64).unwrap();
            for (j, v) in u.iter().enumerate() {
                let exact = amplitude * (2.0 * std::f64::consts::PI * j as f64 / 64.0).cos();
                // Newton's tolerance 1e-10 on the residual, the system well conditioned.
                assert!(
                    (v - exact).abs() < 1e-8,
                    "H = {h}, dof {dof}: {v} vs {exact}"
                );
            }
        }
    }
}
