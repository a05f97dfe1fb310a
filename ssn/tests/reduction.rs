//! Craig–Bampton reduction of the CalculiX cantilever (`fixtures/calculix_cantilever`:
//! 216 dofs, tip contact, point load and observed dof on the tip centre's y): the reduced
//! natural frequencies against the full model's, and the forced response with contact on
//! the reduced model against the full model's (exact condensation), as modes are added.

use std::path::Path;

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::Structure;
use semismooth_contact::reduction::{
    boundary_dofs, craig_bampton, lowest_frequencies, massless_boundary, modal_damping,
    CraigBampton, ModeCount,
};
use semismooth_contact::rod::natural_frequencies;
use ssn::scene::Scene;

fn cantilever() -> (Scene, Structure) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/calculix_cantilever/cantilever.toml");
    let scene = Scene::from_path(path).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    (scene, structure)
}

fn reduce(full: &Structure, modes: usize) -> CraigBampton {
    craig_bampton(full, &boundary_dofs(full, &[]), ModeCount::Count(modes)).unwrap()
}

#[test]
fn lanczos_frequencies_are_the_subspace_iterations() {
    let (_, full) = cantilever();
    let lanczos = lowest_frequencies(&full.model, 10).unwrap();
    let subspace = natural_frequencies(&full.model, 10).unwrap();
    for (a, b) in lanczos.iter().zip(&subspace) {
        // Two solvers converged to 1e-10 (relative residual) and the subspace iteration's
        // own stopping rule: agreement to 1e-8.
        assert!((a - b).abs() < 1e-8 * b, "{a} vs {b}");
    }
}

#[test]
fn reduced_frequencies_approach_the_full_ones_from_above_and_equal_them_with_every_mode() {
    let (_, full) = cantilever();
    let exact = natural_frequencies(&full.model, 6).unwrap();
    let mut previous = vec![f64::INFINITY; 6];
    for modes in [8, 16, 32, 64, 215] {
        let reduced = reduce(&full, modes);
        assert_eq!(reduced.boundary.len(), 1);
        assert_eq!(reduced.structure.model.dofs(), 1 + modes);
        let freqs = natural_frequencies(&reduced.structure.model, 6).unwrap();
        for k in 0..6 {
            let error = freqs[k] / exact[k] - 1.0;
            // Rayleigh–Ritz: the reduced frequency bounds the full one from above (to the
            // eigensolvers' 1e-9).
            assert!(error > -1e-9, "{modes} modes, mode {}: {error:e}", k + 1);
            assert!(error <= previous[k] + 1e-9, "{modes} modes, mode {}", k + 1);
            previous[k] = error;
        }
    }
    // Every interior mode: T is square and invertible, the reduction exact.
    assert!(previous.iter().all(|e| e.abs() < 1e-8), "{previous:?}");
}

#[test]
fn a_frequency_cut_off_keeps_the_interface_modes_below_it_and_the_error_falls_as_it_rises() {
    let (_, full) = cantilever();
    let exact = natural_frequencies(&full.model, 6).unwrap();
    let mut previous = f64::INFINITY;
    for factor in [2.0, 4.0, 8.0, 16.0] {
        let cut_off = factor * exact[5];
        let boundary = boundary_dofs(&full, &[]);
        let reduced = craig_bampton(&full, &boundary, ModeCount::Below(cut_off)).unwrap();
        let kept = &reduced.interface_frequencies;
        assert!(kept.iter().all(|w| *w <= cut_off), "{kept:?}");
        assert!(kept.windows(2).all(|p| p[0] <= p[1]));
        // The next interior mode lies above the cut-off: one more mode by count has it.
        let one_more = reduce(&full, kept.len() + 1);
        assert!(one_more.interface_frequencies[kept.len()] > cut_off);
        let freqs = natural_frequencies(&reduced.structure.model, 6).unwrap();
        let worst = freqs
            .iter()
            .zip(&exact)
            .map(|(r, e)| r / e - 1.0)
            .fold(0.0f64, f64::max);
        eprintln!(
            "cut-off {factor} omega_6: {} modes, worst error {worst:e}",
            kept.len()
        );
        // More modes, a smaller error (Rayleigh–Ritz on a larger space).
        assert!(worst <= previous + 1e-9, "{worst:e} after {previous:e}");
        previous = worst;
    }
    // 16 times the highest frequency of interest: the six to 1e-5 (measured 2.7e-6; 2, 4,
    // 8 times: 3.6e-3, 4.5e-4, 3.4e-5).
    assert!(previous < 1e-5, "{previous:e}");
}

/// The observed dof's samples of the scene's solve on `structure` at the absolute `omega`.
fn observed(scene: &Scene, structure: &Structure, omega: f64) -> Vec<f64> {
    let s = semismooth_contact::solve(structure, omega, &scene.solver, None).unwrap();
    assert!(
        s.converged(),
        "{} dofs: {}",
        structure.model.dofs(),
        s.termination
    );
    s.observed
}

#[test]
fn the_reduced_forced_response_with_tip_contact_converges_to_the_full_one_as_modes_are_added() {
    let (scene, full) = cantilever();
    let omega = scene.omega(full.omega_1);
    let exact = observed(&scene, &full, omega);
    let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // The contact closes: the tip reaches the gap.
    assert!(scale > 0.0015 * 0.999, "{scale}");
    let mut errors = Vec::new();
    for modes in [2, 4, 8, 16, 32, 64, 215] {
        let reduced = reduce(&full, modes);
        let x = observed(&scene, &reduced.structure, omega);
        let error = x
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale;
        eprintln!("{modes} modes: response error {error:e}");
        errors.push(error);
    }
    for pair in errors.windows(2) {
        assert!(pair[1] <= pair[0] * 1.01 + 1e-9, "{errors:?}");
    }
    // Every interior mode: the same equations in other coordinates, solved to the Newton
    // tolerance (1e-10 relative residual by default) on a conditioning of about 1e4.
    assert!(errors[errors.len() - 1] < 1e-9, "{errors:?}");
    // 8 fixed-interface modes: the response to 1e-3 of its amplitude (measured 2.1e-4).
    assert!(errors[2] < 1e-3, "{errors:?}");
}

#[test]
fn a_reduction_section_solves_the_reduced_structure_and_its_mistakes_are_named() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/calculix_cantilever");
    let loaded = ssn::cli::load(&dir.join("cantilever_reduced.toml")).unwrap();
    assert_eq!(loaded.structure.model.dofs(), 17);
    let (scene, full) = cantilever();
    // The scene's frequency ratio keeps the full model's omega_1 as its unit.
    assert_eq!(loaded.omega, scene.omega(full.omega_1));
    let by_hand = reduce(&full, 16);
    let a = observed(&loaded.scene, &loaded.structure, loaded.omega);
    let b = observed(&scene, &by_hand.structure, loaded.omega);
    // The same reduction of the same matrices: the same arithmetic.
    assert_eq!(a, b);
    let text = std::fs::read_to_string(dir.join("cantilever_reduced.toml")).unwrap();
    let path = dir.join("cantilever_reduced.toml");
    for (from, to, words) in [
        (
            "modes = 16",
            "modes = 16\ncutoff_ratio = 2.0",
            &["reduction.cutoff_ratio", "either `modes`"][..],
        ),
        ("modes = 16", "", &["reduction.modes", "missing"]),
        (
            "modes = 16",
            "modes = 16\nmodal_damping = -0.1",
            &["reduction.modal_damping", "-0.1", ">= 0"],
        ),
        ("modes = 16", "modes = 0", &["reduction.modes", "0"]),
        (
            "\"craig-bampton\"",
            "\"guyan\"",
            &["guyan", "craig-bampton"],
        ),
    ] {
        let e = Scene::from_toml(&text.replace(from, to), &path)
            .unwrap_err()
            .to_string();
        for w in words {
            assert!(e.contains(w), "`{w}` not in: {e}");
        }
    }
    // `modal_damping` replaces the reduced damping by the library's modal damping.
    let damped = text.replace("modes = 16", "modes = 16\nmodal_damping = 0.02");
    let damped = Scene::from_toml(&damped, &path).unwrap();
    let loaded = ssn::cli::prepare(damped, ssn::work::Workload::Solve, None).unwrap();
    let expected = modal_damping(&by_hand.structure.model, 0.02).unwrap();
    assert_eq!(
        loaded.structure.model.damping.unwrap().val(),
        expected.val()
    );
}

/// The dense copy of a sparse matrix.
fn dense(a: &semismooth_contact::model::SparseMatrix) -> nalgebra::DMatrix<f64> {
    let r = a.as_ref();
    let mut d = nalgebra::DMatrix::zeros(a.nrows(), a.ncols());
    for j in 0..a.ncols() {
        for (i, &v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
            d[(i, j)] += v;
        }
    }
    d
}

#[test]
fn modal_damping_gives_each_reduced_mode_its_ratio_in_the_linear_response() {
    let (scene, full) = cantilever();
    let mut reduced = reduce(&full, 16).structure;
    let zeta = 0.02;
    reduced.model.damping = Some(modal_damping(&reduced.model, zeta).unwrap());
    // A tenth of the scene's load: the tip moves a fifth of the gap at most, the contact
    // stays open and the response is linear.
    let linear = |model: &mut semismooth_contact::model::StructuralModel| {
        model.load = model.load.clone().scaled(0.1);
    };
    linear(&mut reduced.model);
    let omega = scene.omega(full.omega_1);
    let s = semismooth_contact::solve(&reduced, omega, &scene.solver, None).unwrap();
    assert!(s.converged(), "{}", s.termination);
    // The closed form by modal superposition, the modes from a dense eigensolver
    // (nalgebra, independent of the Lanczos that built D): with M = L L^T and
    // L^{-1} K L^{-T} = V diag(omega_k^2) V^T, phi_k = L^{-T} v_k and
    // U = sum_k phi_k(o) phi_k^T f / (omega_k^2 - omega^2 + 2 i zeta omega_k omega).
    let (k, m) = (dense(&reduced.model.stiffness), dense(&reduced.model.mass));
    let l = nalgebra::Cholesky::new(m)
        .expect("M_r positive definite")
        .l();
    let a = l.solve_lower_triangular(&k).unwrap();
    let a = l.solve_lower_triangular(&a.transpose()).unwrap();
    let eigen = nalgebra::SymmetricEigen::new(0.5 * (&a + a.transpose()));
    let phi = l
        .transpose()
        .solve_upper_triangular(&eigen.eigenvectors)
        .unwrap();
    let f = nalgebra::DVector::from_vec(reduced.model.load.forcing_cosine());
    let o = reduced.observed_dof;
    let mut u = nalgebra::Complex::new(0.0, 0.0);
    for (kk, &w2) in eigen.eigenvalues.iter().enumerate() {
        let p = phi.column(kk);
        let wk = w2.sqrt();
        u += p[o] * p.dot(&f) / nalgebra::Complex::new(w2 - omega * omega, 2.0 * zeta * wk * omega);
    }
    let amplitude = u.norm();
    for (t, x) in s.times.iter().zip(&s.observed) {
        let exact = (u * nalgebra::Complex::new(0.0, omega * t).exp()).re;
        // The solve converges to its Newton tolerance and the two eigensolvers agree to
        // round-off: the samples agree to 1e-6 of the amplitude.
        assert!(
            (x - exact).abs() <= 1e-6 * amplitude,
            "t = {t}: {x} vs {exact} ({} iterations, {})",
            s.iterations,
            s.termination
        );
    }
    assert!(
        amplitude < 0.2 * reduced.model.contacts[0].gap,
        "{amplitude}"
    );
    // Against the projected stiffness-proportional damping (zeta = 0.05 at omega_1) the
    // response differs: the damping is the modal one.
    let mut projected = reduce(&full, 16).structure;
    linear(&mut projected.model);
    let p = semismooth_contact::solve(&projected, omega, &scene.solver, None).unwrap();
    let peak = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!((peak(&p.observed) - peak(&s.observed)).abs() > 1e-3 * amplitude);
}

#[test]
fn the_massless_boundary_reduction_converges_to_the_full_model_as_modes_are_added() {
    let (scene, full) = cantilever();
    let boundary = boundary_dofs(&full, &[]);
    let exact_freqs = natural_frequencies(&full.model, 6).unwrap();
    let omega = scene.omega(full.omega_1);
    let exact = observed(&scene, &full, omega);
    let amplitude = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let error = |x: &[f64]| -> f64 {
        x.iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / amplitude
    };
    let mut previous = f64::INFINITY;
    for modes in [8, 16, 32] {
        let reduced = massless_boundary(&full, &boundary, ModeCount::Count(modes)).unwrap();
        let model = &reduced.structure.model;
        assert_eq!(model.dofs(), 1 + modes);
        // The boundary coordinate carries no mass.
        assert!(model.mass.as_ref().val_of_col(0).iter().all(|&v| v == 0.0));
        // The one massless coordinate has no finite frequency: `modes` remain.
        let freqs = natural_frequencies(model, 6).unwrap();
        let freq_error = (0..6)
            .map(|k| (freqs[k] / exact_freqs[k] - 1.0).abs())
            .fold(0.0, f64::max);
        let mut r = reduced.structure.clone();
        r.omega_1 = full.omega_1;
        let x = observed(&scene, &r, omega);
        let cb = observed(&scene, &reduce(&full, modes).structure, omega);
        let response_error = error(&x);
        println!(
            "{modes} free-interface modes: frequency error {freq_error:.1e}, response error \
             {response_error:.1e} (Craig-Bampton {:.1e})",
            error(&cb)
        );
        // The kept free-interface modes are the full model's own, and condensing the
        // massless boundary gives back `Lambda` exactly: the frequencies below the cut-off
        // are the full ones to the eigensolvers' round-off (measured 5e-13).
        assert!(freq_error < 1e-10, "{modes}: {freq_error:e}");
        // The response with tip contact approaches the full model's exact condensation
        // as modes are added (measured 1.9e-5, 8.4e-7, 2.8e-7; Craig-Bampton's 2.1e-4,
        // 2.7e-5, 3.2e-7).
        assert!(response_error < previous, "{modes}: {response_error:e}");
        previous = response_error;
    }
    assert!(previous < 1e-6, "{previous:e}");
}
