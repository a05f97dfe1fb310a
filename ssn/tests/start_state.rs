//! `ssn solve --state` and `--start`: a solve started from its own state converges at once
//! to the same answer; inside the overhang of the strongly forced rod `ssn solutions` finds
//! three solutions (two stable), and a solve started from each entry returns that entry,
//! while a solve from zero returns the no-contact one; mismatched states are refused with
//! the field named (exit code 2); a state of other harmonics is lifted or truncated.

use std::path::{Path, PathBuf};

use serde_json::Value;

#[path = "common/process.rs"]
mod process;

use process::{json_success, ssn};

/// The strongly forced rod inside its overhang: 20 elements, modified mass, p0 = 0.2,
/// gap 0.5, H = 20, at 1.14 omega_1 (folds at 1.098 and 1.185).
const STRONG: &str = "[rod]\nelements = 20\nmass = \"modified\"\n[damping]\nzeta = 0.01\n\
    [forcing]\namplitude = 0.2\nomega_ratio = 1.14\n[contact]\ngap = 0.5\n\
    [solver]\nharmonics = 20\n\
    [sweep]\nomega_ratio_from = 0.8\nomega_ratio_to = 1.6\n";

struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("ssn-start-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    fn write(&self, name: &str, text: &str) -> String {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    }

    fn path(&self, name: &str) -> String {
        self.0.join(name).to_str().unwrap().to_string()
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn read_json(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(Path::new(path)).unwrap()).unwrap()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Largest difference of two coefficient lists relative to the largest coefficient.
fn relative_distance(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

#[test]
fn a_solve_started_from_its_own_state_converges_at_once_to_the_same_answer() {
    let dir = Dir::new("own");
    let scene = dir.write("strong.toml", STRONG);
    let state = dir.path("state.json");
    let first = json_success(&ssn(&["solve", &scene, "--json", "--state", &state]));
    let doc = read_json(&state);
    assert_eq!(doc["method"], "ssn-hb");
    assert_eq!(doc["harmonics"], 20);
    assert_eq!(doc["dofs"], 20);
    assert_eq!(doc["contacts"], 1);
    assert_eq!(numbers(&doc["displacement"]).len(), 41 * 20);
    assert_eq!(numbers(&doc["contact_force"]).len(), 41);
    let second = json_success(&ssn(&["solve", &scene, "--json", "--start", &state]));
    // The state is a solution to the Newton tolerance: at most one more step, and the same
    // tip extremes to round-off (1e-12 of the amplitude).
    assert!(second["iterations"].as_u64().unwrap() <= 1, "{second}");
    for key in ["tip_min", "tip_max"] {
        let (a, b) = (first[key].as_f64().unwrap(), second[key].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-12 * a.abs(), "{key}: {a} against {b}");
    }
    assert_eq!(second["started_from"]["note"], Value::Null);
}

#[test]
fn inside_the_overhang_each_listed_solution_is_a_start_that_returns_it() {
    let dir = Dir::new("entries");
    let scene = dir.write("strong.toml", STRONG);
    let solutions_out = ssn(&["solutions", &scene, "--json"]);
    let solutions = json_success(&solutions_out);
    let list = solutions["solutions"].as_array().unwrap();
    let stable: Vec<&Value> = list.iter().map(|s| &s["stable"]).collect();
    assert_eq!(
        stable,
        [&Value::Bool(true), &Value::Bool(false), &Value::Bool(true)],
        "three solutions, the middle one unstable"
    );
    let file = dir.write(
        "solutions.json",
        &String::from_utf8(solutions_out.stdout).unwrap(),
    );
    let zero = json_success(&ssn(&["solve", &scene, "--json"]));
    let zero_tip = zero["tip_min"].as_f64().unwrap();
    let mut different_from_zero = 0;
    for (k, entry) in list.iter().enumerate() {
        let k1 = (k + 1).to_string();
        let solved = json_success(&ssn(&[
            "solve", &scene, "--json", "--start", &file, "--entry", &k1,
        ]));
        // The entry is a Newton solution at this very frequency and settings: the solve
        // stays on it (at most one step; the tip extremes to 1e-10 relative).
        assert!(solved["iterations"].as_u64().unwrap() <= 1, "{solved}");
        let (a, b) = (
            entry["tip_min"].as_f64().unwrap(),
            solved["tip_min"].as_f64().unwrap(),
        );
        assert!(
            (a - b).abs() <= 1e-10 * a.abs(),
            "entry {k1}: {a} against {b}"
        );
        assert_eq!(solved["started_from"]["entry"], k + 1);
        if (b - zero_tip).abs() > 0.1 {
            different_from_zero += 1;
        }
    }
    // From zero Newton lands on the no-contact solution (the third); the contact solutions,
    // 0.33 and 0.68 deeper, only from their entries.
    assert_eq!(different_from_zero, 2, "zero start: tip min {zero_tip}");
    // The state of an entry is the entry's coefficients: its tip minimum is reproduced by
    // `--state` of the solve started from it.
    let state = dir.path("state.json");
    json_success(&ssn(&[
        "solve", &scene, "--json", "--start", &file, "--entry", "1", "--state", &state,
    ]));
    let written = numbers(&read_json(&state)["displacement"]);
    let listed = numbers(&list[0]["state"]["displacement"]);
    assert!(relative_distance(&listed, &written) < 1e-10);
}

#[test]
fn a_state_of_other_harmonics_is_lifted_or_truncated_and_mismatches_name_the_field() {
    let dir = Dir::new("mismatch");
    let scene = dir.write("strong.toml", STRONG);
    let state = dir.path("state.json");
    let solutions = dir.path("solutions.json");
    json_success(&ssn(&["solve", &scene, "--json", "--state", &state]));
    let out = ssn(&["solutions", &scene, "--json"]);
    std::fs::write(&solutions, &out.stdout).unwrap();
    // The contact solution (entry 1) at H = 20 started at H = 40 and H = 10: Newton stays
    // on the contact branch (tip min -1.0239 at H = 40 and -1.0390 at H = 10 against
    // -1.0270 at H = 20, measured; a start from zero gives the no-contact -0.3459).
    for (harmonics, note) in [(40, "lifted"), (10, "truncated")] {
        let other = dir.write(
            &format!("h{harmonics}.toml"),
            &STRONG.replace("harmonics = 20", &format!("harmonics = {harmonics}")),
        );
        let solved = json_success(&ssn(&[
            "solve", &other, "--json", "--start", &solutions, "--entry", "1",
        ]));
        let tip = solved["tip_min"].as_f64().unwrap();
        assert!((tip + 1.027).abs() < 0.02, "H = {harmonics}: tip min {tip}");
        let words = solved["started_from"]["note"].as_str().unwrap();
        assert!(words.contains(note), "{words}");
    }
    let refused = |scene_text: &str, start: &str, extra: &[&str], field: &str| {
        let path = dir.write("other.toml", scene_text);
        let mut args = vec!["solve", path.as_str(), "--start", start];
        args.extend_from_slice(extra);
        let o = ssn(&args);
        let message = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(o.status.code(), Some(2), "{field}: {message}");
        assert!(message.contains(field), "{field}: {message}");
        assert!(!message.contains("panicked"), "{message}");
    };
    refused(
        &STRONG.replace("elements = 20", "elements = 10"),
        &state,
        &[],
        "dofs",
    );
    refused(
        &STRONG.replace("[solver]\n", "[solver]\nmethod = \"penalty-hb\"\n"),
        &state,
        &[],
        "method",
    );
    refused(
        &STRONG.replace("[solver]\n", "[solver]\nmethod = \"lcp-ssn\"\n"),
        &state,
        &[],
        "--start",
    );
    refused(STRONG, &solutions, &[], "--entry");
    refused(STRONG, &solutions, &["--entry", "4"], "--entry");
    refused(STRONG, &state, &["--entry", "1"], "--entry");
    let mut doc = read_json(&state);
    doc["contacts"] = 2.into();
    let two = dir.write("two.json", &doc.to_string());
    refused(STRONG, &two, &[], "contact_force");
    let mut doc = read_json(&state);
    doc["displacement"][3] = "x".into();
    let bad = dir.write("bad.json", &doc.to_string());
    refused(STRONG, &bad, &[], "displacement[3]");
    let truncated = dir.write("cut.json", "{\"format\": ");
    refused(STRONG, &truncated, &[], "not a JSON state");
    // The start is an input: --state may not replace it (the run writes nothing).
    let before = std::fs::read_to_string(&state).unwrap();
    refused(STRONG, &state, &["--state", &state], "--state");
    assert_eq!(std::fs::read_to_string(&state).unwrap(), before);
}
