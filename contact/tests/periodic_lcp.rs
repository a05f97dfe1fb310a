//! The periodic time-domain LCP: its matrix, vector and linear response checked
//! against independent computations (the analytic frequency response, a direct static
//! solve, the trapezoidal rule written out in the time domain, dense eigenvalues), and its
//! solvers against each other.

mod common;

use common::{dense, dense_kmd, exact_linear, max_abs_diff};
use nalgebra::{Complex, DMatrix, DVector};
use semismooth::lemke::{Lemke, LemkeOptions, LemkeTermination};
use semismooth::newton::{self, NewtonOptions, Strategy};
use semismooth::polyalgorithm::{self, PolyalgorithmOptions, SolveOptions};
use semismooth::InvalidOption;
use semismooth_contact::lcp::{
    solve_min_map_sequenced, ActiveSetSolver, LcpError, LcpScheme, PeriodicLcp, PeriodicLcpOptions,
    DEFAULT_ACTIVE_SET_REGULARIZATION,
};
use semismooth_contact::model::{InvalidModel, SparseMatrix, StructuralModel};
use semismooth_contact::rod::{build_rod, MassModel, RodContact, RodModel, RodSpec};
use semismooth_contact::solve::{Diagnosis, Termination};

/// The canonical rod with contacts at node `inner` (gap 0.3) and at the tip (gap 0.5): its
/// model and forcing frequency.
fn two_contact_rod(mass: MassModel, inner: usize) -> (StructuralModel, f64) {
    let mut spec = RodSpec::canonical();
    spec.mass = mass;
    spec.contacts = vec![
        RodContact {
            node: inner,
            gap: 0.3,
        },
        RodContact { node: 20, gap: 0.5 },
    ];
    model_and_omega(&spec)
}

/// The canonical rod (damped or not) with the mass model `mass`: its model and forcing
/// frequency.
fn rod(mass: MassModel, damped: bool) -> (StructuralModel, f64) {
    let mut spec = RodSpec::canonical();
    spec.mass = mass;
    if !damped {
        spec.damping = None;
    }
    model_and_omega(&spec)
}

/// The model built from `spec` and the spec's forcing frequency.
fn model_and_omega(spec: &RodSpec) -> (StructuralModel, f64) {
    let rod = build_rod(spec).unwrap();
    let omega = rod.omega();
    (rod.structure.model, omega)
}

fn options(nt: usize, observed: Vec<usize>) -> PeriodicLcpOptions {
    PeriodicLcpOptions {
        time_samples: nt,
        observed_dofs: observed,
        ..Default::default()
    }
}

/// `Re((K + i s D - s^2 M)^{-1} a e^{i 2 pi n / Nt})` at the nodes, by a dense complex solve.
fn frequency_response(model: &StructuralModel, s: f64, nt: usize) -> Vec<Vec<f64>> {
    at_nodes(&exact_linear(model, s), nt)
}

/// `Re(x e^{i 2 pi n / Nt})` at the nodes `n = 0..Nt`, per entry of `x`.
fn at_nodes(x: &DVector<Complex<f64>>, nt: usize) -> Vec<Vec<f64>> {
    x.iter()
        .map(|z| {
            (0..nt)
                .map(|n| {
                    let phase = 2.0 * std::f64::consts::PI * n as f64 / nt as f64;
                    (z * Complex::new(phase.cos(), phase.sin())).re
                })
                .collect()
        })
        .collect()
}

#[test]
fn linear_response_is_the_frequency_response_at_the_warped_frequency_with_second_order_error() {
    let (model, omega) = rod(MassModel::Consistent, true);
    let dofs: Vec<usize> = (0..model.dofs()).collect();
    let mut errors = Vec::new();
    for nt in [32usize, 64, 128, 256, 512] {
        let lcp = PeriodicLcp::new(&model, omega, options(nt, dofs.clone())).unwrap();
        let zero = vec![0.0; lcp.dim()];
        let u = lcp.displacements(&zero).unwrap();
        // The discrete answer is exactly the frequency response at the warped frequency
        // (2/dt) tan(pi/Nt): equal up to the round-off of two O(N) complex solves.
        let warped = frequency_response(&model, lcp.bin_frequency(1), nt);
        let scale = warped.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        for dof in 0..model.dofs() {
            assert!(max_abs_diff(&u[dof], &warped[dof]) < 1e-11 * scale);
        }
        // q = g - u_lin at the tip.
        let tip = model.dofs() - 1;
        let gap = model.contacts[0].gap;
        let from_q: Vec<f64> = lcp.q().iter().map(|q| gap - q).collect();
        assert!(max_abs_diff(&from_q, &u[tip]) < 1e-12 * scale);
        let exact = frequency_response(&model, omega, nt);
        let error = (0..model.dofs())
            .map(|dof| max_abs_diff(&u[dof], &exact[dof]))
            .fold(0.0, f64::max);
        errors.push(error / scale);
    }
    // Warping error: s_1 = omega (1 + (pi/Nt)^2 / 3 + ...). The forcing sits on the
    // resonance (zeta = 0.01) so the response is sensitive to the frequency shift, but once
    // the shift 0.82 / Nt^2 is well below zeta (Nt >= 32) the error falls by 4 per doubling.
    assert_second_order(&errors);
}

/// Errors at `Nt` doubling each time fall by 4 (observed order within 2 +- 0.1).
fn assert_second_order(errors: &[f64]) {
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!((1.9..2.1).contains(&order), "errors {errors:?}");
    }
}

#[test]
fn block_row_sums_of_a_are_the_static_compliance_of_the_contacts() {
    // Two contacts (mid-rod and tip): exercises the m x m blocks.
    for mass in [MassModel::Modified, MassModel::Consistent] {
        let (model, omega) = two_contact_rod(mass, 10);
        let nt = 64;
        let lcp = PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
        let a = lcp.matrix();
        let m = 2;
        let k = dense(&model.stiffness);
        let dofs = [9usize, 19];
        let lu = k.lu();
        let mut compliance = [[0.0; 2]; 2];
        for (c2, &d2) in dofs.iter().enumerate() {
            let e = DVector::from_fn(model.dofs(), |i, _| if i == d2 { 1.0 } else { 0.0 });
            let x = lu.solve(&e).unwrap();
            for (c, &d) in dofs.iter().enumerate() {
                compliance[c][c2] = x[d];
            }
        }
        let scale = compliance[1][1];
        for n in 0..nt {
            for (c, row) in compliance.iter().enumerate() {
                for (c2, expected) in row.iter().enumerate() {
                    let sum: f64 = (0..nt).map(|j| a[(n * m + c, j * m + c2)]).sum();
                    // Sum of Nt kernel values obtained by an FFT of O(1) receptances.
                    assert!(
                        (sum - expected).abs() < 1e-12 * scale * nt as f64,
                        "{mass:?} row {n}, block ({c}, {c2}): {sum} vs {expected}"
                    );
                }
            }
        }
    }
}

/// The periodic trapezoidal rule written out in the time domain (first-order form, all
/// `2 N Nt` unknowns), solved densely for a given contact force history `lambda`:
/// `u_{n+1} - u_n = dt/2 (v_{n+1} + v_n)`,
/// `M (v_{n+1} - v_n) + dt/2 [D (v_{n+1} + v_n) + K (u_{n+1} + u_n)] = dt/2 (f_{n+1} + f_n + G^T (lambda_{n+1} + lambda_n))`.
/// For odd `Nt` the system is regular (no Nyquist bin).
fn trapezoidal_contact_displacement(
    model: &StructuralModel,
    omega: f64,
    nt: usize,
    lambda: &[f64],
) -> Vec<f64> {
    let n = model.dofs();
    let (k, m, d) = dense_kmd(model);
    let dt = 2.0 * std::f64::consts::PI / omega / nt as f64;
    let size = 2 * n * nt;
    let u = |step: usize, i: usize| (step % nt) * 2 * n + i;
    let v = |step: usize, i: usize| (step % nt) * 2 * n + n + i;
    let mut a = DMatrix::<f64>::zeros(size, size);
    let mut b = DVector::<f64>::zeros(size);
    let tip = model.contacts[0].dof();
    let load = model.load.forcing_cosine();
    for step in 0..nt {
        let row0 = step * 2 * n;
        for i in 0..n {
            let r = row0 + i;
            a[(r, u(step + 1, i))] += 1.0;
            a[(r, u(step, i))] -= 1.0;
            a[(r, v(step + 1, i))] -= 0.5 * dt;
            a[(r, v(step, i))] -= 0.5 * dt;
            let r = row0 + n + i;
            for j in 0..n {
                a[(r, v(step + 1, j))] += m[(i, j)] + 0.5 * dt * d[(i, j)];
                a[(r, v(step, j))] += -m[(i, j)] + 0.5 * dt * d[(i, j)];
                a[(r, u(step + 1, j))] += 0.5 * dt * k[(i, j)];
                a[(r, u(step, j))] += 0.5 * dt * k[(i, j)];
            }
            let t0 = step as f64 * dt;
            let t1 = t0 + dt;
            let w = omega;
            let mut rhs = load[i] * ((w * t0).cos() + (w * t1).cos());
            if i == tip {
                rhs += lambda[step] + lambda[(step + 1) % nt];
            }
            b[r] = 0.5 * dt * rhs;
        }
    }
    let x = a.lu().solve(&b).unwrap();
    (0..nt).map(|step| x[u(step, tip)]).collect()
}

#[test]
fn lcp_gap_equals_the_time_domain_trapezoidal_rule_for_odd_nt() {
    for mass in [MassModel::Consistent, MassModel::Modified] {
        let mut spec = RodSpec::canonical();
        spec.elements = 4;
        spec.mass = mass;
        spec.contacts = vec![RodContact { node: 4, gap: 0.5 }];
        let (model, omega) = model_and_omega(&spec);
        let nt = 15; // odd, not a power of two: the direct-DFT path
        let lcp = PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
        let z: Vec<f64> = (0..nt)
            .map(|n| (0.3 + (1.7 * n as f64).sin()).max(0.0) * 0.05)
            .collect();
        let lambda: Vec<f64> = z.iter().map(|v| -v).collect();
        let reference = trapezoidal_contact_displacement(&model, omega, nt, &lambda);
        let from_lcp = &lcp.contact_displacements(&z).unwrap()[0];
        let by_fft = &lcp.contact_displacements_by_fft(&z).unwrap()[0];
        let scale = reference.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        // Two dense solves of well-conditioned systems of size <= 120: round-off.
        assert!(
            max_abs_diff(from_lcp, &reference) < 1e-11 * scale,
            "{mass:?}"
        );
        assert!(max_abs_diff(by_fft, &reference) < 1e-11 * scale, "{mass:?}");
    }
}

fn transpose_distance(a: faer::MatRef<'_, f64>, b: faer::MatRef<'_, f64>) -> f64 {
    let n = a.nrows();
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            worst = worst.max((a[(i, j)] - b[(j, i)]).abs());
        }
    }
    worst
}

fn max_entry(a: faer::MatRef<'_, f64>) -> f64 {
    let mut worst = 0.0f64;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            worst = worst.max(a[(i, j)].abs());
        }
    }
    worst
}

#[test]
fn a_is_symmetric_without_damping_and_its_transpose_is_the_time_reversed_problem() {
    let nt = 128;
    for mass in [MassModel::Modified, MassModel::Consistent] {
        // Undamped: every H_k = G (K - s_k^2 M)^{-1} G^T is real, the kernel is even in time.
        let (undamped, omega) = rod(mass, false);
        let undamped = PeriodicLcp::new(&undamped, omega, options(nt, vec![])).unwrap();
        let a = undamped.matrix();
        assert!(transpose_distance(a, a) < 1e-13 * max_entry(a), "{mass:?}");

        // Damped: H_k has an imaginary part, odd in k, so the kernel has an odd part.
        let (model, omega) = rod(mass, true);
        let damped = PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
        let a = damped.matrix();
        let asymmetry = transpose_distance(a, a) / max_entry(a);
        assert!(
            asymmetry > 1e-2,
            "{mass:?}: relative asymmetry {asymmetry:e}"
        );
        // Theory: A^T has the bins H_k^* = G Z(-s_k)^{-1} G^T, i.e. the LCP of the model
        // with D replaced by -D (time reversal).
        let mut reversed = model.clone();
        let d = reversed.damping.take().unwrap();
        let (symbolic, values) = d.into_parts();
        reversed.damping = Some(SparseMatrix::new(
            symbolic,
            values.iter().map(|v| -v).collect(),
        ));
        let time_reversed = PeriodicLcp::new(&reversed, omega, options(nt, vec![])).unwrap();
        assert!(
            transpose_distance(a, time_reversed.matrix()) < 1e-12 * max_entry(a),
            "{mass:?}"
        );
    }
}

#[test]
fn symmetric_part_spectrum_from_the_bins_matches_a_dense_eigensolver() {
    let (model, omega) = two_contact_rod(MassModel::Consistent, 12);
    for nt in [16usize, 21] {
        let lcp = PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
        let a = lcp.matrix();
        let n = lcp.dim();
        let s = DMatrix::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let eig = nalgebra::SymmetricEigen::new(s).eigenvalues;
        let lo = eig.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = eig.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let (blo, bhi) = lcp.symmetric_part_spectrum();
        let scale = hi.abs().max(lo.abs());
        // Dense symmetric eigenvalues are backward stable: error ~ n eps |S|.
        assert!((lo - blo).abs() < 1e-12 * scale, "{lo} vs {blo}");
        assert!((hi - bhi).abs() < 1e-12 * scale, "{hi} vs {bhi}");
    }
}

#[test]
fn nyquist_bin_is_the_static_receptance_of_the_massless_undamped_dofs() {
    let nt = 64;
    // Undamped modified mass: the tip has neither mass nor damping, H_{Nt/2} = 1 / K_tt.
    let (model, omega) = rod(MassModel::Modified, false);
    let lcp = PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
    assert_eq!(lcp.static_dof_count(), 1);
    let h = lcp.receptance(nt / 2)[0];
    let k_tt = dense(&model.stiffness)[(19, 19)];
    assert!((h.re - 1.0 / k_tt).abs() < 1e-15 && h.im == 0.0);
    // The bins approach that limit: H_k - 1/K_tt = O(1 / s_k^2) near Nyquist.
    let near = lcp.receptance(nt / 2 - 1)[0];
    assert!((near.re - 1.0 / k_tt).abs() < 0.05 / k_tt, "{near}");
    // Damped (stiffness-proportional, the tip is damped) or massive tip: the limit is 0.
    for (mass, damped) in [(MassModel::Modified, true), (MassModel::Consistent, false)] {
        let (model, omega) = rod(mass, damped);
        let lcp = PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
        assert_eq!(lcp.static_dof_count(), 0);
        assert_eq!(lcp.receptance(nt / 2)[0].norm(), 0.0);
    }
}

#[test]
fn bad_options_and_models_are_typed_errors() {
    let (model, omega) = rod(MassModel::Modified, true);
    for nt in [0usize, 1, 7, 8193] {
        match PeriodicLcp::new(&model, omega, options(nt, vec![])) {
            Err(LcpError::InvalidOption(InvalidOption { name, value, .. })) => {
                assert_eq!(name, "time_samples");
                assert_eq!(value, nt as f64);
            }
            other => panic!("Nt = {nt}: {other:?}"),
        }
    }
    assert!(PeriodicLcp::new(&model, omega, options(8, vec![])).is_ok());
    assert_eq!(
        PeriodicLcp::new(&model, omega, options(16, vec![20])).unwrap_err(),
        LcpError::Model(InvalidModel::ObservedDofOutOfRange { dof: 20, dofs: 20 })
    );
    let mut free = model.clone();
    free.contacts.clear();
    assert_eq!(
        PeriodicLcp::new(&free, omega, options(16, vec![])).unwrap_err(),
        LcpError::NoContacts
    );
    assert!(matches!(
        PeriodicLcp::new(&model, f64::NAN, options(16, vec![])),
        Err(LcpError::InvalidOption(InvalidOption { name: "omega", value, .. })) if value.is_nan()
    ));
    let lcp = PeriodicLcp::new(&model, omega, options(16, vec![])).unwrap();
    assert_eq!(
        lcp.gap(&[0.0; 3]).unwrap_err(),
        LcpError::WrongLength {
            what: "z",
            expected: 16,
            found: 3
        }
    );
}

fn lemke_solution(lcp: &PeriodicLcp) -> semismooth::lemke::LemkeReport {
    let mut lemke = Lemke::new(lcp.dim());
    lcp.solve_with_lemke(&mut lemke, &LemkeOptions::default())
        .unwrap()
}

fn ssn_solution(lcp: &PeriodicLcp) -> (Vec<f64>, newton::NewtonReport) {
    ssn_from(lcp, vec![0.0; lcp.dim()])
}

fn ssn_from(lcp: &PeriodicLcp, mut z: Vec<f64>) -> (Vec<f64>, newton::NewtonReport) {
    let mut problem = lcp.min_map();
    let mut solver = ActiveSetSolver::new()
        .with_regularization(DEFAULT_ACTIVE_SET_REGULARIZATION)
        .unwrap();
    let report =
        polyalgorithm::solve(&mut problem, &mut solver, &mut z, &Default::default()).unwrap();
    (z, report)
}

/// Lemke (default options) ends with `expected` after `pivots` pivots (the measured count),
/// and `check_lemke` turns the report into `LemkeNotSolved` carrying its pivots and the
/// smallest eigenvalue of `(A + A^T)/2`.
fn assert_not_solved(lcp: &PeriodicLcp, expected: LemkeTermination, pivots: usize) {
    let report = lemke_solution(lcp);
    println!(
        "Lemke {:?} after {} pivots (n = {})",
        report.termination,
        report.pivots,
        lcp.dim()
    );
    assert_eq!(report.termination, expected);
    assert_eq!(report.pivots, pivots, "{expected:?}");
    match lcp.check_lemke(report.clone()) {
        Err(LcpError::LemkeNotSolved {
            termination,
            pivots,
            symmetric_part_min_eigenvalue,
            ..
        }) => {
            assert_eq!(termination, expected);
            assert_eq!(pivots, report.pivots);
            assert_eq!(
                symmetric_part_min_eigenvalue,
                lcp.symmetric_part_spectrum().0
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn lemke_and_semismooth_newton_give_the_same_lcp_solution_with_the_modified_mass() {
    let (model, omega) = rod(MassModel::Modified, true);
    for nt in [256usize, 1024] {
        // Newton by mesh sequencing (128 -> ... -> Nt, each level warm-started from the
        // interpolated previous Newton solution); Lemke independently on the finest LCP.
        let lcp = &PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
        let sequenced =
            solve_min_map_sequenced(&model, omega, lcp, &SolveOptions::default()).unwrap();
        assert!(sequenced.converged(), "Nt = {nt}: {:?}", sequenced.levels);
        assert_eq!(
            sequenced.levels.len(),
            1 + (nt / 128).trailing_zeros() as usize
        );
        let z = &sequenced.z;
        let lemke = lcp.check_lemke(lemke_solution(lcp)).unwrap();
        // Lemke's basic solution is exact up to the round-off of a solve with the final
        // basis (errors measured 1e-17); Newton ends with an exact solve on the same
        // active set. Both are then the solution of one linear system with A_II
        // (condition ~1e5 here). Measured at Nt = 256 / 1024, relative to max z: forces
        // 2.3e-14 / 2.7e-13, gaps 8.9e-16 / 2.4e-15 (absolute), Lemke's complementarity
        // error 7.8e-17 / 3.9e-16; asserted at under 10 times the larger.
        let zmax = z.iter().cloned().fold(0.0, f64::max);
        assert!(zmax > 0.1, "contact carries force");
        assert!(lemke.complementarity_error < 4e-15 * zmax);
        assert!(max_abs_diff(&lemke.z, z) < 2e-12 * zmax, "Nt = {nt}");
        let w = lcp.gap(z).unwrap();
        assert!(max_abs_diff(&lemke.w, &w) < 2e-14);
        if nt == 256 {
            // From z = 0 directly (no sequencing) Newton reaches the same solution.
            let (cold, report) = ssn_solution(lcp);
            assert!(report.converged());
            // Measured 4.6e-14 of max z.
            assert!(max_abs_diff(&cold, z) < 4e-13 * zmax);
        }
    }
}

#[test]
fn consistent_mass_makes_the_symmetric_part_more_indefinite_and_lemke_paths_much_longer() {
    let (model, omega) = rod(MassModel::Consistent, true);
    let lcp = PeriodicLcp::new(&model, omega, options(256, vec![])).unwrap();
    // The symmetric part of A is indefinite (its eigenvalues are Re H_k: negative above
    // a resonance), here by much more than with the modified mass.
    let (lo, hi) = lcp.symmetric_part_spectrum();
    assert!(lo < -1e-2 && hi > 0.0, "[{lo}, {hi}]");
    let (modified, omega) = rod(MassModel::Modified, true);
    let modified = PeriodicLcp::new(&modified, omega, options(256, vec![])).unwrap();
    assert!(modified.symmetric_part_spectrum().0 > lo / 2.0);
    // With the default pivot limit 50 n + 100 Lemke stops without a solution (no ray):
    assert_not_solved(&lcp, LemkeTermination::PivotLimit, 50 * lcp.dim() + 100);
    // ... but with 100 n pivots it solves this one (25369 pivots measured, against 172 for
    // the modified mass): the path is long, not a ray. At Nt >= 512 it had not finished
    // after 1000 n pivots.
    let mut lemke = Lemke::new(lcp.dim());
    let generous = LemkeOptions {
        max_pivots: Some(100 * lcp.dim()),
        ..LemkeOptions::default()
    };
    let solved = lcp.solve_with_lemke(&mut lemke, &generous).unwrap();
    println!(
        "generous limit: {:?} after {}",
        solved.termination, solved.pivots
    );
    assert!(
        solved.solved(),
        "{:?} after {}",
        solved.termination,
        solved.pivots
    );
    assert!(solved.complementarity_error < 1e-12);
    // Measured 25369 pivots; a window of 10 %: a longer path (a regression) or a much
    // shorter one (an improvement) is noticed.
    assert!(
        (22_832..=27_906).contains(&solved.pivots),
        "{} pivots, measured 25369",
        solved.pivots
    );
}

#[test]
fn lcp_solution_is_the_steady_state_of_the_massless_contact_trapezoidal_march_with_the_same_step() {
    use semismooth_contact::march::{march_to_steady_state, MarchOptions, MarchScheme};
    let (model, omega) = rod(MassModel::Modified, true);
    let tip = model.dofs() - 1;
    for nt in [128usize, 512] {
        let lcp = PeriodicLcp::new(&model, omega, options(nt, vec![])).unwrap();
        let lemke = lcp.check_lemke(lemke_solution(&lcp)).unwrap();
        let u = &lcp.contact_displacements(&lemke.z).unwrap()[0];
        let lambda = &lcp.contact_forces(&lemke.z).unwrap()[0];
        let march = march_to_steady_state(
            &model,
            omega,
            &MarchOptions {
                steps_per_period: nt,
                max_periods: 5000,
                tolerance: 1e-12,
                scheme: MarchScheme::MasslessContactTrapezoidal,
            },
            &[tip],
        )
        .unwrap();
        // Same discrete equations (trapezoidal rule, massless tip in equilibrium at every
        // node, exact contact at the nodes): the periodic LCP solution is the march's limit
        // cycle. The march stops at a period-to-period change of 1e-12; the remaining
        // transient is about 16 times that (decay 0.94 per period), 1.6e-11. Measured at
        // Nt = 128 / 512: displacements 1.4e-12 / 2.6e-12, forces 6.5e-12 / 2.5e-11.
        let du = max_abs_diff(u, &march.displacements[0][..nt]);
        let dl = max_abs_diff(lambda, &march.contact_forces[0][..nt]);
        println!(
            "Nt = {nt}: |du| = {du:.2e}, |dlambda| = {dl:.2e}, periods {}",
            march.periods
        );
        assert!(du < 2e-11, "Nt = {nt}: {du:e}");
        assert!(dl < 1e-10, "Nt = {nt}: {dl:e}");
    }
}

#[test]
fn force_interpolation_reproduces_periodic_piecewise_linear_histories() {
    let (model, omega) = two_contact_rod(MassModel::Modified, 10);
    let lcp = PeriodicLcp::new(&model, omega, options(16, vec![])).unwrap();
    // A coarse history of 4 nodes, 2 contacts (time-major): a triangle wave per contact.
    let coarse = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 2.0, 3.0];
    let fine = lcp.interpolate_forces(&coarse).unwrap();
    for n in 0..16 {
        // Fine node n sits at coarse position n / 4; linear between coarse nodes, and
        // periodic (node 3 -> node 0) at the end. Exact in binary arithmetic.
        let position = n as f64 / 4.0;
        let left = position.floor() as usize;
        let f = position - left as f64;
        for c in 0..2 {
            let expected = (1.0 - f) * coarse[left * 2 + c] + f * coarse[((left + 1) % 4) * 2 + c];
            assert_eq!(fine[n * 2 + c], expected);
        }
    }
    assert!(matches!(
        lcp.interpolate_forces(&[1.0; 3]),
        Err(LcpError::WrongLength { found: 3, .. })
    ));
}

#[test]
fn undamped_forcing_at_resonance_ends_lemke_on_a_ray_reported_with_the_numbers() {
    // Without damping, forcing at omega_1 puts bin 1 (warped just above omega_1) next to
    // the resonance: H_1 is large and negative, so the symmetric part of A (eigenvalues
    // Re H_k) is strongly indefinite; Lemke's method ends on a secondary ray.
    let (model, omega) = rod(MassModel::Modified, false);
    let lcp = PeriodicLcp::new(&model, omega, options(256, vec![])).unwrap();
    let (lo, _) = lcp.symmetric_part_spectrum();
    let h1 = lcp.receptance(1)[0];
    assert_eq!(h1.im, 0.0);
    assert_eq!(lo, h1.re);
    assert!(lo < -1e3, "{lo}");
    // Measured: the ray is met after 2 pivots.
    assert_not_solved(&lcp, LemkeTermination::Ray, 2);
}

/// The 40-element rod of the from-zero hard cases (damping ratio 0.02, `p0 = 0.1`, tip gap
/// 0.3: the linear response overshoots the gap fourfold) with the given mass model, its
/// LCP at `nt`, and `lcp-ssn` run on it from zero as a user runs it.
fn forty_element_lcp(
    mass: MassModel,
    nt: usize,
) -> (PeriodicLcp, semismooth_contact::solve::Solution) {
    forty_element_lcp_with(mass, nt, LcpScheme::Trapezoidal)
}

/// [`forty_element_lcp`] with the given time discretisation.
fn forty_element_lcp_with(
    mass: MassModel,
    nt: usize,
    scheme: LcpScheme,
) -> (PeriodicLcp, semismooth_contact::solve::Solution) {
    let rod = forty_element_rod_with(mass);
    let lcp_options = PeriodicLcpOptions {
        scheme,
        ..options(nt, vec![])
    };
    let lcp = PeriodicLcp::new(&rod.structure.model, rod.omega(), lcp_options).unwrap();
    (lcp, lcp_ssn_from_zero(&rod, nt, scheme, 200))
}

/// The strongly forced 40-element rod with the given mass model.
fn forty_element_rod_with(mass: MassModel) -> RodModel {
    build_rod(&RodSpec {
        mass,
        ..semismooth_contact::from_zero::forty_element_rod()
    })
    .unwrap()
}

/// `lcp-ssn` from zero (mesh sequencing) as a scene runs it, with the scene defaults but the
/// time discretisation and the iteration budget per level.
fn lcp_ssn_from_zero(
    rod: &RodModel,
    nt: usize,
    scheme: LcpScheme,
    max_iterations: usize,
) -> semismooth_contact::solve::Solution {
    let settings = semismooth_contact::settings::SolverSettings {
        method: semismooth_contact::settings::Method::LcpSsn,
        time_samples: nt,
        lcp_scheme: scheme,
        max_iterations,
        ..semismooth_contact::settings::SolverSettings::with_harmonics(20)
    };
    semismooth_contact::solve::solve(rod, rod.omega(), &settings, None).unwrap()
}

/// Why `lcp-ssn` does not converge from zero on the strongly forced 40-element rod with its
/// consistent mass. With stiffness-proportional damping every dof has mass or damping, so
/// the Nyquist receptance is 0 and the alternating vector `(-1)^n` is a null vector of `A`:
/// a contact force that alternates node to node moves nothing. On the long contact phase
/// of this rod the LCP solution uses it: the force chatters (active nodes interleaved with
/// inactive ones) and inactive nodes sit within 1e-4 of the obstacle, so the solution is
/// nearly degenerate. Full Newton steps converge from it perturbed by 1e-6, not by 1e-4;
/// Lemke needs 28,349 pivots (the default limit 50 n + 100 = 6,500 stops it).
#[test]
fn strongly_forced_rod_has_a_chattering_nearly_degenerate_lcp_solution_with_a_tiny_newton_basin() {
    let nt = 128;
    let (lcp, sol) = forty_element_lcp(MassModel::Consistent, nt);
    let a = lcp.matrix();
    let alternating: Vec<f64> = (0..nt)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let mut image = vec![0.0; nt];
    for (j, v) in alternating.iter().enumerate() {
        for (i, out) in image.iter_mut().enumerate() {
            *out += a[(i, j)] * v;
        }
    }
    // The kernel by FFT: round-off of the largest entry (1e-2) times a few ulps.
    let largest = max_entry(a);
    assert!(image.iter().all(|v| v.abs() < 1e-13 * largest), "{image:?}");
    assert_not_solved(&lcp, LemkeTermination::PivotLimit, 50 * nt + 100);
    let mut lemke = Lemke::new(nt);
    let generous = LemkeOptions {
        max_pivots: Some(250 * nt),
        ..LemkeOptions::default()
    };
    let solved = lcp.check_lemke(lcp.solve_with_lemke(&mut lemke, &generous).unwrap());
    let solved = solved.unwrap();
    // Measured 28,349 pivots: a window of 10 %.
    assert!(
        (25_514..=31_184).contains(&solved.pivots),
        "{}",
        solved.pivots
    );
    assert!(solved.complementarity_error < 1e-12);
    let z = &solved.z;
    let w = &solved.w;
    let active: Vec<usize> = (0..nt).filter(|&i| z[i] > 0.0).collect();
    let (first, last) = (active[0], *active.last().unwrap());
    // Measured: 12 active nodes between 1 and 17, five inactive ones among them.
    let holes = (first..=last).filter(|i| z[*i] == 0.0).count();
    assert!(holes >= 3, "active nodes {active:?}");
    let nearest = (0..nt)
        .filter(|&i| z[i] == 0.0)
        .map(|i| w[i])
        .fold(f64::INFINITY, f64::min);
    let weakest = active.iter().map(|&i| z[i]).fold(f64::INFINITY, f64::min);
    // Measured: 1.6e-5 (against the gap 0.3) and 5.7e-2.
    assert!(nearest < 1e-4 && weakest > 1e-2, "{nearest:e}, {weakest:e}");
    let newton_from = |size: f64| {
        let start: Vec<f64> = z
            .iter()
            .enumerate()
            .map(|(i, v)| v + size * ((i * 7919 % 13) as f64 / 13.0 - 0.3))
            .collect();
        let options = NewtonOptions {
            max_iterations: 50,
            globalization: newton::Globalization::None,
            ..NewtonOptions::default()
        };
        let mut problem = lcp.min_map();
        let mut solver = ActiveSetSolver::new()
            .with_regularization(DEFAULT_ACTIVE_SET_REGULARIZATION)
            .unwrap();
        let mut x = start;
        newton::solve(&mut problem, &mut solver, &mut x, &options).unwrap()
    };
    let near = newton_from(1e-6);
    assert!(near.converged() && near.iterations <= 2, "{near:?}");
    assert!(!newton_from(1e-4).converged());
    // lcp-lemke as a user runs it says where it stopped and why.
    let rod = forty_element_rod_with(MassModel::Consistent);
    let settings = semismooth_contact::settings::SolverSettings {
        method: semismooth_contact::settings::Method::LcpLemke,
        time_samples: nt,
        ..semismooth_contact::settings::SolverSettings::with_harmonics(20)
    };
    let lemke_run = semismooth_contact::solve::solve(&rod, rod.omega(), &settings, None).unwrap();
    assert!(
        matches!(
            lemke_run.termination,
            Termination::Lemke {
                outcome: LemkeTermination::PivotLimit,
                pivots: 6500,
                pivot_limit: 6500,
                order: 128,
                ..
            }
        ),
        "{}",
        lemke_run.termination
    );
    // From zero (the smoothing path on the min-map, then the line search and the Newton
    // homotopy) lcp-ssn does not get there: max-iterations after its whole budget.
    assert!(!sol.converged());
    assert_eq!(
        sol.termination,
        Termination::Newton(newton::Termination::MaxIterations)
    );
    assert_eq!(sol.iterations, 200);
    // The run says why, and what has no null vector.
    assert!(lcp.has_alternating_null_vector());
    assert_eq!(sol.diagnosis, Some(Diagnosis::AlternatingNullVector));
}

/// With the tip's mass moved to its neighbour (modified mass) the same rod's LCP is solved
/// by `lcp-ssn` from zero at `Nt` = 128 and 256: the coarsest level follows the smoothing
/// path of the min-map (`min(z, w) = z - max(0, z - w)`, the max smoothed), the finer one
/// starts from it interpolated. The answer is Lemke's (the same LCP solved by pivoting) to
/// round-off. At `Nt = 512` the finer level starts from an interpolation whose chattering
/// active set is wrong and ends at the iteration limit (295 iterations over the levels).
#[test]
fn modified_mass_strongly_forced_rod_lcp_ssn_from_zero_reaches_lemkes_solution_at_nt_128_and_256() {
    // (Nt, iterations measured over the levels: 41 and 41 + 54).
    for (nt, measured) in [(128usize, 41usize), (256, 95)] {
        let (lcp, sol) = forty_element_lcp(MassModel::Modified, nt);
        assert!(sol.converged(), "Nt = {nt}: {}", sol.termination);
        assert!(sol.diagnosis.is_none());
        let lemke = lcp.check_lemke(lemke_solution(&lcp)).unwrap();
        let zmax = lemke.z.iter().cloned().fold(0.0, f64::max);
        // Both end on one exact solve with the same active set (condition of A_II ~1e3):
        // agreement to round-off, measured 2.0e-14 and 2.0e-13 of the largest force at
        // Nt = 128 and 256, asserted at 2e-12 (10 times the larger).
        let diff = max_abs_diff(&sol.state, &lemke.z);
        assert!(diff < 2e-12 * zmax, "Nt = {nt}: {diff:e}");
        let window = measured * 9 / 10..=measured * 11 / 10;
        assert!(
            window.contains(&sol.iterations),
            "Nt = {nt}: {}",
            sol.iterations
        );
    }
    let (_, sol) = forty_element_lcp(MassModel::Modified, 512);
    assert_eq!(
        sol.termination,
        Termination::Newton(newton::Termination::MaxIterations)
    );
    // 41 + 54 on the coarser levels, the whole budget of 200 on the last.
    assert_eq!(sol.iterations, 295);
    // The massless tip has stiffness-proportional damping: the same null vector.
    assert!(sol.diagnosis.is_some());
}

/// A level that fails does not spend more than its budget: the polyalgorithm's paths
/// (smoothing, Newton homotopy) count every corrector iteration, restarts and rejected steps
/// included, against `max_iterations`. Measured before the paths had a hard budget: 229 and
/// 1,396 iterations on the last level at `Nt` = 512 and 1024 for a budget of 200.
#[test]
fn every_sequencing_level_stays_within_the_iteration_budget_when_it_fails() {
    let rod = forty_element_rod_with(MassModel::Modified);
    let model = &rod.structure.model;
    for (nt, budget) in [(512, 200), (1024, 200), (1024, 60)] {
        let lcp = PeriodicLcp::new(model, rod.omega(), options(nt, vec![])).unwrap();
        let newton_options = SolveOptions::Polyalgorithm(PolyalgorithmOptions {
            max_iterations: budget,
            ..PolyalgorithmOptions::default()
        });
        let solved = solve_min_map_sequenced(model, rod.omega(), &lcp, &newton_options).unwrap();
        assert!(!solved.converged(), "Nt = {nt}");
        for level in &solved.levels {
            assert!(
                level.report.iterations <= budget,
                "Nt = {nt}, level {}: {} iterations for a budget of {budget}",
                level.time_samples,
                level.report.iterations
            );
            let attempted: usize = level.report.attempts.iter().map(|a| a.iterations).sum();
            assert!(attempted <= budget, "{:?}", level.report.attempts);
        }
        assert_eq!(solved.levels.last().unwrap().report.iterations, budget);
    }
}

#[path = "periodic_lcp/bdf2.rs"]
mod bdf2;
