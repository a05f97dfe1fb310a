//! The forcing amplitude at which the tip of the canonical rod without its stop reaches the
//! stop's gap, in harmonic balance: one extra scalar unknown through the core's bordered solver.
//!
//! Unknowns: the harmonic-balance coefficients `U` of the library's SSN-HB problem without
//! contact at H = 1 (`R_0(U) = A(w) U - F`) and the load factor `a`. Equations:
//! `A(w) U - a F = R_0(U) + (a - 1) b = 0` with `b = R_0(0) = -F`, and
//! `(u_c[o]^2 + u_s[o]^2 - T^2) / 2 = 0` at the observed dof `o`. Newton's Jacobian is
//! bordered: `J` = the problem's Jacobian `A(w)` (constant, factored once), `B = b`,
//! `C = (u_c[o] e_c, u_s[o] e_s)`, `D = 0`.
//! Independent check: the response is linear in `a`, so `a* = T / |u_o(1)|` with `u_o(1)`
//! from a complex dense LU of `K - w^2 M + i w D`.
//!
//! ```text
//! cargo run --release -p semismooth-contact --example bordered_amplitude
//! ```
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{c64, Mat};
use semismooth::linalg::{BorderedSolver, FaerDenseLu};
use semismooth::{GeneralizedJacobian, Residual};
use semismooth_contact::hb::{HbOptions, SsnHb};
use semismooth_contact::rod::{build_rod, RodSpec};

fn main() {
    let rod = build_rod(&RodSpec::canonical().with_tip_gap(None)).expect("the canonical rod");
    let (s, w) = (&rod.structure, rod.omega());
    let (model, o) = (&s.model, s.observed_dof);
    let options = HbOptions {
        harmonics: 1,
        ..HbOptions::default()
    };
    let mut hb = SsnHb::new(model, w, &options).expect("the rod's harmonic balance");
    let (n, dim, target) = (model.dofs(), hb.dim(), 0.5); // the canonical stop's gap
    let (cos, sin) = (n + o, 2 * n + o); // u_c[o], u_s[o] (harmonic-major unknowns)
    let mut b = vec![0.0; dim]; // B = R_0(0) = -F
    hb.residual(&vec![0.0; dim], &mut b).expect("the residual");
    let mut jac = hb.new_jacobian(); // A(w): the problem is linear
    hb.jacobian(&vec![0.0; dim], &mut jac)
        .expect("the Jacobian");
    // Newton on (U, a) from a guess with the phase of resonance: the tip's sine part at
    // the target (the root a > 0; -a gives the same amplitude).
    let (mut u, mut a) = (vec![0.0; dim], 1.0);
    u[sin] = target;
    let (mut lu, mut bordered) = (FaerDenseLu::new(), BorderedSolver::new(dim, 1));
    let (mut c, mut r, mut iterations) = (vec![0.0; dim], vec![0.0; dim], 0);
    for iteration in 0..20 {
        // Residual: R_0(U) + (a - 1) b, and the amplitude condition.
        hb.residual(&u, &mut r).expect("the residual");
        r.iter_mut().zip(&b).for_each(|(r, b)| *r += (a - 1.0) * b);
        let mut g = [(u[cos] * u[cos] + u[sin] * u[sin] - target * target) / 2.0];
        let norm = (r.iter().map(|v| v * v).sum::<f64>() + g[0] * g[0]).sqrt();
        println!("iteration {iteration}: |R| = {norm:.3e}, a = {a:.15}");
        if norm < 1e-12 {
            break; // loads ~1e-3, |K| ~ 1e2: rounding leaves ~1e-14
        }
        iterations += 1;
        (c[cos], c[sin]) = (u[cos], u[sin]);
        if iteration == 0 {
            bordered.factor(&mut lu, &jac, &b, &c, &[0.0])
        } else {
            bordered.factor_border(&mut lu, &b, &c, &[0.0]) // J is constant: no refactoring
        }
        .expect("a regular bordered matrix");
        bordered.solve(&mut lu, &mut r, &mut g).expect("a solve");
        u.iter_mut().zip(&r).for_each(|(u, d)| *u -= d);
        a -= g[0];
    }
    // Independent: the complex response to the unit load factor, scaled linearly.
    let (k, m) = (&model.stiffness, &model.mass);
    let d = model.damping.as_ref().expect("a damped rod");
    let mut z = Mat::<c64>::zeros(n, n);
    let (one, mass, imag) = (c64::new(1.0, 0.0), c64::new(-w * w, 0.0), c64::new(0.0, w));
    for (matrix, scale) in [(k, one), (m, mass), (d, imag)] {
        for e in matrix.triplet_iter() {
            z[(e.row, e.col)] += scale * *e.val;
        }
    }
    let load = model.load.forcing_cosine();
    let mut x = Mat::<c64>::from_fn(n, 1, |i, _| c64::new(load[i], 0.0));
    PartialPivLu::new(z.as_ref()).solve_in_place(x.as_mut());
    let closed_form = target / x[(o, 0)].norm();
    let counters = bordered.counters();
    let work = (counters.factorizations, counters.solves);
    println!(
        "load factor {a:.15} (p0 = {:.12}), closed form {closed_form:.15}, relative difference \
         {:.1e}; {work:?} factorizations of J and solves",
        a * rod.spec.amplitude,
        (a - closed_form).abs() / closed_form
    );
    // Two LU solutions (real 2N and complex N) of the same dynamics, condition ~1e4 (the
    // element stiffness spread times 1/(2 zeta) at resonance): ~1e-12 at worst, measured 3e-14.
    assert!((a - closed_form).abs() <= 1e-11 * closed_form);
    // One factorization of J for the whole Newton run, k + 1 = 2 solves per iteration.
    assert_eq!(work, (1, 2 * iterations));
}
