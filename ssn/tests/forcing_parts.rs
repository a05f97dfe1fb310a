//! `[forcing]` loads beyond the cosine `vector` of a `[model]` scene: `vector_sin`,
//! `static` and `[[forcing.harmonic]]` reach the model's load with the amplitude applied
//! (except to `static`), and bad ones are refused naming the key, the value and what is
//! allowed.

use std::path::{Path, PathBuf};

use ssn::cli::load;
use ssn::scene::Scene;

/// A fresh directory for one test.
fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssn-forcing-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// An `n x 1` Matrix Market vector.
fn vector_text(v: &[f64]) -> String {
    let mut t = format!("%%MatrixMarket matrix array real general\n{} 1\n", v.len());
    for x in v {
        t.push_str(&format!("{x:e}\n"));
    }
    t
}

/// A 3-dof chain scene with `forcing` appended to its `[forcing]` section (amplitude 0.5,
/// 3 harmonics), and the load files it may name.
fn scene(dir: &Path, forcing: &str) -> PathBuf {
    let files = [
        (
            "K.mtx",
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n3 3 1\n"
                .to_string(),
        ),
        (
            "M.mtx",
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n1 1 1\n2 2 1\n3 3 1\n"
                .to_string(),
        ),
        ("f.mtx", vector_text(&[0.0, 0.0, 1.0])),
        ("fs.mtx", vector_text(&[1.0, 0.0, 0.0])),
        ("f0.mtx", vector_text(&[0.0, 2.0, 0.0])),
        ("c2.mtx", vector_text(&[0.5, 0.0, 0.0])),
        ("s2.mtx", vector_text(&[0.0, 0.0, -1.0])),
        ("short.mtx", vector_text(&[1.0, 2.0])),
    ];
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let text = format!(
        "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\nzeta = 0.02\n\
         [forcing]\nvector = \"f.mtx\"\namplitude = 0.5\n{forcing}\n[solver]\nharmonics = 3\n"
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A sine part, a static load and harmonic 2's cosine and sine parts.
const EVERY_PART: &str = "vector_sin = \"fs.mtx\"\nstatic = \"f0.mtx\"\n\
     [[forcing.harmonic]]\norder = 2\ncos = \"c2.mtx\"\nsin = \"s2.mtx\"";

#[test]
fn sine_static_and_harmonic_loads_reach_the_model_scaled_by_the_amplitude_but_static() {
    let dir = temp_dir("parts");
    let path = scene(&dir, EVERY_PART);
    let loaded = load(&path).unwrap();
    let f = &loaded.structure.model.load;
    // Exact: each part is its file times 0.5 (or 1 for `static`), a single product.
    assert_eq!(f.harmonic(0), Some((&[0.0, 2.0, 0.0][..], &[0.0; 3][..])));
    assert_eq!(
        f.harmonic(1),
        Some((&[0.0, 0.0, 0.5][..], &[0.5, 0.0, 0.0][..]))
    );
    assert_eq!(
        f.harmonic(2),
        Some((&[0.25, 0.0, 0.0][..], &[0.0, 0.0, -0.5][..]))
    );
    assert_eq!(f.highest_harmonic(), 2);
    // The scene solves: the linear HB response to the whole load (no contact).
    let settings = &loaded.scene.solver;
    let s = semismooth_contact::solve(&loaded.structure, loaded.omega, settings, None).unwrap();
    assert!(s.converged(), "{}", s.termination);
}

#[test]
fn bad_load_parts_are_refused_with_the_key_the_value_and_what_is_allowed() {
    let dir = temp_dir("bad");
    for (forcing, expected) in [
        (
            "[[forcing.harmonic]]\norder = 0\ncos = \"c2.mtx\"",
            ["forcing.harmonic.order", "0", "1..=3"],
        ),
        (
            "[[forcing.harmonic]]\norder = 4\ncos = \"c2.mtx\"",
            ["forcing.harmonic.order", "4", "1..=3"],
        ),
        (
            "[[forcing.harmonic]]\norder = 2",
            ["forcing.harmonic", "order = 2", "`cos` and/or `sin`"],
        ),
    ] {
        let error = Scene::from_path(scene(&dir, forcing))
            .unwrap_err()
            .to_string();
        for part in expected {
            assert!(error.contains(part), "{error} lacks {part}");
        }
    }
    let error = match load(&scene(&dir, "vector_sin = \"short.mtx\"")) {
        Ok(_) => panic!("a 2 x 1 sine part on 3 dofs was accepted"),
        Err(e) => e.to_string(),
    };
    for part in ["short.mtx", "forcing.vector_sin", "2 x 1", "allowed 3 x 1"] {
        assert!(error.contains(part), "{error} lacks {part}");
    }
    let rod = dir.join("rod.toml");
    std::fs::write(
        &rod,
        "[rod]\nelements = 4\n[forcing]\namplitude = 0.1\nstatic = \"f0.mtx\"\n",
    )
    .unwrap();
    let error = Scene::from_path(&rod).unwrap_err().to_string();
    assert!(error.contains("forcing.static") && error.contains("[model] scenes"));
}

#[test]
fn an_exported_scene_keeps_every_load_part_bit_for_bit() {
    let dir = temp_dir("export");
    let path = scene(&dir, EVERY_PART);
    let loaded = load(&path).unwrap();
    let out = dir.join("exported");
    std::fs::create_dir_all(&out).unwrap();
    for (name, text) in ssn::import::export_files(&loaded.scene, &loaded.structure) {
        std::fs::write(out.join(name), text).unwrap();
    }
    let exported = load(&out.join(ssn::import::EXPORTED_SCENE)).unwrap();
    // The same load: every harmonic's cosine and sine parts equal to the last bit.
    assert_eq!(exported.structure.model.load, loaded.structure.model.load);
    // Hence the same solution.
    let solve = |l: &ssn::cli::Loaded| {
        semismooth_contact::solve(&l.structure, l.omega, &l.scene.solver, None).unwrap()
    };
    assert_eq!(solve(&exported).state, solve(&loaded).state);
}
