//! Sweep windows in rad per unit time or in Hz: the same branch as the window given in
//! ratios of `omega_1`, and bounds of two units at once refused with both keys.

mod common;
#[path = "common/exit_status.rs"]
mod exit_status;
#[path = "common/process.rs"]
mod process;

use std::f64::consts::TAU;

use process::{json_success, ssn};

/// The modified-mass rod at H = 5 over a window around resonance, with the bounds `bounds`
/// given by `--set` (the scene itself has no `[sweep]`).
fn sweep_with(bounds: [(&str, f64); 2]) -> serde_json::Value {
    let scene = common::scenes_dir().join("paper_fig1_modified_mass.toml");
    let sets: Vec<String> = bounds
        .iter()
        .map(|(key, value)| format!("sweep.{key}={value:?}"))
        .chain([
            "solver.harmonics=5".to_string(),
            "sweep.stability=false".into(),
        ])
        .collect();
    let mut args = vec!["sweep", scene.to_str().unwrap(), "--json", "--quiet"];
    for set in &sets {
        args.extend(["--set", set]);
    }
    json_success(&ssn(&args))
}

fn numbers(doc: &serde_json::Value, key: &str) -> Vec<f64> {
    let values = doc[key]
        .as_array()
        .unwrap_or_else(|| panic!("{key} in {doc}"));
    values.iter().map(|v| v.as_f64().unwrap()).collect()
}

/// The window 0.9..1.1 omega_1 given in Hz and in rad per unit time gives the same points
/// as given in ratios. The bounds pass through `r omega_1 / 2 pi` and back (a few ulps), so
/// the continuation's points agree to round-off: 1e-9 relative, far below the arclength
/// steps (1e-2) a change of behaviour would move them by.
#[test]
fn a_sweep_in_hz_or_rad_per_time_equals_the_sweep_in_ratios() {
    let ratios = sweep_with([("omega_ratio_from", 0.9), ("omega_ratio_to", 1.1)]);
    let omega_1 = ratios["omega_1"].as_f64().unwrap();
    let hz = sweep_with([
        ("frequency_hz_from", 0.9 * omega_1 / TAU),
        ("frequency_hz_to", 1.1 * omega_1 / TAU),
    ]);
    let rad = sweep_with([("omega_from", 0.9 * omega_1), ("omega_to", 1.1 * omega_1)]);
    for other in [&hz, &rad] {
        for key in ["omega_ratio", "tip_max", "tip_min"] {
            let (a, b) = (numbers(&ratios, key), numbers(other, key));
            assert_eq!(a.len(), b.len(), "{key}: point counts");
            for (x, y) in a.iter().zip(&b) {
                assert!(
                    (x - y).abs() <= 1e-9 * x.abs().max(1.0),
                    "{key}: {x} against {y}"
                );
            }
        }
    }
    let first = numbers(&hz, "omega_ratio")[0];
    assert!(
        (first - 0.9).abs() < 1e-12,
        "the branch starts at 0.9 omega_1, not {first}"
    );
}

/// Bounds in two units at once are refused naming both keys; bounds set in one unit on a
/// scene whose file gives another replace the file's.
#[test]
fn sweep_bounds_in_two_units_are_refused_with_their_keys() {
    let scene = common::scenes_dir().join("paper_fig1_modified_mass.toml");
    let o = ssn(&[
        "sweep",
        scene.to_str().unwrap(),
        "--set",
        "sweep.omega_ratio_from=0.9",
        "--set",
        "sweep.omega_ratio_to=1.1",
        "--set",
        "sweep.frequency_hz_from=0.2",
    ]);
    exit_status::assert_exit(&o, 2, "two units");
    exit_status::assert_mentions(&o, &["sweep.frequency_hz_from", "sweep.omega_ratio_from"]);
    let text = "[rod]\nelements = 4\n[forcing]\namplitude = 1.0\n[sweep]\nomega_ratio_from = 0.9\nomega_ratio_to = 1.1\n";
    let set = |key: &str, value: f64| ssn::scene::Override::new(key, toml::Value::Float(value));
    let overrides = [
        set("sweep.omega_from", 1.0).unwrap(),
        set("sweep.omega_to", 2.0).unwrap(),
    ];
    let scene = ssn::scene::Scene::from_toml_with(text, "<test>", &overrides).unwrap();
    assert_eq!(scene.sweep_unit, ssn::scene::SweepUnit::RadPerTime);
    let sweep = scene.sweep.as_ref().unwrap();
    assert_eq!((sweep.omega_ratio_from, sweep.omega_ratio_to), (1.0, 2.0));
}
