//! CalculiX models: the fixture `fixtures/calculix_cantilever` holds the stiffness, mass
//! and dof files that CalculiX 2.20 wrote for a cantilever of 8 x 2 x 2 C3D8 elements
//! (`*FREQUENCY, SOLVER=MATRIXSTORAGE`), and the natural frequencies CalculiX itself
//! printed for the same mesh (`cantilever_modes.dat`). A `format = "calculix"` scene reads
//! them, its point load, contact and observed dof named by node and component.

use std::path::{Path, PathBuf};

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::rod::natural_frequencies;
use ssn::scene::Scene;

mod common;

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/calculix_cantilever")
}

/// The 0-based row of `node.component` in the fixture's `.dof` file, read from its lines.
fn dof_file_row(node: u64, component: u8) -> usize {
    let dof = std::fs::read_to_string(fixture().join("cantilever.dof")).unwrap();
    let wanted = format!("{node}.{component}");
    dof.lines().position(|l| l.trim() == wanted).unwrap()
}

fn error_of_edited(edit: impl Fn(String) -> String) -> String {
    common::error_of_edited_scene(&fixture().join("cantilever.toml"), edit)
}

#[test]
fn natural_frequencies_of_the_read_matrices_are_those_calculix_printed() {
    let scene = Scene::from_path(fixture().join("cantilever.toml")).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    assert_eq!(structure.model.dofs(), 216);
    let printed = common::calculix_eigenvalues(&fixture().join("cantilever_modes.dat"));
    assert_eq!(printed.len(), 10);
    let ours = natural_frequencies(&structure.model, printed.len()).unwrap();
    for (k, (w, lambda)) in ours.iter().zip(&printed).enumerate() {
        // CalculiX prints omega^2 with 7 significant digits: half a unit of the last digit
        // is at most 5.3e-8 relative for these values; 2e-7 leaves room for its own
        // eigensolver's convergence tolerance.
        let relative = (w * w - lambda).abs() / lambda;
        assert!(
            relative < 2e-7,
            "mode {}: {} vs {lambda}: {relative:e}",
            k + 1,
            w * w
        );
    }
    // The import's omega_1 is the same pencil's lowest frequency from a run that asked for
    // one mode: the same to the subspace iteration's tolerance.
    assert!((structure.omega_1 - ours[0]).abs() < 1e-10 * ours[0]);
}

#[test]
fn the_point_load_contact_and_observed_dof_by_node_are_the_dof_files_row() {
    let scene = Scene::from_path(fixture().join("cantilever.toml")).unwrap();
    let spec = scene.model.as_ref().unwrap();
    let row = dof_file_row(45, 2);
    assert_eq!(spec.load_dof, Some(row));
    assert_eq!(spec.observed_dof, Some(row));
    assert_eq!(spec.contacts[0].row.single(), Some((row, 1.0)));
    let structure = build_imported(spec).unwrap();
    let mut unit = vec![0.0; 216];
    unit[row] = 1.0;
    assert_eq!(structure.model.load.as_cosine(), Some(unit));
}

#[test]
fn a_node_outside_the_map_and_a_calculix_model_without_its_dof_file_are_refused() {
    // Node 1 is on the clamped face: CalculiX wrote no row for it.
    let e = error_of_edited(|t| t.replacen("node = 45", "node = 1", 1));
    for w in [
        "forcing.node",
        "1",
        "a node of the dof map",
        "cantilever.dof",
    ] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    let e = error_of_edited(|t| t.replace("component = 2\namplitude", "component = 7\namplitude"));
    assert!(
        e.contains("forcing.component") && e.contains("1, 2, 3"),
        "{e}"
    );
    let e = error_of_edited(|t| t.replace("dof_map = \"cantilever.dof\"\n", ""));
    assert!(
        e.contains("model.dof_map") && e.contains(".dof file"),
        "{e}"
    );
    let e = error_of_edited(|t| {
        t.replace(
            "node = 45\ncomponent = 2\namplitude",
            "node = 45\ncomponent = 2\nvector = \"f.mtx\"\namplitude",
        )
    });
    assert!(
        e.contains("forcing.node") && e.contains("together with `vector`"),
        "{e}"
    );
    let e = error_of_edited(|t| t.replace("format = \"calculix\"", "format = \"abaqus\""));
    assert!(e.contains("abaqus") && e.contains("calculix"), "{e}");
}

#[test]
fn a_defect_of_a_calculix_file_names_the_file_and_the_line() {
    let dir = std::env::temp_dir().join(format!("ssn-calculix-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["cantilever.toml", "cantilever.mas", "cantilever.dof"] {
        std::fs::copy(fixture().join(f), dir.join(f)).unwrap();
    }
    let sti = std::fs::read_to_string(fixture().join("cantilever.sti")).unwrap();
    let mut lines: Vec<&str> = sti.lines().collect();
    lines[2] = "3 217 1.0";
    std::fs::write(dir.join("cantilever.sti"), lines.join("\n")).unwrap();
    let scene = Scene::from_path(dir.join("cantilever.toml")).unwrap();
    let e = build_imported(scene.model.as_ref().unwrap())
        .unwrap_err()
        .to_string();
    for w in ["cantilever.sti", "line 3", "column `217`", "1..=216"] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
