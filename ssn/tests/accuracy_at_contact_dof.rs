//! An accuracy target at a contact dof: the observed maximum is read through the contact
//! law (the samples clamped at the obstacle, `tip_max_clamped`), so the truncated series'
//! Gibbs overshoot past the obstacle, which converges only like `H^-0.85`, no longer keeps
//! `accuracy = 1e-4` out of reach on the 20-element modified-mass rod (gap 0.5).

use std::process::Command;

use serde_json::Value;

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

/// The target asked.
const TARGET: f64 = 1e-4;

/// Harmonics of the independent reference: the finest rung a search on this rod reaches,
/// where the observed dof's extremes and the mean force have settled to about 1e-6
/// relative (their change from H = 320 to 640 is 1e-6 to 1.4e-6).
const REFERENCE_HARMONICS: usize = 640;

/// `ssn solve` of the shipped modified-mass scene with `sets` (`--set key=value`), its exit
/// status and JSON document.
fn solve(sets: &[String]) -> (bool, Value) {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/paper_fig1_modified_mass.toml"
    );
    let mut command = Command::new(SSN);
    command.args(["solve", scene, "--json", "--quiet"]);
    for set in sets {
        command.args(["--set", set]);
    }
    let out = command.output().unwrap();
    let json = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
    (out.status.success(), json)
}

fn number(json: &Value, key: &str) -> f64 {
    json[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no {key}: {json}"))
}

#[test]
fn accuracy_1e_4_at_a_contact_dof_is_met_and_agrees_with_a_refined_reference() {
    let (ok, json) = solve(&[format!("solver.accuracy={TARGET}")]);
    assert!(ok, "{json}");
    let accuracy = &json["accuracy"];
    assert_eq!(accuracy["met"], true, "{accuracy}");
    let chosen = accuracy["chosen"]["harmonics"].as_u64().unwrap() as usize;
    // Read on the raw series' maximum the estimate would need H > 640 (its change from
    // H = 320 to 640 alone is 1.35e-4 of the excursion); through the law the search stops
    // below the reference's harmonics.
    assert!(chosen < REFERENCE_HARMONICS, "H = {chosen}");
    let gap = 0.5;
    assert_eq!(number(&json, "tip_max_clamped"), gap);
    assert!(number(&json, "tip_max") > gap, "{json}");

    let (ok, reference) = solve(&[format!("solver.harmonics={REFERENCE_HARMONICS}")]);
    assert!(ok, "{reference}");
    let excursion = number(&reference, "tip_max").max(-number(&reference, "tip_min"));
    // The reported quantities against the reference, each relative to the reference's
    // excursion (the displacements) or its mean force, within the target: the reference's
    // own error (about 1e-6, above) is far below it.
    for key in ["tip_max_clamped", "tip_min"] {
        let error = (number(&json, key) - number(&reference, key)).abs() / excursion;
        assert!(error < TARGET, "{key}: {error:e}");
    }
    let force = number(&reference, "contact_force_mean");
    let error = (number(&json, "contact_force_mean") - force).abs() / force.abs();
    assert!(error < TARGET, "contact_force_mean: {error:e}");
    // The raw series' maximum is still reported, past the obstacle by more than the target.
    let overshoot = (number(&json, "tip_max") - number(&reference, "tip_max_clamped")) / excursion;
    assert!(overshoot > TARGET, "{overshoot:e}");
}
