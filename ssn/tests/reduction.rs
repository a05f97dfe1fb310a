//! Craig–Bampton reduction of the CalculiX cantilever (`fixtures/calculix_cantilever`:
//! 216 dofs, tip contact, point load and observed dof on the tip centre's y): the reduced
//! natural frequencies against the full model's, and the forced response with contact on
//! the reduced model against the full model's (exact condensation), as modes are added.

use std::path::Path;

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::Structure;
use semismooth_contact::reduction::{
    boundary_dofs, craig_bampton, lowest_frequencies, CraigBampton, ModeCount,
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
        eprintln!("{modes}: {:?}", freqs.iter().zip(&exact).map(|(r, e)| r / e - 1.0).collect::<Vec<_>>());
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
