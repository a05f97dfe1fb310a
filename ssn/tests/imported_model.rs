//! Imported structures: the rod written as Matrix Market files and a `[model]` scene, read
//! back, gives the built-in rod's answer to round-off (consistent and modified mass, every
//! method family); every defect of the files is an error naming the file and the entry.

use std::path::{Path, PathBuf};

use semismooth_contact::matrix_market::{build_imported, ImportError};
use semismooth_contact::model::Structure;
use semismooth_contact::rod::build_rod;
use semismooth_contact::solve::Solution;
use ssn::import::{export_files, EXPORTED_SCENE};
use ssn::scene::{Method, Scene};

mod common;

/// A fresh directory for one test.
fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssn-import-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

/// The shipped rod scene `name` and its export read back: both scenes and structures.
fn round_trip(name: &str, tag: &str) -> (Scene, Structure, Scene, Structure) {
    let scene = Scene::from_path(common::scenes_dir().join(name)).unwrap();
    let rod = build_rod(&scene.rod).unwrap().structure;
    let dir = temp_dir(tag);
    for (file, text) in export_files(&scene, &rod) {
        write(&dir, &file, &text);
    }
    let imported_scene = Scene::from_path(dir.join(EXPORTED_SCENE)).unwrap();
    let spec = imported_scene.model.as_ref().expect("a [model] scene");
    let imported = build_imported(spec).unwrap();
    (scene, rod, imported_scene, imported)
}

fn solve(structure: &Structure, scene: &Scene, method: Method) -> Solution {
    let mut settings = scene.solver.clone();
    settings.method = method;
    if method == Method::March {
        settings.steps_per_period = 256;
    }
    let omega = scene.omega(structure.omega_1);
    let s = semismooth_contact::solve(structure, omega, &settings, None).unwrap();
    assert!(s.converged(), "{method:?}: {}", s.termination);
    s
}

#[test]
fn exported_rod_reimported_gives_the_built_in_answer_to_round_off() {
    for (name, methods) in [
        (
            "paper_fig1_modified_mass.toml",
            &[
                Method::SsnHb,
                Method::PenaltyHb,
                Method::LcpLemke,
                Method::March,
            ][..],
        ),
        ("paper_fig1.toml", &[Method::SsnHb, Method::March][..]),
    ] {
        let (scene, rod, imported_scene, imported) = round_trip(name, name);
        assert_eq!(imported.model.dofs(), rod.model.dofs());
        assert_eq!(imported.observed_dof, rod.observed_dof);
        // The same frequency unit: the same matrices give the same omega_1.
        assert!(
            (imported.omega_1 - rod.omega_1).abs() <= 1e-14 * rod.omega_1,
            "{name}: omega_1 {} vs {}",
            imported.omega_1,
            rod.omega_1
        );
        assert_eq!(imported_scene.solver, scene.solver);
        for &method in methods {
            let a = solve(&rod, &scene, method);
            let b = solve(&imported, &imported_scene, method);
            let scale = common::max_abs(&a.observed).max(1e-300);
            let diff = common::max_abs_diff(&a.observed, &b.observed);
            assert!(
                diff <= 1e-12 * scale,
                "{name} {method:?}: tip differs by {diff:e} (scale {scale})"
            );
            let fa = a.stats.mean_contact_force;
            let fb = b.stats.mean_contact_force;
            assert!(
                (fa - fb).abs() <= 1e-12 * fa.abs().max(1e-300),
                "{name} {method:?}: mean force {fa} vs {fb}"
            );
            assert_eq!(a.iterations, b.iterations, "{name} {method:?}");
        }
    }
}

/// Matrix Market text of a dense symmetric `n x n` matrix given by rows.
fn dense_text(rows: &[&[f64]]) -> String {
    let n = rows.len();
    let mut t = format!("%%MatrixMarket matrix array real general\n{n} {n}\n");
    for j in 0..n {
        for row in rows {
            t.push_str(&format!("{}\n", row[j]));
        }
    }
    t
}

/// A valid 3-dof `[model]` scene in `dir` (a spring chain with a stop on the last dof), with
/// `edit` applied to the scene text.
fn chain_scene(dir: &Path, edit: impl Fn(String) -> String) -> PathBuf {
    write(
        dir,
        "K.mtx",
        "%%MatrixMarket matrix coordinate real symmetric\n% a chain\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n3 3 1\n",
    );
    write(
        dir,
        "M.mtx",
        &dense_text(&[&[1.0, 0.0, 0.0], &[0.0, 1.0, 0.0], &[0.0, 0.0, 0.0]]),
    );
    write(
        dir,
        "f.mtx",
        "%%MatrixMarket matrix coordinate real general\n3 1 1\n3 1 1.0\n",
    );
    let scene = "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\nzeta = 0.02\n\
                 [forcing]\nvector = \"f.mtx\"\namplitude = 0.1\n\
                 [[contact.point]]\ndof = 3\ngap = 0.05\n";
    let path = dir.join("chain.toml");
    write(dir, "chain.toml", &edit(scene.to_string()));
    path
}

fn import_error(path: &Path) -> String {
    let scene = match Scene::from_path(path) {
        Ok(s) => s,
        Err(e) => return e.to_string(),
    };
    match build_imported(scene.model.as_ref().unwrap()) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_small_imported_chain_matches_its_closed_form_and_massless_dofs_are_allowed() {
    let dir = temp_dir("chain");
    let path = chain_scene(&dir, |s| s);
    let scene = Scene::from_path(&path).unwrap();
    let s = build_imported(scene.model.as_ref().unwrap()).unwrap();
    // Dof 3 is massless: condensing it (K33 = 1) leaves K' = [[2, -1], [-1, 1]] on unit
    // masses, omega_1^2 = (3 - sqrt 5) / 2.
    let exact = ((3.0 - 5f64.sqrt()) / 2.0).sqrt();
    assert!(
        (s.omega_1 - exact).abs() < 1e-13,
        "{} vs {exact}",
        s.omega_1
    );
    assert_eq!(s.observed_dof, 2, "default: the first contact dof");
    assert_eq!(s.model.load.as_cosine(), Some(vec![0.0, 0.0, 0.1]));
    assert!((scene.omega(s.omega_1) - s.omega_1).abs() < 1e-15);
    // The linear answer (no contact reached with a wide gap) against the exact
    // frequency-domain solve.
    let path = chain_scene(&dir, |t| t.replace("gap = 0.05", "gap = 1e6"));
    let scene = Scene::from_path(&path).unwrap();
    let wide = build_imported(scene.model.as_ref().unwrap()).unwrap();
    let omega = scene.omega(wide.omega_1);
    let sol = semismooth_contact::solve(&wide, omega, &scene.solver, None).unwrap();
    assert!(sol.converged());
    let (diff, z) = common::linear_history_error(&wide.model, 2, &sol);
    assert!(diff < 1e-10 * z, "{diff:e} against |z| = {z}");
}

#[test]
fn defects_of_the_files_are_named_with_file_entry_and_allowed_values() {
    let dir = temp_dir("defects");
    let coordinate = |shape: &str, entries: &str| {
        format!("%%MatrixMarket matrix coordinate real general\n{shape}\n{entries}")
    };
    let cases: Vec<(&str, String, &[&str])> = vec![
        (
            "K.mtx",
            coordinate("3 3 2", "1 1 2\n2 x 1\n"),
            &["K.mtx", "line 4", "`2 x 1`"],
        ),
        (
            "K.mtx",
            coordinate("3 3 4", "1 1 2\n2 2 2\n3 3 1\n2 1 -1\n"),
            &["K.mtx", "not symmetric", "(2, 1)", "allowed"],
        ),
        (
            "M.mtx",
            dense_text(&[&[1.0, 0.0], &[0.0, 1.0]]),
            &["M.mtx", "2 x 2", "3 x 3"],
        ),
        (
            "M.mtx",
            dense_text(&[&[1.0, 0.0, 0.0], &[0.0, -1.0, 0.0], &[0.0, 0.0, 0.0]]),
            &["M.mtx", "(2, 2)", ">= 0"],
        ),
        (
            "K.mtx",
            coordinate("3 3 5", "1 1 1\n2 1 -1\n1 2 -1\n2 2 1\n3 3 1\n"),
            &["K.mtx", "singular"],
        ),
        (
            "f.mtx",
            coordinate("4 1 1", "4 1 1.0\n"),
            &["f.mtx", "4 x 1", "3 x 1"],
        ),
        (
            "K.mtx",
            coordinate("3 3 1", "1 1 NaN\n"),
            &["K.mtx", "(1, 1)", "finite"],
        ),
    ];
    for (i, (file, text, expected)) in cases.iter().enumerate() {
        let path = chain_scene(&dir, |s| s);
        write(&dir, file, text);
        let message = import_error(&path);
        for e in *expected {
            assert!(message.contains(e), "case {i}: `{e}` not in: {message}");
        }
    }
    let scene_cases: [(&str, &str, &[&str]); 5] = [
        (
            "dof = 3",
            "dof = 4",
            &["chain.toml", "contact.point.dof", "= 4", "1..=3"],
        ),
        (
            "dof = 3",
            "dof = 0",
            &["chain.toml", "contact.point.dof", "0"],
        ),
        (
            "gap = 0.05",
            "gap = 0.05\ndirection = 2",
            &["contact.point.direction", "2", "-1"],
        ),
        (
            "vector = \"f.mtx\"",
            "vector = \"missing.mtx\"",
            &["missing.mtx"],
        ),
        (
            "[damping]\nzeta = 0.02\n",
            "[output]\ndof = 7\n",
            &["output.dof", "= 7", "1..=3"],
        ),
    ];
    for (from, to, expected) in scene_cases {
        let path = chain_scene(&dir, |s| s.replace(from, to));
        let message = import_error(&path);
        for e in expected {
            assert!(message.contains(e), "{to}: `{e}` not in: {message}");
        }
    }
}

#[test]
fn import_error_is_a_typed_value() {
    let dir = temp_dir("typed");
    let path = chain_scene(&dir, |s| s.replace("dof = 3", "dof = 9"));
    let scene = Scene::from_path(&path).unwrap();
    assert!(matches!(
        build_imported(scene.model.as_ref().unwrap()),
        Err(ImportError::DofOutOfRange {
            key: "contact.point.dof",
            value: 9,
            dofs: 3,
            ..
        })
    ));
}

#[test]
fn scene_sections_of_an_imported_model_are_checked_by_key() {
    let base = "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[forcing]\nvector = \"f.mtx\"\n\
                amplitude = 1.0\n[[contact.point]]\ndof = 1\ngap = 0.1\n";
    let cases: [(&str, &[&str]); 6] = [
        ("[rod]\nelements = 3\n", &["model", "[rod]"]),
        ("[damping]\nzeta = 0.1\n", &[]),
        ("[model]\n", &["model"]),
        ("[output]\ndof = 0\n", &["output.dof", "0"]),
        (
            "[[contact.point]]\nnode = 2\ngap = 0.1\n",
            &["contact.point.node", "dof"],
        ),
        (
            "[[contact.point]]\ndof = 1\ngap = 0.2\ndirection = 1\n",
            &["contact.point.dof", "direction"],
        ),
    ];
    for (extra, expected) in cases {
        let text = format!("{base}{extra}");
        let result = Scene::from_toml(&text, "m.toml");
        if expected.is_empty() {
            assert!(result.is_ok(), "{extra}: {result:?}");
            continue;
        }
        let message = result.unwrap_err().to_string();
        for e in expected {
            assert!(message.contains(e), "{extra}: `{e}` not in: {message}");
        }
    }
    let without = Scene::from_toml("[forcing]\namplitude = 1.0\n", "m.toml").unwrap_err();
    assert!(without.to_string().contains("[model]"), "{without}");
    let damping_twice =
        base.replace("K.mtx\"\n", "K.mtx\"\ndamping = \"D.mtx\"\n") + "[damping]\nzeta = 0.1\n";
    let message = Scene::from_toml(&damping_twice, "m.toml")
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("damping") && message.contains("either"),
        "{message}"
    );
}
