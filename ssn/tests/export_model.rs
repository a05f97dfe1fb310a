//! `ssn export-model` and `[model]` scenes as users run them: the exported rod solves to the
//! same numbers as the rod scene, and a bad imported scene exits 2 naming the file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

#[path = "common/process.rs"]
mod process;

use process::ssn;

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

fn json(o: &Output) -> Value {
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssn-export-test-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn the_exported_rod_solves_to_the_rod_scenes_numbers() {
    let dir = temp_dir("rod");
    let scene = scenes_dir().join("paper_fig1_modified_mass.toml");
    let scene = scene.to_str().unwrap();
    let out = ssn(&["export-model", scene, dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    for file in ["M.mtx", "K.mtx", "D.mtx", "f.mtx", "scene.toml"] {
        assert!(dir.join(file).is_file(), "{file} missing");
    }
    let exported = dir.join("scene.toml");
    let a = ssn(&["solve", scene, "--json"]);
    let b = ssn(&["solve", exported.to_str().unwrap(), "--json"]);
    assert_eq!(b.status.code(), Some(0), "{b:?}");
    let (a, b) = (json(&a), json(&b));
    for field in [
        "omega",
        "omega_ratio",
        "iterations",
        "tip_max",
        "tip_min",
        "max_penetration",
        "contact_force_mean",
        "c",
    ] {
        assert_eq!(a[field], b[field], "{field}");
    }
    let check = ssn(&["scene-check", exported.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&check.stdout);
    assert!(
        check.status.success() && text.contains("20 dofs (1 with a zero mass diagonal)"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_imported_scene_exits_2_naming_the_file_and_the_key() {
    let dir = temp_dir("bad");
    std::fs::create_dir_all(&dir).unwrap();
    let beam = std::fs::read_to_string(scenes_dir().join("beam_tip_stop.toml")).unwrap();
    let matrices = scenes_dir().join("beam");
    let beam = beam.replace("beam/", &format!("{}/", matrices.display()));
    for (from, to, must_name) in [
        ("dof = 41", "dof = 42", "contact.point.dof"),
        ("beam/M.mtx", "beam/missing.mtx", "missing.mtx"),
        ("vector = ", "load = \"tip\"\nvector = ", "forcing.load"),
    ] {
        let path = dir.join("bad.toml");
        std::fs::write(&path, beam.replace(from, to)).unwrap();
        let out = ssn(&["solve", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{to}: {err}");
        assert!(err.contains(must_name), "{to}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_forced_matrix_free_solve_is_exported_by_its_scene_name_and_agrees() {
    let dir = temp_dir("krylov");
    std::fs::create_dir_all(&dir).unwrap();
    let rod = std::fs::read_to_string(scenes_dir().join("paper_fig1_modified_mass.toml")).unwrap();
    let krylov = dir.join("krylov.toml");
    let edited = rod.replace("[solver]", "[solver]\nlinear_solver = \"condensed-krylov\"");
    assert_ne!(edited, rod, "the scene has a [solver] section");
    std::fs::write(&krylov, edited).unwrap();
    let out = ssn(&[
        "export-model",
        krylov.to_str().unwrap(),
        dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let exported = dir.join("scene.toml");
    let text = std::fs::read_to_string(&exported).unwrap();
    assert!(
        text.contains("linear_solver = \"condensed-krylov\""),
        "{text}"
    );
    // The matrix-free path against the default (dense condensed) one on the rod scene: the
    // same iterations, and answers within the GMRES tolerance (1e-10 relative per step).
    let a = json(&ssn(&["solve", exported.to_str().unwrap(), "--json"]));
    let b = json(&ssn(&[
        "solve",
        scenes_dir()
            .join("paper_fig1_modified_mass.toml")
            .to_str()
            .unwrap(),
        "--json",
    ]));
    assert_eq!(a["converged"], Value::Bool(true));
    assert_eq!(a["iterations"], b["iterations"]);
    for field in ["tip_max", "tip_min", "contact_force_mean"] {
        let (x, y) = (a[field].as_f64().unwrap(), b[field].as_f64().unwrap());
        assert!(
            (x - y).abs() <= 1e-9 * (1.0 + y.abs()),
            "{field}: {x} vs {y}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_model_scene_too_large_for_the_memory_limit_is_refused_by_its_imported_size() {
    // The 100-contact disk needs about 23 MB (dense condensed system of 1,100 unknowns);
    // the placeholder rod of a [model] scene would have been estimated at well under 10 MB.
    let scene = scenes_dir().join("bladed_disk_casing.toml");
    let out = Command::new(SSN)
        .args(["solve", scene.to_str().unwrap()])
        .env("SSN_MEMORY_LIMIT", "10000000")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("10.0 MB") && err.contains("solver.harmonics"),
        "{err}"
    );
}
