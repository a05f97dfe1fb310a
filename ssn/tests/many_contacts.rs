//! A hundred contacts: the mistuned bladed disk of `scenes/bladed_disk_casing.toml`
//! (300 dofs, a stop on each of 100 blade tip pads), and its tuned twin, whose cyclic
//! symmetry makes every blade answer exactly as one sector with one contact.

use semismooth_contact::model::{ContactPoint, HarmonicLoad, StructuralModel, Structure};
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::solve::solve;
use semismooth_contact::structures::BladedDisk;
use ssn::scene::Scene;

mod common;

fn shipped(edit: impl Fn(String) -> String) -> (Scene, Structure) {
    common::shipped_model("bladed_disk_casing.toml", edit)
}

#[test]
fn a_hundred_contacts_converge_and_the_linear_limit_is_exact() {
    let (scene, s) = shipped(|t| t);
    assert_eq!(s.model.contacts.len(), 100);
    assert_eq!(s.model.dofs(), 300);
    let sol = solve(&s, scene.omega(s.omega_1), &scene.solver, None).unwrap();
    // Measured: 13 iterations from zero at H = 5 (0.7 s on the 2-core machine).
    assert!(
        sol.converged() && sol.iterations <= 30,
        "{} {}",
        sol.termination,
        sol.iterations
    );
    let gap = s.model.contacts[0].gap;
    assert!(
        sol.stats.max > gap,
        "the first blade reaches the casing: {}",
        sol.stats.max
    );
    let means: Vec<f64> = sol
        .contact_forces
        .iter()
        .map(|f| f.iter().sum::<f64>() / f.len() as f64)
        .collect();
    assert!(
        means.iter().all(|f| *f < 0.0),
        "every blade rubs: {means:?}"
    );
    // Far casing: the exact linear response (dense complex solve of the 300 dofs).
    let (scene, far) = shipped(|t| t.replace("gap = 1.0", "gap = 1000.0"));
    let sol = solve(&far, scene.omega(far.omega_1), &scene.solver, None).unwrap();
    assert!(sol.converged());
    let (diff, z) = common::linear_history_error(&far.model, far.observed_dof, &sol);
    assert!(diff < 1e-9 * z, "{diff:e}");
}

/// The tuned disk of `semismooth_contact::structures` (no mistuning) with `blades` sectors
/// and a stop of gap `gap` on every pad; the load is 0.02 on every blade tip, the damping
/// `beta K` with `beta = 2 zeta / omega_1` of one sector (`zeta = 0.01`), the same for every
/// disk size.
fn tuned(blades: usize, gap: f64) -> StructuralModel {
    let (stiffness, mass, shape) = BladedDisk {
        blades,
        mistuning: 0.0,
    }
    .matrices();
    let mut model = StructuralModel {
        frictional_contacts: Vec::new(),
        mass,
        damping: Some(stiffness.clone()),
        stiffness,
        load: HarmonicLoad::cosine(shape.iter().map(|f| 0.02 * f).collect()),
        contacts: (0..blades)
            .map(|j| ContactPoint::new(BladedDisk::pad(j), gap))
            .collect(),
        friction: Vec::new(),
        cyclic: None,
    };
    let omega_1 = natural_frequencies(&model, 1).unwrap()[0];
    let beta = 2.0 * 0.01 / omega_1;
    if let Some(d) = model.damping.as_mut() {
        for v in d.val_mut() {
            *v *= beta;
        }
    }
    model
}

#[test]
fn a_tuned_disk_with_a_hundred_contacts_answers_as_one_sector_with_one_contact() {
    let (scene, shipped) = shipped(|t| t);
    // Both at the shipped scene's frequency.
    let omega = scene.omega(shipped.omega_1);
    let sector = tuned(1, 1.0);
    let disk = tuned(100, 1.0);
    // In phase (engine order 0) the ring springs carry no force: each sector is the
    // one-sector model. Its damping is the same beta K (omega_1 is the sector's).
    let one = Structure {
        omega_1: natural_frequencies(&sector, 1).unwrap()[0],
        model: sector,
        observed_dof: 1,
    };
    let all = Structure {
        omega_1: one.omega_1,
        model: disk,
        observed_dof: 3 * 57 + 1,
    };
    // SSN-HB's answer depends on c at finite H: the same c for both (the default is the
    // static stiffness at one contact with the others free, which the ring changes).
    let mut settings = scene.solver.clone();
    settings.c = Some(one.model.default_complementarity_constant());
    let a = solve(&one, omega, &settings, None).unwrap();
    let b = solve(&all, omega, &settings, None).unwrap();
    assert!(
        a.converged() && b.converged(),
        "{} / {}",
        a.termination,
        b.termination
    );
    assert!(
        a.stats.max > 1.0,
        "the blade reaches the casing: {}",
        a.stats.max
    );
    let diff = common::max_abs_diff(&a.observed, &b.observed);
    assert!(diff < 1e-10, "{diff:e}");
    for f in &b.contact_forces {
        let d = common::max_abs_diff(f, &a.contact_forces[0]);
        assert!(d < 1e-10, "{d:e}");
    }
}

#[test]
fn a_model_scene_is_estimated_from_its_imported_size_and_contacts() {
    use ssn::limits::{rod_scene_memory, run_memory, structure_memory};
    let (scene, s) = shipped(|t| t);
    // A [model] scene has no rod to estimate before its files are read.
    assert!(rod_scene_memory(&scene, false).is_none());
    let need = structure_memory(&s, &scene.solver, false);
    assert_eq!(need, run_memory(300, 100, &scene.solver));
    // The placeholder rod (one contact) would have been estimated at far less: the dense
    // condensed system of 100 x 11 unknowns is the difference.
    let placeholder = run_memory(scene.rod.elements, 1, &scene.solver);
    assert!(need.bytes > placeholder.bytes + 8.0 * 1100.0 * 1100.0);
}
