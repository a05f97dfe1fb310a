//! The documented fields of the program's JSON documents (README, `ssn sweep --help`),
//! shared by the library's tests (`tests/common`) and the command-line tests
//! (`ssn/tests/cli.rs` includes this file).

/// The fields of `ssn sweep --json` (`FrequencyResponse::to_json`).
pub const SWEEP: [&str; 10] = [
    "points",
    "omega",
    "tip_max",
    "tip_min",
    "amplitude",
    "folds",
    "converged",
    "solve_seconds",
    "termination",
    "counters",
];
