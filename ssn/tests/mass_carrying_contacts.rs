//! Shipped scenes with every contact moved onto a dof that carries mass (the rod with its
//! consistent mass, the beam's stops on its tip instead of its massless pad): their sweeps
//! pass every contact corner from 0.5 to 3 `omega_1` at H = 10, 20 and 40, and every
//! point gets a stability verdict.

use std::path::Path;
use std::process::Command;

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

/// `ssn sweep SCENE --json` over `[0.5, 3] omega_1` at `harmonics` with the keys `edits`.
fn sweep(scene: &str, edits: &[&str], harmonics: usize) -> serde_json::Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes")
        .join(scene);
    let mut command = Command::new(SSN);
    command.args(["sweep", path.to_str().unwrap(), "--json", "--quiet"]);
    for edit in edits.iter().copied().chain([
        "sweep.omega_ratio_from=0.5",
        "sweep.omega_ratio_to=3",
        &format!("solver.harmonics={harmonics}"),
    ]) {
        command.args(["--set", edit]);
    }
    let out = command.output().unwrap();
    assert!(
        out.status.success(),
        "{scene} {edits:?} H = {harmonics}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn sweeps_with_every_contact_on_a_mass_carrying_dof_pass_the_whole_range_decided() {
    let cases: [(&str, &[&str]); 4] = [
        ("tip_force.toml", &["rod.mass=consistent"]),
        ("two_contacts.toml", &["rod.mass=consistent"]),
        // The beam's tip deflection dof instead of its massless pad.
        ("beam_tip_stop.toml", &["contact.point.0.dof=39"]),
        (
            "beam_two_sided.toml",
            &["contact.point.0.dof=39", "contact.point.1.dof=39"],
        ),
    ];
    for (scene, edits) in cases {
        for harmonics in [10, 20, 40] {
            let r = sweep(scene, edits, harmonics);
            let ratio = r["omega_ratio"].as_array().unwrap();
            let last = ratio.last().unwrap().as_f64().unwrap();
            println!(
                "{scene} H = {harmonics}: {} points, last at {last}",
                ratio.len()
            );
            assert_eq!(r["converged"], true, "{scene} H = {harmonics}");
            // The end of the sweep, to the round-off of omega_ratio = omega / omega_1.
            assert!(
                (last - 3.0).abs() < 1e-12,
                "{scene} H = {harmonics}: {last}"
            );
            let stable = r["stable"].as_array().unwrap();
            assert!(
                stable.iter().all(|s| s.is_boolean()),
                "{scene} H = {harmonics}: an undecided point"
            );
        }
    }
}
