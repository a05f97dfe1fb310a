//! `[model] format` for every finite-element format: the beam of the library's
//! `tests/fixtures/fe_formats` (written by CalculiX, and in Abaqus, Nastran DMIG and
//! Harwell-Boeing form from the same numbers) as a scene whose load, contact and observed
//! dof are named by node and component. Every format, given or detected from the file
//! names, gives the same structure, and its natural frequencies are those CalculiX printed.

mod common;

use std::path::{Path, PathBuf};

use semismooth_contact::matrix_market::{build_imported, MatrixFormat};
use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use ssn::scene::Scene;

fn fixture_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../contact/tests/fixtures/fe_formats")
}

/// The scene of the beam with the `[model]` keys `model`; node 20 (a corner of the free
/// end) loaded, in contact and observed along y.
fn scene_text(model: &str) -> String {
    format!(
        "[model]\n{model}\n[damping]\nzeta = 0.05\n\n[forcing]\nnode = 20\ncomponent = 2\n\
         amplitude = 1.0\nomega_ratio = 0.8\n\n[[contact.point]]\nnode = 20\ncomponent = 2\n\
         gap = 1e-7\n\n[output]\nnode = 20\ncomponent = 2\n\n[solver]\nharmonics = 5\n"
    )
}

/// The `[model]` keys of each format (`format` given), and the same files without it.
const MODELS: [(&str, MatrixFormat); 4] = [
    (
        "stiffness = \"beam.sti\"\nmass = \"beam.mas\"\ndof_map = \"beam.dof\"",
        MatrixFormat::CalculiX,
    ),
    (
        "stiffness = \"beam_STIF1.mtx\"\nmass = \"beam_MASS1.mtx\"",
        MatrixFormat::Abaqus,
    ),
    (
        "stiffness = \"beam.pch\"\nmass = \"beam.pch\"",
        MatrixFormat::NastranDmig,
    ),
    (
        "stiffness = \"beam_K.matrix\"\nmass = \"beam_M.matrix\"\ndof_map = \"beam.mapping\"",
        MatrixFormat::HarwellBoeing,
    ),
];

fn imported(model: &str) -> Result<(Scene, Structure), String> {
    let scene = Scene::from_toml(&scene_text(model), fixture_dir().join("beam.toml"))
        .map_err(|e| e.to_string())?;
    let structure = build_imported(scene.model.as_ref().unwrap()).map_err(|e| e.to_string())?;
    Ok((scene, structure))
}

#[test]
fn every_format_given_or_detected_gives_the_same_structure_and_calculix_frequencies() {
    let (_, reference) = imported(MODELS[0].0).unwrap();
    let model = &reference.model;
    assert_eq!(model.dofs(), 48);
    let printed = common::calculix_eigenvalues(&fixture_dir().join("beam_modes.dat"));
    assert_eq!(printed.len(), 4);
    let ours = natural_frequencies(model, printed.len()).unwrap();
    for (k, (w, lambda)) in ours.iter().zip(&printed).enumerate() {
        // CalculiX prints omega^2 with 7 significant digits (half a unit of the last: at most
        // 5e-7 relative for 0.1545852E+10); the matrices were rounded to 10 digits (about
        // 1e-10 relative on the eigenvalues). 1e-6 leaves room for both.
        let relative = (w * w - lambda).abs() / lambda;
        assert!(relative < 1e-6, "mode {}: {} vs {lambda}", k + 1, w * w);
    }
    for (keys, format) in MODELS {
        let given = format!("format = \"{}\"\n{keys}", format.name());
        for model_keys in [given.as_str(), keys] {
            let (scene, s) = imported(model_keys).unwrap();
            let spec = scene.model.as_ref().unwrap();
            assert_eq!(spec.format, format, "{model_keys}");
            assert_eq!(s.model.stiffness.to_dense(), model.stiffness.to_dense());
            assert_eq!(s.model.mass.to_dense(), model.mass.to_dense());
            assert_eq!(s.model.load.as_cosine(), model.load.as_cosine());
            assert_eq!(s.model.contacts, model.contacts);
            assert_eq!(s.observed_dof, reference.observed_dof);
            assert_eq!(s.omega_1, reference.omega_1);
        }
    }
    // Node 20's y is the row the CalculiX dof file lists for `20.2`.
    let dof = std::fs::read_to_string(fixture_dir().join("beam.dof")).unwrap();
    let row = dof.lines().position(|l| l.trim() == "20.2").unwrap();
    assert_eq!(reference.observed_dof, row);
}

#[test]
fn a_dof_map_beside_labelled_files_and_a_defect_of_a_file_are_named() {
    let e = imported(&format!("{}\ndof_map = \"beam.dof\"", MODELS[1].0)).unwrap_err();
    for w in ["model.dof_map", "abaqus", "node labels", "calculix"] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    let e = imported("stiffness = \"beam.pch\"\nmass = \"beam_M.matrix\"").unwrap_err();
    for w in ["beam_M.matrix", "Nastran DMIG", "no DMIG matrix"] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    let calculix = format!("format = \"calculix\"\n{}", MODELS[0].0);
    let e = imported(&calculix.replace("beam.sti", "beam.pch")).unwrap_err();
    for w in ["beam.pch", "line 1", "CalculiX"] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    // A node the files do not name (node 1 is on the clamped face).
    let text = scene_text(MODELS[2].0).replace(
        "node = 20\ncomponent = 2\namplitude",
        "node = 1\ncomponent = 2\namplitude",
    );
    let e = Scene::from_toml(&text, fixture_dir().join("beam.toml"))
        .unwrap_err()
        .to_string();
    for w in ["forcing.node", "1", "beam.pch"] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
}

/// The normal row of the beam's single 3-D contact at node 20 with the contact keys `keys`
/// (`[model] mesh = "beam.inp"`), as a dense vector over the 48 dofs.
fn normal_of(keys: &str) -> Result<Vec<f64>, String> {
    let model = format!("{}\nmesh = \"beam.inp\"", MODELS[0].0);
    let text = scene_text(&model).replace(
        "[[contact.point]]\nnode = 20\ncomponent = 2\ngap = 1e-7",
        &format!("[[contact.point]]\nnode = 20\ngap = 1e-7\nfriction = 0.0\n{keys}"),
    );
    let scene =
        Scene::from_toml(&text, fixture_dir().join("beam.toml")).map_err(|e| e.to_string())?;
    let spec = scene.model.as_ref().unwrap();
    let row = spec.frictional_contacts[0].normal_row().unwrap();
    let mut v = vec![0.0; 48];
    for (&d, &c) in row.dofs().iter().zip(row.coefficients()) {
        v[d] += c;
    }
    Ok(v)
}

#[test]
fn a_radial_normal_is_the_hand_computed_direction_from_the_axis_to_the_node() {
    // Node 20 is at (40, 10, 10) (beam.inp); the axis along x through (0, 5, 5) leaves
    // (0, 5, 5) from the axis to the node: the normal (0, 1, 1) / sqrt 2.
    let radial =
        normal_of("normal = \"radial\"\naxis = [2.0, 0.0, 0.0]\naxis_origin = [0.0, 5.0, 5.0]")
            .unwrap();
    let dof = std::fs::read_to_string(fixture_dir().join("beam.dof")).unwrap();
    let row = |c: u8| {
        dof.lines()
            .position(|l| l.trim() == format!("20.{c}"))
            .unwrap()
    };
    let s = 0.5f64.sqrt();
    for (c, want) in [(1, 0.0), (2, s), (3, s)] {
        // The direction is a difference and a division of numbers exact in binary: the
        // rounding of 1/sqrt 2 alone, a few ulps.
        assert!((radial[row(c)] - want).abs() < 1e-15, "{c}: {radial:?}");
    }
    assert_eq!(radial.iter().filter(|v| **v != 0.0).count(), 2);
    let given = normal_of("normal = [0.0, 0.7071067811865476, 0.7071067811865476]").unwrap();
    for (a, b) in radial.iter().zip(&given) {
        assert!((a - b).abs() < 1e-15);
    }
    for (keys, words) in [
        (
            "normal = \"radial\"",
            &["contact.point.axis", "missing"][..],
        ),
        (
            "normal = \"radial\"\naxis = [1.0, 0.0]",
            &["contact.point.axis", "3 finite"],
        ),
        (
            "normal = \"outward\"",
            &["contact.point.normal", "\"radial\""],
        ),
        (
            "normal = \"radial\"\naxis = [1.0, 0.0, 0.0]\naxis_origin = [0.0, 10.0, 10.0]",
            &["contact.point.axis", "does not pass through the node"],
        ),
        (
            "normal = [0.0, 1.0, 0.0]\naxis = [1.0, 0.0, 0.0]",
            &["contact.point.axis", "only with"],
        ),
    ] {
        let e = normal_of(keys).unwrap_err();
        for w in words {
            assert!(e.contains(w), "`{w}` not in: {e}");
        }
    }
    let text = scene_text(MODELS[0].0).replace(
        "[[contact.point]]\nnode = 20\ncomponent = 2\ngap = 1e-7",
        "[[contact.point]]\nnode = 20\ngap = 1e-7\nfriction = 0.0\nnormal = \"radial\"\naxis = [1.0, 0.0, 0.0]",
    );
    let e = Scene::from_toml(&text, fixture_dir().join("beam.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("[model] mesh"), "{e}");
}
