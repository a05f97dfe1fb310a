//! The adversarial probe of the program's contract (`contract_probe.py` beside this file),
//! run on the built `ssn` in its fast form: every case but the few heavy by design ends in
//! well under a second. A case breaks when the program panics, aborts, is killed, hangs,
//! exits with a code other than the contract's (0 converged, 1 not converged, 2 bad input,
//! 3 output not written), writes NaN or null numbers, replaces an input, or refuses without
//! naming the key. The whole probe, heavy cases included:
//! `python3 ssn/tests/contract_probe.py target/release/ssn scenes`.

use std::path::Path;
use std::process::Command;

#[test]
fn the_fast_adversarial_probe_breaks_nowhere() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let output = Command::new("python3")
        .arg(manifest.join("tests/contract_probe.py"))
        .arg(env!("CARGO_BIN_EXE_ssn"))
        .arg(manifest.join("../scenes"))
        .env("PROBE_FAST", "1")
        .output()
        .expect("python3 runs the probe (the Python package's tests need it too)");
    let report = String::from_utf8_lossy(&output.stdout);
    let breaks: Vec<&str> = report.lines().filter(|l| l.starts_with("BREAK")).collect();
    assert!(
        output.status.success() && breaks.is_empty(),
        "{}\n{breaks:#?}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let last = report.lines().last().unwrap_or_default();
    let cases: usize = last
        .split_whitespace()
        .nth(3)
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(
        last.starts_with("0 breaks of") && cases >= 60,
        "the probe ran its cases: {last}"
    );
}
