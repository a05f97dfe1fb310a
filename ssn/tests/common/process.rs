//! Running the `ssn` program as a user does: its standard output as text and the JSON
//! document of a run that succeeded.

#![allow(dead_code)]

use std::process::{Command, Output};

/// Runs `ssn` with `args` to its end.
pub fn ssn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ssn"))
        .args(args)
        .output()
        .expect("the ssn binary runs")
}

/// The process's standard output as text.
pub fn out(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Asserts that the run exited with 0 (the assertion shows its standard error).
pub fn assert_success(o: &Output) {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The JSON document on the standard output of a run asserted to have exited with 0
/// ([`assert_success`]).
pub fn json_success(o: &Output) -> serde_json::Value {
    assert_success(o);
    serde_json::from_slice(&o.stdout).expect("a JSON document")
}
