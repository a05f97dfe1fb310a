//! `ssn modes SCENE`: the backbone of the shipped rod's first nonlinear mode, its JSON
//! document against the linear mode computed independently, and its input errors.

#[path = "common/process.rs"]
mod process;

use process::{json_success, ssn};
use semismooth_contact::rod::{build_rod, natural_frequencies};
use ssn::scene::Scene;

/// The shipped scenes, `scenes/` at the root of the repository.
fn scenes_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

#[test]
fn rod_backbone_starts_at_the_linear_mode_and_stiffens_once_the_stop_is_reached() {
    let path = scenes_dir().join("paper_rod_modes.toml");
    let scene = Scene::from_path(&path).unwrap();
    let rod = build_rod(&scene.rod).unwrap();
    let omega_1 = natural_frequencies(&rod.model, 1).unwrap()[0];
    let json = json_success(&ssn(&["modes", path.to_str().unwrap(), "--json"]));
    assert_eq!(json["converged"], true, "{json}");
    let points = json["points"].as_array().unwrap();
    assert!(points.len() >= 10, "{}", points.len());
    for p in points {
        for field in [
            "amplitude",
            "energy",
            "omega",
            "damping_ratio",
            "modal_damping",
        ] {
            assert!(
                p[field].as_f64().is_some_and(f64::is_finite),
                "{field}: {p}"
            );
        }
        assert_eq!(p["contacts"].as_array().unwrap().len(), 1, "{p}");
    }
    let first = &points[0];
    // Open at amplitude 0.05 < gap 0.5: the linear mode, to the eigensolver's round-off
    // (subspace iteration stops at 1e-13 relative change).
    let omega = first["omega"].as_f64().unwrap();
    assert!(
        (omega - omega_1).abs() < 1e-11 * omega_1,
        "{omega} {omega_1}"
    );
    // The scene's zeta = 0.01 is the damping ratio of mode 1.
    let zeta = first["damping_ratio"].as_f64().unwrap();
    assert!((zeta - 0.01).abs() < 1e-12, "{zeta}");
    assert_eq!(first["contacts"][0]["force_mean"].as_f64(), Some(0.0));
    // At amplitude 1.5 (three times the gap) the stop stiffens the rod: the frequency rose
    // and the contact pushes back (force <= 0) on average.
    let last = points.last().unwrap();
    assert_eq!(last["amplitude"].as_f64(), Some(1.5));
    assert!(last["omega"].as_f64().unwrap() > 1.1 * omega_1, "{last}");
    assert!(
        last["contacts"][0]["force_mean"].as_f64().unwrap() < 0.0,
        "{last}"
    );
}

#[test]
fn a_scene_without_modes_section_is_refused_naming_the_section() {
    let path = scenes_dir().join("paper_fig1_modified_mass.toml");
    let out = ssn(&["modes", path.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("[modes]") && err.contains("amplitude_from"),
        "{err}"
    );
}

#[test]
fn equal_amplitudes_are_refused_naming_the_key() {
    let path = scenes_dir().join("paper_rod_modes.toml");
    let out = ssn(&[
        "modes",
        path.to_str().unwrap(),
        "--set",
        "modes.amplitude_to=0.05",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("modes.amplitude_to"), "{err}");
}

#[test]
fn an_energy_range_gives_the_amplitude_backbone_between_the_same_energies() {
    let path = scenes_dir().join("paper_rod_modes.toml");
    let by_amplitude = json_success(&ssn(&["modes", path.to_str().unwrap(), "--json"]));
    let points = by_amplitude["points"].as_array().unwrap();
    let energy = |p: &serde_json::Value| p["energy"].as_f64().unwrap();
    let (e_from, e_to) = (energy(&points[0]), energy(points.last().unwrap()));
    // The same scene with the energies of the amplitude backbone's ends as its range.
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text
        .replace(
            "amplitude_from = 0.05",
            &format!("energy_from = {e_from:e}"),
        )
        .replace("amplitude_to = 1.5", &format!("energy_to = {e_to:e}"));
    assert!(text.contains("energy_to"), "{text}");
    let dir = std::env::temp_dir().join(format!("ssn-modes-energy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("rod_modes_energy.toml");
    std::fs::write(&scene, text).unwrap();
    let by_energy = json_success(&ssn(&["modes", scene.to_str().unwrap(), "--json"]));
    assert_eq!(by_energy["converged"], true, "{by_energy}");
    let pts = by_energy["points"].as_array().unwrap();
    let amplitude = |p: &serde_json::Value| p["amplitude"].as_f64().unwrap();
    // It starts at the linear mode of that energy: amplitude 0.05 again, to round-off.
    assert!((amplitude(&pts[0]) - 0.05).abs() < 1e-12, "{}", pts[0]);
    assert!((energy(&pts[0]) - e_from).abs() < 1e-12 * e_from);
    // It ends at the first point at or past e_to, so at amplitude 1.5 or one step beyond;
    // the point before it is below both.
    let (last, before) = (&pts[pts.len() - 1], &pts[pts.len() - 2]);
    assert!(
        energy(last) >= e_to && energy(before) < e_to,
        "{before} {last}"
    );
    assert!(
        amplitude(before) < 1.5 && amplitude(last) >= 1.5 - 1e-9,
        "{before} {last}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_method_other_than_ssn_hb_is_refused_naming_the_key() {
    let path = scenes_dir().join("paper_rod_modes.toml");
    let out = ssn(&[
        "modes",
        path.to_str().unwrap(),
        "--set",
        "solver.method=\"penalty-hb\"",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("solver.method") && err.contains("ssn-hb"),
        "{err}"
    );
}
