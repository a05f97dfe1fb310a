//! The periodic LCP with the BDF2 scheme: its linear response against the response at its
//! symbol, its Nyquist receptance, its solutions against Lemke's and against the
//! trapezoidal LCPs.

use super::*;

/// `(K + s D + s^2 M)^{-1} f` for a complex `s`, by a dense complex solve.
fn response_at_symbol(model: &StructuralModel, s: Complex<f64>) -> DVector<Complex<f64>> {
    let (k, m, d) = dense_kmd(model);
    let z = DMatrix::from_fn(k.nrows(), k.ncols(), |i, j| {
        s * s * m[(i, j)] + s * d[(i, j)] + k[(i, j)]
    });
    let load = model.load.forcing_cosine();
    let f = DVector::from_fn(k.nrows(), |i, _| Complex::new(load[i], 0.0));
    z.lu().solve(&f).unwrap()
}

/// The BDF2 symbol `(3 - 4 e^{-i theta} + e^{-2 i theta}) / (2 dt)`, written from the
/// difference formula (not from the library).
fn bdf2(theta: f64, dt: f64) -> Complex<f64> {
    let back = Complex::new(theta.cos(), -theta.sin());
    (Complex::new(3.0, 0.0) - back * 4.0 + back * back) / (2.0 * dt)
}

fn bdf2_options(nt: usize, observed: Vec<usize>) -> PeriodicLcpOptions {
    PeriodicLcpOptions {
        scheme: LcpScheme::Bdf2,
        ..options(nt, observed)
    }
}

#[test]
fn bdf2_linear_response_is_the_response_at_its_symbol_and_converges_at_second_order() {
    let (model, omega) = rod(MassModel::Consistent, true);
    let dofs: Vec<usize> = (0..model.dofs()).collect();
    let mut errors = Vec::new();
    for nt in [128usize, 256, 512, 1024] {
        let lcp = PeriodicLcp::new(&model, omega, bdf2_options(nt, dofs.clone())).unwrap();
        let u = lcp.displacements(&vec![0.0; lcp.dim()]).unwrap();
        let dt = lcp.time_step();
        let symbol = bdf2(2.0 * std::f64::consts::PI / nt as f64, dt);
        let at_symbol = at_nodes(&response_at_symbol(&model, symbol), nt);
        let exact = frequency_response(&model, omega, nt);
        let scale = exact.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut error = 0.0f64;
        for dof in 0..model.dofs() {
            // Two O(N) complex solves of the same system: round-off.
            assert!(max_abs_diff(&u[dof], &at_symbol[dof]) < 1e-11 * scale);
            error = error.max(max_abs_diff(&u[dof], &exact[dof]));
        }
        errors.push(error / scale);
    }
    // s_1 dt = i theta (1 + theta^2 / 3) + theta^4 / 4 + ...: the trapezoidal rule's
    // warping at second order. The numerical damping ratio theta^3 / 4 is of higher order
    // but, on the resonance (zeta = 0.01), only negligible once well below zeta: measured
    // orders 1.3 / 1.9 from Nt = 32 / 64, 1.99 to 2.00 from Nt = 128.
    assert_second_order(&errors);
}

/// With BDF2 the Nyquist symbol is real, `s = 4 / dt`, and `Z = K + s D + s^2 M` is
/// symmetric positive definite: the Nyquist receptance of the strongly forced rod's tip is
/// positive, where the trapezoidal rule's is 0 (every dof has mass or damping), and the
/// alternating force `(-1)^n` moves the tip by exactly that receptance.
#[test]
fn bdf2_nyquist_receptance_is_positive_so_the_alternating_force_is_no_null_vector() {
    for mass in [MassModel::Consistent, MassModel::Modified] {
        let rod = forty_element_rod_with(mass);
        let model = &rod.structure.model;
        let tip = model.contacts[0].dof();
        let nt = 128;
        let trapezoidal = PeriodicLcp::new(model, rod.omega(), options(nt, vec![])).unwrap();
        assert_eq!(trapezoidal.receptance(nt / 2)[0].re, 0.0);
        let lcp = PeriodicLcp::new(model, rod.omega(), bdf2_options(nt, vec![])).unwrap();
        let s = 4.0 / lcp.time_step();
        let (k, m, d) = dense_kmd(model);
        let z = &k + &d * s + &m * (s * s);
        let e = DVector::from_fn(model.dofs(), |i, _| if i == tip { 1.0 } else { 0.0 });
        let expected = z.cholesky().expect("s.p.d. at Nyquist").solve(&e)[tip];
        let nyquist = lcp.receptance(nt / 2)[0];
        assert!(expected > 0.0);
        assert!(
            (nyquist.re - expected).abs() < 1e-10 * expected && nyquist.im.abs() < 1e-14,
            "{nyquist} against {expected:e}"
        );
        let a = lcp.matrix();
        for i in 0..nt {
            let image: f64 = (0..nt)
                .map(|j| a[(i, j)] * if j % 2 == 0 { 1.0 } else { -1.0 })
                .sum();
            let alternating = if i % 2 == 0 { 1.0 } else { -1.0 };
            assert!((image - expected * alternating).abs() < 1e-9 * expected + 1e-15);
        }
    }
}

/// The BDF2 LCP of the strongly forced 40-element rod (the case whose trapezoidal LCP has
/// the null vector and a chattering solution) is solved from zero by `lcp-ssn` at every
/// `Nt` from 128 to 2048 with the modified mass and up to 1024 with the consistent mass,
/// and the answer is Lemke's, the same LCP solved by pivoting. Lemke's pivots grow about
/// linearly with the massless contact (one contact phase, no chattering). The consistent
/// mass at `Nt = 2048` needs more than the default budget of 200 iterations per level (a
/// third contact episode appears that the interpolated `Nt = 1024` solution does not have,
/// and the line search takes 160 iterations to find it): measured, it fails at 200 and
/// converges at 400.
#[test]
fn bdf2_lcp_of_the_strongly_forced_rod_is_solved_from_zero_and_agrees_with_lemke() {
    // (mass, Nt, lcp-ssn iterations summed over the levels, Lemke pivots), measured.
    let cases = [
        (MassModel::Modified, 128, 4, 51),
        (MassModel::Modified, 256, 6, 96),
        (MassModel::Modified, 512, 8, 191),
        (MassModel::Modified, 1024, 9, 380),
        (MassModel::Modified, 2048, 11, 759),
        (MassModel::Consistent, 128, 40, 63),
        (MassModel::Consistent, 256, 42, 160),
        (MassModel::Consistent, 512, 78, 603),
        (MassModel::Consistent, 1024, 80, 2657),
        (MassModel::Consistent, 2048, 280, 34_326),
    ];
    for (mass, nt, iterations, pivots) in cases {
        let (lcp, sol) = forty_element_lcp_with(mass, nt, LcpScheme::Bdf2);
        let case = format!("{mass:?}, Nt = {nt}");
        let lemke = lcp.check_lemke(lemke_solution(&lcp)).unwrap();
        let within = |measured: usize, found: usize| {
            found + 2 >= measured * 9 / 10 && found <= measured * 11 / 10 + 2
        };
        assert!(within(pivots, lemke.pivots), "{case}: {}", lemke.pivots);
        assert!(
            within(iterations, sol.iterations),
            "{case}: {}",
            sol.iterations
        );
        let sol = if (mass, nt) == (MassModel::Consistent, 2048) {
            // 80 iterations up to Nt = 1024, then the whole default budget of the last
            // level: 30 full steps, the line search on half of the 170 left, the Newton
            // homotopy on the rest.
            assert!(!sol.converged(), "{case}");
            assert_eq!(
                sol.termination,
                Termination::Newton(newton::Termination::MaxIterations)
            );
            // Not the trapezoidal null vector: no diagnosis.
            assert!(!lcp.has_alternating_null_vector() && sol.diagnosis.is_none());
            // The line search needs 160 iterations there: with max_iterations = 400 it gets
            // 185 and converges (270 iterations over the levels).
            let sol = lcp_ssn_from_zero(&forty_element_rod_with(mass), nt, LcpScheme::Bdf2, 400);
            assert!(within(270, sol.iterations), "{case}: {}", sol.iterations);
            assert_eq!(sol.strategy, Some(Strategy::LineSearch));
            sol
        } else {
            sol
        };
        assert!(sol.converged(), "{case}: {}", sol.termination);
        // The finest level's strategy is the answer's (full steps from the interpolated
        // coarser solution, or a fallback when they stall).
        let last = sol.attempts.last().expect("the finest level's attempts");
        assert!(last.converged && sol.strategy == Some(last.strategy));
        // Both end on one exact solve with the same active set: round-off, which grows with
        // the conditioning of A_II and so with Nt (measured 7.8e-15 of the largest force at
        // Nt = 128 to 7.1e-11 at 2048), asserted at 1e-9 (14 times the largest).
        let zmax = lemke.z.iter().cloned().fold(0.0, f64::max);
        let diff = max_abs_diff(&sol.state, &lemke.z);
        assert!(diff < 1e-9 * zmax, "{case}: {diff:e}");
    }
}

/// The BDF2 tip minimum converges at second order as `Nt` doubles (measured ratios of the
/// successive changes 6.2, 4.9, 4.4), to the value of the trapezoidal LCP (an independent
/// discretisation, solved by Lemke where it is established, `Nt = 512` with the modified
/// mass): at `Nt = 2048` the two differ by less than the trapezoidal LCP's own last change.
#[test]
fn bdf2_tip_minimum_converges_at_second_order_to_the_trapezoidal_lcps() {
    let tip_min = |lcp: &PeriodicLcp, z: &[f64]| {
        lcp.contact_displacements(z).unwrap()[0]
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min)
    };
    let bdf2: Vec<f64> = [128, 256, 512, 1024, 2048]
        .into_iter()
        .map(|nt| {
            let (lcp, sol) = forty_element_lcp_with(MassModel::Modified, nt, LcpScheme::Bdf2);
            assert!(sol.converged());
            tip_min(&lcp, &sol.state)
        })
        .collect();
    let changes: Vec<f64> = bdf2.windows(2).map(|p| (p[1] - p[0]).abs()).collect();
    for pair in changes.windows(2) {
        assert!(pair[0] > 3.5 * pair[1], "tip minima {bdf2:?}");
    }
    let trapezoidal: Vec<f64> = [256, 512]
        .into_iter()
        .map(|nt| {
            let rod = forty_element_rod_with(MassModel::Modified);
            let lcp =
                PeriodicLcp::new(&rod.structure.model, rod.omega(), options(nt, vec![])).unwrap();
            let lemke = lcp.check_lemke(lemke_solution(&lcp)).unwrap();
            tip_min(&lcp, &lemke.z)
        })
        .collect();
    let trapezoidal_change = (trapezoidal[1] - trapezoidal[0]).abs();
    let difference = (bdf2[4] - trapezoidal[1]).abs();
    assert!(
        difference < trapezoidal_change,
        "BDF2 {bdf2:?}, trapezoidal {trapezoidal:?}"
    );
}

/// BDF2 is no cure at fine steps for a massive contact node: its Nyquist receptance, the
/// static-like solve of `K + (4/dt) D + (16/dt^2) M`, shrinks like `dt^2`, and the LCP becomes
/// nearly degenerate again. On the canonical rod with the consistent mass, `lcp-ssn` from zero
/// (measured: 8 / 20 / 40 iterations over the levels) and Lemke agree at `Nt` = 128 / 256 /
/// 512, with tip minima approaching each other at second order; at `Nt = 1024` lcp-ssn ends
/// at its budget on the last level (40 + 200 iterations), a measured limit.
#[test]
fn bdf2_with_a_massive_contact_node_solves_up_to_nt_512_and_not_at_1024() {
    let rod = build_rod(&RodSpec {
        mass: MassModel::Consistent,
        ..RodSpec::canonical()
    })
    .unwrap();
    let solve = |nt: usize| lcp_ssn_from_zero(&rod, nt, LcpScheme::Bdf2, 200);
    let mut minima = Vec::new();
    for (nt, measured) in [(128, 8), (256, 20), (512, 40)] {
        let sol = solve(nt);
        assert!(sol.converged(), "Nt = {nt}: {}", sol.termination);
        assert!(
            sol.iterations + 2 >= measured * 9 / 10 && sol.iterations <= measured * 11 / 10 + 2,
            "Nt = {nt}: {}",
            sol.iterations
        );
        let lcp =
            PeriodicLcp::new(&rod.structure.model, rod.omega(), bdf2_options(nt, vec![])).unwrap();
        let lemke = lcp.check_lemke(lemke_solution(&lcp)).unwrap();
        let zmax = lemke.z.iter().cloned().fold(0.0, f64::max);
        assert!(
            max_abs_diff(&sol.state, &lemke.z) < 1e-9 * zmax,
            "Nt = {nt}"
        );
        minima.push(sol.stats.min);
    }
    // Measured -0.525709 / -0.523562 / -0.523253: changes 2.1e-3 then 3.1e-4.
    assert!(
        (minima[0] - minima[1]).abs() > 4.0 * (minima[1] - minima[2]).abs(),
        "{minima:?}"
    );
    let sol = solve(1024);
    assert!(!sol.converged());
    // The line search stops at a kink of the merit, the Newton homotopy spends the rest.
    assert!(
        sol.termination == Termination::Newton(newton::Termination::LineSearchFailed),
        "{}",
        sol.termination
    );
    assert_eq!(sol.iterations, 240);
}
