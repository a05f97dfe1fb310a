//! `ssn modes SCENE`: the backbone of the shipped rod's first nonlinear mode, its JSON
//! document against the linear mode computed independently, and its input errors.

#[path = "common/process.rs"]
mod process;

use process::{json_success, ssn};
use semismooth_contact::describing_function::{jenkins_mode, terms_without_slider};
use semismooth_contact::rod::{build_rod, natural_frequencies};
use semismooth_contact::structures::{self, cantilever_with_tip_spring};
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

#[test]
fn friction_beam_scene_backbone_follows_the_single_harmonic_mode() {
    // The scene's matrices are `cantilever_with_tip_spring(10, 0.3)`: a Jenkins element
    // (k_t = 0.3, slip force 0.003) on the tip deflection, D = 0.05 M.
    let path = scenes_dir().join("beam_friction_modes.toml");
    let json = json_success(&ssn(&["modes", path.to_str().unwrap(), "--json"]));
    assert_eq!(json["converged"], true, "{json}");
    let (k, m, _) = cantilever_with_tip_spring(10, 0.3);
    let (terms, kt) = terms_without_slider(&k, &m, (0.05, 0.0), 18, 20).unwrap();
    let points = json["points"].as_array().unwrap();
    assert!(points.len() >= 20, "{}", points.len());
    let value = |p: &serde_json::Value, key: &str| p[key].as_f64().unwrap();
    let mut largest = (0.0f64, 0.0f64);
    for p in points {
        let r = jenkins_mode(&terms, kt, 0.003, 1, &[value(p, "amplitude")]).unwrap()[0];
        let dw = (value(p, "omega") / r.omega - 1.0).abs();
        let dzeta = (value(p, "damping_ratio") / r.damping_ratio - 1.0).abs();
        largest = (largest.0.max(dw), largest.1.max(dzeta));
    }
    // As in the library's test of the same beam (`contact/tests/nonlinear_modes.rs`): the
    // describing function is the one-harmonic limit, the differences EPMC's truncation of
    // the slider's kinked motion at H = 15, largest at the onset of slip (measured 4.2e-4 in
    // w, 2.9e-2 in the damping ratio).
    assert!(largest.0 < 1e-3 && largest.1 < 5e-2, "{largest:?}");
    // The damping ratio passes through a maximum about three times the stuck one.
    let zeta: Vec<f64> = points.iter().map(|p| value(p, "damping_ratio")).collect();
    let peak = zeta.iter().copied().fold(0.0, f64::max);
    assert!(
        peak > 3.0 * zeta[0] && peak > 2.0 * zeta[zeta.len() - 1],
        "{zeta:?}"
    );
}

#[test]
fn a_rod_beyond_the_dense_limit_gets_its_backbone_from_the_structured_solve() {
    // 200 elements at H = 20: (200 dofs + 1 contact) 41 + 2 = 8243 EPMC unknowns, past the
    // dense bordered solve's 8000: `ssn modes` takes the structured one.
    let path = scenes_dir().join("paper_rod_modes.toml");
    let refined = json_success(&ssn(&[
        "modes",
        path.to_str().unwrap(),
        "--json",
        "--set",
        "rod.elements=200",
    ]));
    let coarse = json_success(&ssn(&["modes", path.to_str().unwrap(), "--json"]));
    assert_eq!(refined["converged"], true, "{refined}");
    assert_eq!(refined["bordered_solve"], "structured");
    assert_eq!(coarse["bordered_solve"], "dense");
    let mut scene = Scene::from_path(&path).unwrap();
    scene.rod.elements = 200;
    let omega_1 = natural_frequencies(&build_rod(&scene.rod).unwrap().model, 1).unwrap()[0];
    let points = refined["points"].as_array().unwrap();
    assert!(points.len() >= 10, "{}", points.len());
    let omega = |p: &serde_json::Value| p["omega"].as_f64().unwrap();
    // Open at the first point: the refined rod's linear mode, to the eigensolvers'
    // round-off.
    assert!((omega(&points[0]) - omega_1).abs() < 1e-10 * omega_1);
    // Past the stop, the 20-element scene's backbone at the same amplitude 1.5, within
    // the discretisation error of the coarse rod (measured 3.7e-4 here, 4.5e-4 between
    // 20 and 100 elements at H = 10).
    let (last, reference) = (points.last().unwrap(), coarse["points"].as_array().unwrap());
    let reference = reference.last().unwrap();
    assert_eq!(last["amplitude"].as_f64(), Some(1.5));
    assert_eq!(reference["amplitude"].as_f64(), Some(1.5));
    let difference = (omega(last) / omega(reference) - 1.0).abs();
    println!("200 against 20 elements at amplitude 1.5: {difference:.1e}");
    assert!(
        omega(last) > 1.1 * omega_1 && difference < 1e-3,
        "{difference}"
    );
}

/// The shipped 100-blade sector scene under `engine_order` with a `[modes]` section (blade
/// tip amplitudes 0.05 to 3, the casing at gap 1 on the pad), written in `dir`.
fn sector_modes_scene(dir: &std::path::Path, engine_order: usize) -> std::path::PathBuf {
    let sector = scenes_dir().join("blade_sector");
    let text = std::fs::read_to_string(scenes_dir().join("bladed_disk_sector.toml"))
        .unwrap()
        .replace("\"blade_sector/", &format!("\"{}/", sector.display()))
        .replace(
            "engine_order = 3",
            &format!("engine_order = {engine_order}"),
        );
    let path = dir.join("sector_modes.toml");
    let modes = "\n[modes]\namplitude_from = 0.05\namplitude_to = 3.0\n";
    std::fs::write(&path, text + modes).unwrap();
    path
}

#[test]
fn a_sector_under_engine_order_0_starts_its_backbone_at_the_full_disks_nodal_diameter_0_mode() {
    let tmp = tempfile::tempdir().unwrap();
    let path = sector_modes_scene(tmp.path(), 0);
    let json = json_success(&ssn(&["modes", path.to_str().unwrap(), "--json"]));
    assert_eq!(json["converged"], true, "{json}");
    // The full 100-blade disk (the sector's files are its sector) has nodal diameter 0
    // lowest: its first natural frequency, from a dense eigensolve of the whole disk.
    let disk = structures::BladedDisk::tuned(100);
    let full = disk
        .structure(&structures::DiskLoading::shipped(Vec::new()))
        .unwrap();
    let omega_0 = natural_frequencies(&full.model, 1).unwrap()[0];
    let points = json["points"].as_array().unwrap();
    let first = points[0]["omega"].as_f64().unwrap();
    // The casing is open at the first amplitude: the linear mode, to the round-off of two
    // eigensolves of different matrices (4 sector dofs against 300).
    assert!(
        (first - omega_0).abs() < 1e-10 * omega_0,
        "{first} {omega_0}"
    );
    // Pressed into the casing at the last amplitude, the mode has stiffened.
    let last = points.last().unwrap()["omega"].as_f64().unwrap();
    assert!(last > 1.01 * omega_0, "{last} {omega_0}");
}

#[test]
fn a_sector_whose_harmonic_1_is_a_travelling_wave_is_refused_with_the_reason() {
    let tmp = tempfile::tempdir().unwrap();
    let path = sector_modes_scene(tmp.path(), 3);
    let out = ssn(&["modes", path.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("travelling wave") && err.contains("nodal diameter 3"),
        "{err}"
    );
}
