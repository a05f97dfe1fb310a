//! The forcing amplitude at which the tip of the canonical rod without its stop reaches the
//! stop's gap, in harmonic balance: one extra scalar unknown through the core's bordered solver.
//!
//! Unknowns: the first-harmonic coefficients `U = (u_c, u_s)` and the load factor `a`
//! (load `a f cos(w t)`, `f` the rod's load). Equations, with `Z = K - w^2 M`:
//! `[[Z, w D], [-w D, Z]] U - a (f, 0) = 0` and `(u_c[o]^2 + u_s[o]^2 - T^2) / 2 = 0` at the
//! observed dof `o`. Newton's Jacobian is bordered: `J` = the harmonic block (constant,
//! factored once), `B = -(f, 0)`, `C = (u_c[o] e_o, u_s[o] e_o)`, `D = 0`.
//! Independent check: the response is linear in `a`, so `a* = T / |u_o(1)|` with `u_o(1)`
//! from a complex dense LU of `K - w^2 M + i w D`.
//!
//! ```text
//! cargo run --release -p semismooth-contact --example bordered_amplitude
//! ```
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::sparse::{SparseColMat, Triplet};
use faer::{c64, Mat};
use semismooth::linalg::{BorderedSolver, FaerSparseLu};
use semismooth_contact::rod::{build_rod, RodSpec};

fn main() {
    let rod = build_rod(&RodSpec::canonical().with_tip_gap(None)).expect("the canonical rod");
    let (s, w) = (&rod.structure, rod.omega());
    let (model, o) = (&s.model, s.observed_dof);
    let load = model.load.forcing_cosine();
    let (n, target) = (load.len(), 0.5); // the canonical stop's gap
    let (k, m) = (&model.stiffness, &model.mass);
    let d = model.damping.as_ref().expect("a damped rod");
    // J = [[K - w^2 M, w D], [-w D, K - w^2 M]] on (u_c, u_s).
    let mut t = Vec::new();
    for (matrix, scale, blocks) in [
        (k, 1.0, [(0, 0, 1.0), (n, n, 1.0)]),
        (m, -w * w, [(0, 0, 1.0), (n, n, 1.0)]),
        (d, w, [(0, n, 1.0), (n, 0, -1.0)]),
    ] {
        for e in matrix.triplet_iter() {
            for (r, c, s) in blocks {
                t.push(Triplet::new(r + e.row, c + e.col, s * scale * e.val));
            }
        }
    }
    let jac = SparseColMat::try_new_from_triplets(2 * n, 2 * n, &t).expect("the HB block");
    let mut b = vec![0.0; 2 * n]; // B = -(f, 0)
    (0..n).for_each(|i| b[i] = -load[i]);
    // Newton on (U, a) from a guess with the phase of resonance: the tip's sine part at
    // the target (the root a > 0; -a gives the same amplitude).
    let (mut u, mut a) = (vec![0.0; 2 * n], 1.0);
    u[n + o] = target;
    let (mut lu, mut bordered) = (FaerSparseLu::new(), BorderedSolver::new(2 * n, 1));
    let (mut c, mut iterations) = (vec![0.0; 2 * n], 0);
    for iteration in 0..20 {
        // Residual: J U + a B, and the amplitude condition.
        let mut r = vec![0.0; 2 * n];
        for e in jac.triplet_iter() {
            r[e.row] += e.val * u[e.col];
        }
        r.iter_mut().zip(&b).for_each(|(r, b)| *r += a * b);
        let mut g = [(u[o] * u[o] + u[n + o] * u[n + o] - target * target) / 2.0];
        let norm = (r.iter().map(|v| v * v).sum::<f64>() + g[0] * g[0]).sqrt();
        println!("iteration {iteration}: |R| = {norm:.3e}, a = {a:.15}");
        if norm < 1e-12 {
            break; // loads ~1e-3, |K| ~ 1e2: rounding leaves ~1e-14
        }
        iterations += 1;
        (c[o], c[n + o]) = (u[o], u[n + o]);
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
    let mut z = Mat::<c64>::zeros(n, n);
    let (one, mass, imag) = (c64::new(1.0, 0.0), c64::new(-w * w, 0.0), c64::new(0.0, w));
    for (matrix, scale) in [(k, one), (m, mass), (d, imag)] {
        for e in matrix.triplet_iter() {
            z[(e.row, e.col)] += scale * *e.val;
        }
    }
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
