//! Friction in the program's documents: `ssn solve --json`, `ssn sweep --json` and
//! `ssn solutions --json` on the shipped friction-damper scene carry each friction point
//! (stick fraction, force amplitude; the series for a solve), the sweep's peak is the one
//! single solves find, each solution is the root an independent solve finds, and the
//! stability is `null` with the reason.

use std::process::Command;

use serde_json::Value;

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

/// The shipped damper's slip limit `mu N` (`friction = 0.5`, `normal_load = 0.003`).
const SLIP_LIMIT: f64 = 0.5 * 0.003;

/// The JSON document of `ssn COMMAND scenes/friction_damper.toml --json ARGS` (asserted to
/// exit with 0).
fn run(command: &str, args: &[&str]) -> Value {
    let scene =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/friction_damper.toml");
    let out = Command::new(SSN)
        .arg(command)
        .arg(&scene)
        .args(["--json", "--quiet"])
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{command} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn number(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn a_solve_reports_each_friction_point_with_its_series() {
    let exact = run("solve", &[]);
    let friction = exact["friction"].as_array().unwrap();
    assert_eq!(friction.len(), 1);
    let f = &friction[0];
    assert_eq!(f["point"], 0);
    // The HB outputs are reconstructed on 1024 points per period.
    assert_eq!(f["force"].as_array().unwrap().len(), 1024);
    assert_eq!(f["slip_velocity"].as_array().unwrap().len(), 1024);
    // At resonance the damper slips over most of the period: its force reaches mu N
    // (the law's force on the truncated series, exactly the limit where it slips).
    assert_eq!(number(&f["slip_limit_max"]), SLIP_LIMIT);
    assert!((number(&f["force_amplitude"]) - SLIP_LIMIT).abs() < 1e-15);
    let stick = number(&f["stick_fraction"]);
    assert!((0.0..0.05).contains(&stick), "{stick}");
    // The slip velocity is the time derivative of the pads' relative displacement: of the
    // order of omega times the tip amplitude (the blades move out of phase, so the
    // relative motion is up to twice one blade's; measured 2.0 omega tip_max).
    let omega = number(&exact["omega"]);
    let tip = number(&exact["tip_max"]);
    let slip = number(&f["slip_velocity_amplitude"]);
    assert!(
        slip > 0.1 * omega * tip && slip < 4.0 * omega * tip,
        "{slip}"
    );

    // Regularised friction (penalty HB, eps = 1e-3 of the static slip): the same peak to
    // Newton's tolerance (1e-10 in force units, times the resonance amplification
    // 1 / (2 zeta) = 100: measured 2.9e-7 relative; the damper slips through the band of
    // the regularisation in a tiny part of the period), a force below mu N.
    let regularised = run("solve", &["--set", "solver.method=\"penalty-hb\""]);
    let r = &regularised["friction"][0];
    assert!(number(&r["force_amplitude"]) <= SLIP_LIMIT);
    assert!(number(&r["force_amplitude"]) > 0.99 * SLIP_LIMIT);
    let tip_r = number(&regularised["tip_max"]);
    assert!((tip_r - tip).abs() < 1e-6 * tip, "{tip_r} vs {tip}");
}

#[test]
fn a_friction_only_summary_shows_the_friction_point_and_no_contact_lines() {
    // The damper has no unilateral contact: its text summary has no penetration or mean
    // contact force line (they would read 0), and one line for its friction point with the
    // JSON's stick fraction and force against the slip limit mu N.
    let json = run("solve", &[]);
    let scene =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/friction_damper.toml");
    let out = Command::new(SSN).arg("solve").arg(&scene).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(!text.contains("max penetration"), "{text}");
    assert!(!text.contains("mean contact force"), "{text}");
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("friction 1 "))
        .unwrap_or_else(|| panic!("no friction line: {text}"));
    let f = &json["friction"][0];
    let stick = format!("stick {:.1} %", 100.0 * number(&f["stick_fraction"]));
    let force = format!("max force {:.6e}", number(&f["force_amplitude"]));
    let limit = format!("(slip limit {SLIP_LIMIT:.6e})");
    for part in [stick, force, limit] {
        assert!(line.contains(&part), "{part} not in {line}");
    }
}

#[test]
fn a_sweep_through_the_damped_resonance_and_the_solutions_on_it() {
    let sweep = run("sweep", &[]);
    assert_eq!(sweep["converged"], true);
    let points = sweep["points"].as_u64().unwrap() as usize;
    let friction = sweep["friction"].as_array().unwrap();
    assert_eq!(friction.len(), points);
    for point in friction {
        let f = &point[0];
        assert!((0.0..=1.0).contains(&number(&f["stick_fraction"])));
        assert!(number(&f["force_amplitude"]) <= SLIP_LIMIT * (1.0 + 1e-12));
    }
    // Stability: undecided at every point, with the reason.
    assert!(sweep["stable"]
        .as_array()
        .unwrap()
        .iter()
        .all(Value::is_null));
    let note = sweep["stability_note"].as_str().unwrap();
    assert!(note.contains("friction"), "{note}");

    // The peak of the branch against single SSN-HB solves from rest: at the peak's
    // frequency the same amplitude (the same equations, each solved to 1e-10: measured
    // agreement 1e-9 relative), and lower amplitudes 1 % to either side.
    let amplitude: Vec<f64> = sweep["amplitude"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    let ratio: Vec<f64> = sweep["omega_ratio"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    let peak = (0..points)
        .max_by(|a, b| amplitude[*a].total_cmp(&amplitude[*b]))
        .unwrap();
    assert!(
        peak > 0 && peak + 1 < points,
        "the peak is inside the sweep"
    );
    let single = |r: f64| {
        let s = run("solve", &["--set", &format!("forcing.omega_ratio={r}")]);
        number(&s["tip_max"]).max(-number(&s["tip_min"]))
    };
    let at_peak = single(ratio[peak]);
    assert!(
        (at_peak - amplitude[peak]).abs() < 1e-6 * at_peak,
        "{at_peak} vs {}",
        amplitude[peak]
    );
    for side in [0.99, 1.01] {
        assert!(single(side * ratio[peak]) < at_peak);
    }

    // `ssn solutions` at the shipped frequency: each solution is the root an independent
    // solve from rest finds (the same tip to 1e-6 relative), undecided with the reason.
    let set = run("solutions", &[]);
    let solutions = set["solutions"].as_array().unwrap();
    assert!(!solutions.is_empty());
    let solve = run("solve", &[]);
    for s in solutions {
        let tip = number(&s["tip_max"]);
        let independent = number(&solve["tip_max"]);
        assert!(
            (tip - independent).abs() < 1e-6 * independent,
            "{tip} vs {independent}"
        );
        assert!(s["stable"].is_null());
        assert!(s["stability_note"].as_str().unwrap().contains("friction"));
        assert!(number(&s["friction"][0]["force_amplitude"]) > 0.0);
    }
}
