//! Dofs named by node and component through a `[model] dof_map`: the fixture
//! `fixtures/node_lattice` is a 12-dof spring lattice whose rows are in a shuffled node and
//! component order (`nodes.dof`); `by_node.toml` names its contacts (one with friction on a
//! tangent row), friction point and observed dof by node and component, `by_dof.toml` the same by matrix row, written by hand
//! from the map's lines. A wrong map (or a wrong resolution) gives other rows, hence other
//! answers.

use std::path::{Path, PathBuf};

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::Structure;
use semismooth_contact::solve::Solution;
use ssn::scene::Scene;

mod common;

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/node_lattice")
}

fn solve(scene: &Scene, structure: &Structure) -> Solution {
    let omega = scene.omega(structure.omega_1);
    let s = semismooth_contact::solve(structure, omega, &scene.solver, None).unwrap();
    assert!(s.converged(), "{}", s.termination);
    s
}

/// The message of the scene `by_node.toml` with `edit` applied (its directory kept), from
/// reading the scene or else from importing its files.
fn error_of_edited(edit: impl Fn(String) -> String) -> String {
    common::error_of_edited_scene(&fixture().join("by_node.toml"), edit)
}

#[test]
fn contacts_and_observed_dof_by_node_give_the_dof_scenes_answer_bit_for_bit() {
    let by_node = Scene::from_path(fixture().join("by_node.toml")).unwrap();
    let by_dof = Scene::from_path(fixture().join("by_dof.toml")).unwrap();
    let (a, b) = (
        by_node.model.as_ref().unwrap(),
        by_dof.model.as_ref().unwrap(),
    );
    assert_eq!(a.contacts, b.contacts);
    assert_eq!(a.friction, b.friction);
    assert_eq!(a.observed_dof, Some(0));
    assert_eq!(a.observed_dof, b.observed_dof);
    let (sa, sb) = (build_imported(a).unwrap(), build_imported(b).unwrap());
    let (ra, rb) = (solve(&by_node, &sa), solve(&by_dof, &sb));
    // The same rows of the same matrices: the same arithmetic, so equal to the last bit.
    assert_eq!(ra.observed, rb.observed);
    assert_eq!(ra.state, rb.state);
    assert_eq!(ra.contact_forces, rb.contact_forces);
    assert_eq!(ra.iterations, rb.iterations);
    // The contact on node 9, x closes in the period (the case exercises the contact law).
    assert!(ra.contact_forces[0].iter().any(|&f| f < 0.0));
}

#[test]
fn an_unknown_node_or_component_is_refused_with_the_map_file_and_the_value() {
    let cases: [(&str, &str, &[&str]); 6] = [
        (
            "node = 9\ncomponent = 1",
            "node = 5\ncomponent = 1",
            &[
                "by_node.toml",
                "`contact.point.node` = 5",
                "nodes.dof",
                "4..=30",
            ],
        ),
        (
            "node = 9\ncomponent = 1",
            "node = 9\ncomponent = 4",
            &[
                "`contact.point.component` = 4",
                "nodes.dof",
                "node 9: 1, 2, 3",
            ],
        ),
        (
            "node = 30\ncomponent = 2",
            "node = 31\ncomponent = 2",
            &["`output.node` = 31", "nodes.dof"],
        ),
        (
            "components = [3, 3]",
            "components = [3, 7]",
            &["`contact.point.components` = 7", "nodes.dof"],
        ),
        (
            "node = 4\ncomponent = 2",
            "node = 4\ncomponent = 2\ndof = 6",
            &["`friction.point.node`", "together with `dof`", "either"],
        ),
        (
            "dof_map = \"nodes.dof\"\n",
            "",
            &[
                "`contact.point.node`",
                "without [model] dof_map",
                "dof_map = \"FILE\"",
            ],
        ),
    ];
    for (from, to, words) in cases {
        let message = error_of_edited(|t| t.replacen(from, to, 1));
        for w in words {
            assert!(message.contains(w), "{to}: `{w}` not in: {message}");
        }
    }
}

#[test]
fn a_malformed_or_short_dof_map_is_refused_with_its_file_and_line() {
    let dir = std::env::temp_dir().join(format!("ssn-dof-map-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for entry in std::fs::read_dir(fixture()).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), dir.join(entry.file_name())).unwrap();
    }
    let map = std::fs::read_to_string(dir.join("nodes.dof")).unwrap();
    let cases: [(String, &[&str]); 3] = [
        (
            map.replacen("4.1\n", "4.x\n", 1),
            &[
                "by_node.toml",
                "`model.dof_map`",
                "nodes.dof: line 3",
                "`4.x`",
                "component",
            ],
        ),
        (
            map.replacen("9.2\n", "9.3\n", 1),
            &["nodes.dof: line 4", "node 9 component 3 again", "line 2"],
        ),
        (
            map.lines().take(11).map(|l| format!("{l}\n")).collect(),
            &["nodes.dof", "the dof map has 11 rows", "allowed 12"],
        ),
    ];
    for (text, words) in cases {
        std::fs::write(dir.join("nodes.dof"), &text).unwrap();
        let path = dir.join("by_node.toml");
        let message = match Scene::from_path(&path) {
            Err(e) => e.to_string(),
            Ok(scene) => match build_imported(scene.model.as_ref().unwrap()) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("accepted the map:\n{text}"),
            },
        };
        for w in words {
            assert!(message.contains(w), "`{w}` not in: {message}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scene_check_names_the_rows_of_a_node_scene_with_their_node_and_component() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ssn"))
        .arg("scene-check")
        .arg(fixture().join("by_node.toml"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    // Rows 7 and 1 are the lines `9.1` and `30.2` of nodes.dof.
    for w in [
        "nodes.dof: nodes 4..=30",
        "dof 7 (node 9, component 1), gap 0.01",
        "observed dof      1 (node 30, component 2)",
    ] {
        assert!(text.contains(w), "`{w}` not in:\n{text}");
    }
}
