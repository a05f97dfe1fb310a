//! Scenes: every shipped scene parses; bad input gives an error naming the file, the key and
//! what is allowed.

use semismooth_contact::rod::{build_rod, MassModel};
use ssn::scene::{Method, Scene, SceneError};

const BASE: &str = r#"
[rod]
elements = 20
[damping]
zeta = 0.01
[forcing]
amplitude = 0.04
omega_ratio = 1.0
[contact]
gap = 0.5
"#;

fn scenes_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

fn error_of(text: &str) -> String {
    Scene::from_toml(text, "bad.toml")
        .expect_err("scene should be rejected")
        .to_string()
}

#[test]
fn every_shipped_scene_parses_and_builds_a_rod() {
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let scene = Scene::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
        build_rod(&scene.rod).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        count += 1;
    }
    assert!(count >= 6, "expected the shipped scenes, found {count}");
}

#[test]
fn the_modified_mass_scene_declares_modified_mass_and_ssn_hb() {
    let scene = Scene::from_path(scenes_dir().join("paper_fig1_modified_mass.toml")).unwrap();
    assert_eq!(scene.rod.mass, MassModel::Modified);
    assert_eq!(scene.solver.method, Method::SsnHb);
}

#[test]
fn malformed_toml_names_the_file_and_line() {
    let err = error_of("[rod\nelements = 20");
    assert!(
        err.starts_with("bad.toml:") && err.contains("line 1"),
        "{err}"
    );
}

#[test]
fn missing_required_keys_are_named() {
    let err = error_of("[rod]\n[forcing]\namplitude = 1.0\n");
    assert!(err.contains("elements"), "{err}");
    let err = error_of("[forcing]\namplitude = 1.0\n");
    assert!(err.contains("rod"), "{err}");
    let err = error_of("[rod]\nelements = 3\n");
    assert!(err.contains("forcing"), "{err}");
}

#[test]
fn unknown_keys_and_sections_are_named() {
    let err = error_of(&BASE.replace("[contact]", "[contact]\nstiffness = 3"));
    assert!(err.contains("stiffness"), "{err}");
    let err = error_of(&format!("{BASE}\n[thermal]\nconductivity = 0.3\n"));
    assert!(err.contains("thermal"), "{err}");
    let err = error_of(&format!("{BASE}\n[friction]\nmu = 0.3\n"));
    assert!(err.contains("mu"), "{err}");
}

#[test]
fn wrong_types_are_named() {
    let err = error_of(&BASE.replace("elements = 20", "elements = \"twenty\""));
    assert!(err.contains("elements") || err.contains("integer"), "{err}");
    let err = error_of(&BASE.replace("gap = 0.5", "gap = true"));
    assert!(err.contains("gap") || err.contains("float"), "{err}");
}

#[test]
fn unknown_enum_values_list_the_allowed_ones() {
    let err = error_of(&format!("{BASE}\n[solver]\nmethod = \"newton\"\n"));
    assert!(err.contains("ssn-hb") && err.contains("lcp-lemke"), "{err}");
    let err = error_of(&BASE.replace("elements = 20", "elements = 20\nmass = \"heavy\""));
    assert!(err.contains("modified"), "{err}");
}

#[test]
fn zero_and_negative_sizes_are_rejected_with_the_allowed_range() {
    for (from, to, key) in [
        ("elements = 20", "elements = 0", "rod.elements"),
        ("elements = 20", "elements = -3", "rod.elements"),
        (
            "elements = 20",
            "elements = 20\nlength = -1.0",
            "rod.length",
        ),
        ("zeta = 0.01", "zeta = -0.01", "damping.zeta"),
        (
            "omega_ratio = 1.0",
            "omega_ratio = 0.0",
            "forcing.omega_ratio",
        ),
    ] {
        let err = error_of(&BASE.replace(from, to));
        assert!(err.contains(key) && err.contains("allowed"), "{err}");
    }
}

#[test]
fn nan_and_infinite_values_are_rejected() {
    for (from, to, key) in [
        ("gap = 0.5", "gap = nan", "contact.gap"),
        ("amplitude = 0.04", "amplitude = inf", "forcing.amplitude"),
        ("zeta = 0.01", "zeta = -inf", "damping.zeta"),
    ] {
        let err = error_of(&BASE.replace(from, to));
        assert!(err.contains(key) && err.contains("finite"), "{err}");
    }
}

#[test]
fn zero_harmonics_and_too_few_samples_are_rejected() {
    let err = error_of(&format!("{BASE}\n[solver]\nharmonics = 0\n"));
    assert!(
        err.contains("solver.harmonics") && err.contains("1..="),
        "{err}"
    );
    let err = error_of(&format!(
        "{BASE}\n[solver]\nharmonics = 10\ntime_samples = 20\n"
    ));
    assert!(
        err.contains("solver.time_samples") && err.contains("> 2 * harmonics"),
        "{err}"
    );
}

#[test]
fn contact_node_out_of_range_is_rejected() {
    let err = error_of(&BASE.replace("gap = 0.5", "gap = 0.5\nnode = 21"));
    assert!(
        err.contains("contact.node") && err.contains("1..=20"),
        "{err}"
    );
    let err = error_of(&BASE.replace(
        "[contact]\ngap = 0.5",
        "[[contact.point]]\nnode = 0\ngap = 0.5",
    ));
    assert!(err.contains("contact.point.node"), "{err}");
}

#[test]
fn conflicting_keys_are_rejected() {
    let err = error_of(&BASE.replace("omega_ratio = 1.0", "omega_ratio = 1.0\nomega = 1.5"));
    assert!(err.contains("forcing.omega"), "{err}");
    let err = error_of(&BASE.replace("zeta = 0.01", "zeta = 0.01\nbeta = 0.1"));
    assert!(err.contains("damping"), "{err}");
}

#[test]
fn unreadable_scene_file_is_an_io_error_naming_it() {
    let err = Scene::from_path("/nonexistent/scene.toml").unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/scene.toml"));
}

#[test]
fn sections_not_declared_are_not_simulated() {
    let scene = Scene::from_path(scenes_dir().join("linear_no_contact.toml")).unwrap();
    assert!(scene.rod.contacts.is_empty());
    let undamped = Scene::from_toml(&BASE.replace("[damping]\nzeta = 0.01", ""), "x").unwrap();
    let rod = build_rod(&undamped.rod).unwrap();
    assert!(rod.model.damping.is_none());
}

#[test]
fn damping_model_key_selects_and_checks_the_model() {
    use semismooth_contact::rod::DampingSpec;
    for (damping, expected) in [
        (
            "model = \"stiffness-proportional\"\nzeta = 0.02",
            DampingSpec::StiffnessProportional { zeta: 0.02 },
        ),
        (
            "model = \"rayleigh\"\nalpha = 0.1\nbeta = 0.001",
            DampingSpec::Rayleigh {
                alpha: 0.1,
                beta: 0.001,
            },
        ),
    ] {
        let scene = Scene::from_toml(&BASE.replace("zeta = 0.01", damping), "x").unwrap();
        assert_eq!(scene.rod.damping, Some(expected));
    }
    for (damping, needles) in [
        (
            "model = \"rayleigh\"\nzeta = 0.01",
            ["damping.zeta", "rayleigh"],
        ),
        (
            "model = \"stiffness-proportional\"",
            ["damping.zeta", "missing"],
        ),
        (
            "model = \"viscous\"",
            ["rayleigh", "stiffness-proportional"],
        ),
    ] {
        let err = error_of(&BASE.replace("zeta = 0.01", damping));
        assert!(needles.iter().all(|n| err.contains(n)), "{err}");
    }
}
