//! The `ssn` program as users run it: help texts, `ssn solve` on every shipped
//! scene (JSON fields, exit code 0), bad scenes (exit code 2, message naming the file and the
//! key), unwritable outputs (exit code 3, nothing left behind), a non-converged run (JSON
//! with `converged = false`, exit code 1) and `ssn scene-check`.

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

#[path = "common/exit_status.rs"]
mod exit_status;
#[path = "common/json_fields.rs"]
mod json_fields;
#[path = "common/process.rs"]
mod process;

use exit_status::err as stderr;
use process::{out as stdout, ssn};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

fn shipped_scenes() -> Vec<PathBuf> {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .expect("scenes exists")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 6, "expected the shipped scenes: {scenes:?}");
    scenes
}

/// A fresh directory under the system temporary directory, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("ssn-cli-test-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temporary directory");
        TempDir(dir)
    }

    fn write(&self, name: &str, text: &str) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, text).expect("write scene");
        path
    }

    fn entries(&self) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(&self.0)
            .expect("read temporary directory")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The subcommands listed under "Commands:" in `ssn --help` (so a new subcommand is
/// covered by the help test without editing it).
fn subcommands() -> Vec<String> {
    let help = stdout(&ssn(&["--help"]));
    let mut in_commands = false;
    let mut names = Vec::new();
    for line in help.lines() {
        if line.starts_with("Commands:") {
            in_commands = true;
            continue;
        }
        if in_commands {
            if line.trim().is_empty() || !line.starts_with(' ') {
                break;
            }
            if let Some(name) = line.split_whitespace().next() {
                if name != "help" {
                    names.push(name.to_string());
                }
            }
        }
    }
    names
}

#[test]
fn every_subcommand_help_exits_zero_and_shows_an_example() {
    let commands = subcommands();
    for expected in ["solve", "scene-check", "sweep"] {
        assert!(
            commands.iter().any(|c| c == expected),
            "{expected} missing from {commands:?}"
        );
    }
    for c in &commands {
        let out = ssn(&[c, "--help"]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "ssn {c} --help: {}",
            stderr(&out)
        );
        let text = stdout(&out);
        assert!(
            text.to_lowercase().contains("example"),
            "ssn {c} --help has no example:\n{text}"
        );
        assert!(
            text.contains("ssn "),
            "ssn {c} --help: the example should be a command line"
        );
    }
}

#[test]
fn program_help_exits_zero_and_documents_the_exit_codes() {
    let out = ssn(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    for needle in ["Exit codes", "0  converged", "1  ", "2  bad input", "3  "] {
        assert!(
            text.contains(needle),
            "`{needle}` missing from ssn --help:\n{text}"
        );
    }
}

/// The program's own help shows an example command line, as every subcommand's help does.
#[test]
fn program_help_shows_an_example() {
    let text = stdout(&ssn(&["--help"]));
    assert!(text.to_lowercase().contains("example"), "{text}");
}

const REQUIRED_FIELDS: [&str; 13] = [
    "method",
    "converged",
    "termination",
    "iterations",
    "residual_norm",
    "effective_tolerance",
    "omega",
    "time_samples",
    "tip_max",
    "tip_min",
    "contact_force_mean",
    "max_penetration",
    "solve_seconds",
];
const COUNTER_FIELDS: [&str; 5] = [
    "residual_evaluations",
    "jacobian_evaluations",
    "factorizations",
    "linear_solves",
    "ffts",
];

fn solve_json(scene: &Path, extra: &[&str]) -> (Output, Value) {
    let mut args = vec!["solve", "--json", scene.to_str().expect("utf-8 path")];
    args.extend_from_slice(extra);
    let out = ssn(&args);
    let json: Value = serde_json::from_str(&stdout(&out)).unwrap_or_else(|e| {
        panic!(
            "{}: stdout is not JSON ({e}):\n{}\nstderr: {}",
            scene.display(),
            stdout(&out),
            stderr(&out)
        )
    });
    (out, json)
}

/// `ssn solve --json` on a scene given as text (written to a temporary directory).
fn solve_text(tag: &str, text: &str) -> (Output, Value) {
    let dir = TempDir::new(tag);
    let scene = dir.write("scene.toml", text);
    solve_json(&scene, &[])
}

#[test]
fn solve_every_shipped_scene_prints_the_documented_json() {
    for scene in shipped_scenes() {
        let (out, json) = solve_json(&scene, &[]);
        let name = scene.display();
        assert_eq!(out.status.code(), Some(0), "{name}: {}", stderr(&out));
        for f in REQUIRED_FIELDS {
            assert!(json.get(f).is_some(), "{name}: field {f} missing: {json}");
        }
        for f in COUNTER_FIELDS {
            assert!(
                json["counters"].get(f).and_then(Value::as_u64).is_some(),
                "{name}: counters.{f} missing or not an integer: {json}"
            );
        }
        assert_eq!(json["converged"], Value::Bool(true), "{name}");
        assert_eq!(json["termination"], "converged", "{name}");
        // Every number finite (JSON has no NaN; the program writes null for non-finite).
        for f in [
            "residual_norm",
            "omega",
            "tip_max",
            "tip_min",
            "contact_force_mean",
            "max_penetration",
            "solve_seconds",
        ] {
            assert!(
                json[f].as_f64().is_some_and(f64::is_finite),
                "{name}: {f} = {}",
                json[f]
            );
        }
        let method = json["method"].as_str().expect("method is a string");
        let is_hb = matches!(method, "ssn-hb" | "penalty-hb");
        assert_eq!(
            json.get("harmonics").is_some(),
            is_hb,
            "{name}: harmonics present only for HB"
        );
        assert!(
            json["tip_min"].as_f64() <= json["tip_max"].as_f64(),
            "{name}"
        );
        assert!(
            json["contact_force_mean"].as_f64().unwrap() <= 0.0,
            "{name}: mean contact force > 0"
        );
    }
}

/// A tolerance below the model's round-off floor is raised to it and the JSON reports the
/// tolerance actually used: the scene asks 1e-300, the run converges against
/// `eps max K_ii sqrt(n) min(max|U|, max|g|)` with `K_ii = 2 EA / h = 40` (20 elements),
/// `n = 21 x 41` SSN-HB unknowns at H = 20, `max|U|` the answer's largest displacement
/// coefficient and the gap 0.5; at the scene's default 1e-10 the floor is below it and the
/// tolerance is the scene's.
#[test]
fn a_tolerance_below_the_round_off_floor_is_raised_and_reported() {
    let dir = TempDir::new("tolerance");
    let scene = dir.write(
        "scene.toml",
        &CANONICAL.replace("[solver]", "[solver]\ntolerance = 1e-300"),
    );
    let state = dir.0.join("state.json");
    let (out, json) = solve_json(&scene, &["--state", state.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let state: Value = serde_json::from_str(&std::fs::read_to_string(&state).unwrap()).unwrap();
    let largest = state["displacement"]
        .as_array()
        .unwrap()
        .iter()
        .fold(0.0f64, |m, u| m.max(u.as_f64().unwrap().abs()));
    let floor = f64::EPSILON * 40.0 * (21.0f64 * 41.0).sqrt() * largest.min(0.5);
    let used = json["effective_tolerance"].as_f64().unwrap();
    assert!((used / floor - 1.0).abs() < 1e-12, "{used:e} vs {floor:e}");
    assert!(json["residual_norm"].as_f64().unwrap() <= used);
    let (_, json) = solve_json(&scenes_dir().join("paper_fig1_modified_mass.toml"), &[]);
    assert_eq!(json["effective_tolerance"].as_f64(), Some(1e-10));
}

#[test]
fn the_linear_scene_costs_one_factorization_no_fft_one_iteration() {
    let (out, json) = solve_json(&scenes_dir().join("linear_no_contact.toml"), &[]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(json["iterations"], 1, "{json}");
    assert_eq!(json["counters"]["factorizations"], 1, "{json}");
    assert_eq!(json["counters"]["ffts"], 0, "{json}");
    // The closed form: the tip of the damped linear rod at 0.9 omega_1 is symmetric.
    let (max, min) = (
        json["tip_max"].as_f64().unwrap(),
        json["tip_min"].as_f64().unwrap(),
    );
    assert!(
        (max + min).abs() <= 1e-12 * max.abs(),
        "linear response not symmetric: {max} / {min}"
    );
}

/// The shipped modified-mass scene of Fig. 1; the bad scenes replace or add one of its keys.
const CANONICAL: &str = include_str!("../../scenes/paper_fig1_modified_mass.toml");

fn bad_scene_case(dir: &TempDir, name: &str, text: &str, must_name: &[&str]) {
    let path = dir.write(&format!("{name}.toml"), text);
    for command in ["solve", "scene-check"] {
        let out = ssn(&[command, path.to_str().unwrap()]);
        let err = stderr(&out);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{name} ({command}): exit {:?}, stderr {err}",
            out.status.code()
        );
        assert!(
            err.contains(&format!("{name}.toml")),
            "{name} ({command}): file not named: {err}"
        );
        for needle in must_name {
            assert!(
                err.contains(needle),
                "{name} ({command}): `{needle}` not in: {err}"
            );
        }
        assert!(
            stdout(&out).trim().is_empty(),
            "{name}: printed a result: {}",
            stdout(&out)
        );
    }
}

#[test]
fn bad_scenes_exit_2_naming_the_file_and_the_key() {
    let dir = TempDir::new("bad");
    bad_scene_case(&dir, "malformed", "[rod\nelements = 20\n", &["line 1"]);
    // (name, text replaced in the scene, replacement, what the message must contain)
    #[rustfmt::skip]
    let cases: [(&str, &str, &str, &[&str]); 10] = [
        ("unknown_key", "gap = 0.5", "gapp = 0.5", &["gapp"]),
        ("missing_key", "amplitude = 0.04\n", "", &["amplitude"]),
        ("wrong_type", "elements = 20", "elements = \"twenty\"", &["elements"]),
        ("negative_size", "elements = 20", "elements = -5", &["rod.elements", "-5"]),
        ("zero_size", "elements = 20", "elements = 0", &["rod.elements"]),
        ("nan", "amplitude = 0.04", "amplitude = nan", &["forcing.amplitude", "NaN"]),
        ("infinite", "gap = 0.5", "gap = inf", &["contact.gap"]),
        ("zero_harmonics", "harmonics = 20", "harmonics = 0", &["solver.harmonics"]),
        ("nt_too_small", "harmonics = 20", "harmonics = 20\ntime_samples = 16", &["solver.time_samples", "16"]),
        ("node_out_of_range", "[contact]\ngap = 0.5", "[[contact.point]]\nnode = 25\ngap = 0.5", &["node", "25"]),
    ];
    for (name, from, to, needles) in cases {
        assert!(
            CANONICAL.contains(from),
            "{name}: `{from}` not in the scene"
        );
        bad_scene_case(&dir, name, &CANONICAL.replace(from, to), needles);
    }
}

#[test]
fn a_missing_scene_file_exits_2_naming_it() {
    let out = ssn(&["solve", "/nonexistent/scene.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("/nonexistent/scene.toml"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn an_unwritable_output_exits_3_and_leaves_no_file() {
    let scene = scenes_dir().join("linear_no_contact.toml");
    let scene = scene.to_str().unwrap();
    for flag in ["--csv", "--svg"] {
        let out = ssn(&["solve", scene, flag, "/nonexistent/dir/x.out"]);
        assert_eq!(
            out.status.code(),
            Some(3),
            "{flag}: stderr {}",
            stderr(&out)
        );
        assert!(
            stderr(&out).contains("/nonexistent/dir"),
            "{flag}: {}",
            stderr(&out)
        );
        assert!(!Path::new("/nonexistent/dir/x.out").exists());
    }
    // A parent that is a regular file: cannot be created even by root (where
    // /nonexistent/dir could be), so the write must fail and leave nothing.
    let dir = TempDir::new("out");
    let file = dir.write("a-file", "x");
    // `ssn solve --csv target` exits 3 and leaves only `left` in `dir`.
    let write_fails = |target: &Path, left: &str| {
        let out = ssn(&["solve", scene, "--csv", target.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(3), "stderr {}", stderr(&out));
        assert_eq!(dir.entries(), vec![left], "something was left behind");
    };
    write_fails(&file.join("x.csv"), "a-file");
    std::fs::remove_file(&file).unwrap();
    // The target is an existing directory: the write fails and no temporary file is left.
    let sub = dir.0.join("a-directory");
    std::fs::create_dir(&sub).unwrap();
    write_fails(&sub, "a-directory");
    assert!(
        std::fs::read_dir(&sub).unwrap().next().is_none(),
        "files left in the target"
    );
}

#[test]
fn a_writable_output_is_complete_csv() {
    let dir = TempDir::new("csv");
    let csv = dir.0.join("tip.csv");
    let scene = scenes_dir().join("paper_fig1_modified_mass.toml");
    let out = ssn(&[
        "solve",
        scene.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("t,u_tip"), "{header}");
    let rows: Vec<&str> = lines.filter(|l| !l.is_empty()).collect();
    // 1024 reconstruction points for HB (semismooth_contact::solve::HB_OUTPUT_POINTS).
    assert_eq!(rows.len(), 1024);
    for r in rows {
        assert!(
            r.split(',')
                .all(|v| v.trim().parse::<f64>().is_ok_and(f64::is_finite)),
            "{r}"
        );
    }
    assert_eq!(
        dir.entries(),
        vec!["tip.csv".to_string()],
        "temporary files left"
    );
}

/// The columns of an `ssn solve --csv` file by header.
fn csv_columns(text: &str) -> std::collections::HashMap<String, Vec<f64>> {
    let mut lines = text.lines();
    let headers: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); headers.len()];
    for line in lines.filter(|l| !l.is_empty()) {
        for (column, value) in columns.iter_mut().zip(line.split(',')) {
            column.push(value.trim().parse().unwrap());
        }
    }
    headers.into_iter().zip(columns).collect()
}

#[test]
fn the_contact_force_column_is_the_law_on_the_samples_and_never_tension() {
    let dir = TempDir::new("force-law");
    let csv = dir.0.join("force.csv");
    let scene = scenes_dir().join("paper_fig1.toml");
    // AFT samples on the output grid (1024 points), so that the law's samples are the
    // ones the equations project.
    let out = ssn(&[
        "solve",
        scene.to_str().unwrap(),
        "--set",
        "solver.time_samples=1024",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let columns = csv_columns(&std::fs::read_to_string(&csv).unwrap());
    let (law, series) = (&columns["lambda_0"], &columns["lambda_series_0"]);
    assert!(
        law.iter().all(|&f| f <= 0.0),
        "tension in the law's samples"
    );
    // The truncated series rings into tension (about +0.027 against a peak of -0.25).
    let ringing = series.iter().fold(f64::NEG_INFINITY, |m, &f| m.max(f));
    assert!(ringing > 1e-2, "largest series value {ringing}");
    // Independent of the output code: the equations say the series is the projection of
    // the law's samples on harmonics 0..=20, here a DFT of the column. Both are
    // reconstructions of a converged solve to 1e-10: 1e-9 leaves a margin of 10.
    let n = law.len();
    let projection: Vec<f64> = (0..n)
        .map(|t| {
            (0..=20)
                .map(|k| {
                    let weight = if k == 0 { 1.0 } else { 2.0 } / n as f64;
                    let (a, b) = law.iter().enumerate().fold((0.0, 0.0), |(a, b), (s, f)| {
                        let phase = 2.0 * std::f64::consts::PI * (k * s) as f64 / n as f64;
                        (a + f * phase.cos(), b + f * phase.sin())
                    });
                    let phase = 2.0 * std::f64::consts::PI * (k * t) as f64 / n as f64;
                    weight * (a * phase.cos() + b * phase.sin())
                })
                .sum()
        })
        .collect();
    let difference = projection
        .iter()
        .zip(series)
        .fold(0.0f64, |m, (p, s)| m.max((p - s).abs()));
    assert!(
        difference <= 1e-9,
        "series against the law's projection: {difference:e}"
    );
}

#[test]
fn a_run_that_does_not_converge_prints_its_json_and_exits_1() {
    let (out, json) = solve_text("noconv", &format!("{CANONICAL}max_iterations = 1\n"));
    assert_eq!(out.status.code(), Some(1), "stderr {}", stderr(&out));
    assert_eq!(json["converged"], Value::Bool(false));
    assert_eq!(json["termination"], "max-iterations", "{json}");
    assert_eq!(json["iterations"], 1);
    assert!(
        json["residual_norm"]
            .as_f64()
            .is_some_and(|r| r.is_finite() && r > 1e-10),
        "{json}"
    );
}

#[test]
fn a_run_that_does_not_converge_prints_no_result_in_its_text() {
    let scene = scenes_dir().join("paper_fig1_modified_mass.toml");
    let scene = scene.to_str().expect("a UTF-8 path");
    let out = ssn(&["solve", scene, "--set", "solver.max_iterations=1"]);
    assert_eq!(out.status.code(), Some(1), "stderr {}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("converged         false"), "{text}");
    // The best iterate is not an answer: no tip extremes, penetration or force that could
    // be read as one.
    assert!(
        text.contains("tip max / min     none: the solve did not converge"),
        "{text}"
    );
    for key in ["max penetration", "mean contact force"] {
        assert!(!text.contains(key), "{key} printed:\n{text}");
    }
}

fn natural_frequencies_line(text: &str) -> Vec<f64> {
    let line = text
        .lines()
        .find(|l| l.starts_with("natural freqs"))
        .unwrap_or_else(|| panic!("no natural frequencies in:\n{text}"));
    line["natural freqs".len()..]
        .split(',')
        .map(|v| v.trim().parse().expect("a frequency"))
        .collect()
}

#[test]
fn scene_check_prints_frequencies_and_the_effects_present() {
    let check = |name: &str| {
        let out = ssn(&["scene-check", scenes_dir().join(name).to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(0), "{name}: {}", stderr(&out));
        stdout(&out)
    };
    // Continuous clamped-free rod: omega_k = (2k - 1) pi / 2 (L = EA = rhoA = 1). Linear
    // elements with consistent mass overestimate a frequency by (omega h)^2 / 24 relative
    // (h = 1/20): 2.6e-4 for mode 1, 6.4e-3 for mode 3; allow 1.5 times that.
    let text = check("paper_fig1.toml");
    let freqs = natural_frequencies_line(&text);
    assert_eq!(freqs.len(), 5);
    let h = 1.0 / 20.0;
    for (k, &w) in freqs.iter().take(3).enumerate() {
        let exact = (2 * k + 1) as f64 * std::f64::consts::FRAC_PI_2;
        let relative = (exact * h).powi(2) / 24.0;
        assert!(
            w >= exact,
            "mode {}: consistent mass is an upper bound: {w} < {exact}",
            k + 1
        );
        assert!(
            w - exact <= 1.5 * relative * exact,
            "mode {}: {w} vs {exact}",
            k + 1
        );
    }
    assert!(
        text.contains("zeta = 0.01"),
        "damping not described:\n{text}"
    );
    assert!(
        text.contains("gap 0.5") && text.contains("(tip)"),
        "contact not described:\n{text}"
    );
    assert!(
        text.contains("note"),
        "the consistent-mass contact note is missing:\n{text}"
    );

    let text = check("linear_no_contact.toml");
    assert!(text.contains("none: linear problem"), "{text}");

    let text = check("two_contacts.toml");
    assert_eq!(
        text.lines()
            .filter(|l| l.starts_with("contact ") && l.contains("node"))
            .count(),
        2,
        "{text}"
    );
}

/// scene-check says when a contact node has mass. In
/// `two_contacts.toml` (modified mass) node 10 is interior and keeps its mass, so the LCP
/// and time marching need an impact law (measured: Lemke ends at the pivot limit, 25,700
/// pivots, on this scene), but scene-check only warns for non-modified mass models.
#[test]
fn scene_check_warns_about_a_massive_interior_contact_node() {
    let out = ssn(&[
        "scene-check",
        scenes_dir().join("two_contacts.toml").to_str().unwrap(),
    ]);
    let text = stdout(&out);
    assert!(text.contains("note"), "{text}");
}

/// LCP and time marching: no `harmonics`, `time_samples` the steps per period, their own
/// counters, contact exact at the time nodes; the tip minimum agrees with SSN-HB's on the
/// same (modified-mass) scene within the HB truncation bound `4 A / (pi H)` (hard_cases.rs).
#[test]
fn lcp_and_march_scenes_print_json_without_harmonics() {
    let (_, hb) = solve_json(&scenes_dir().join("paper_fig1_modified_mass.toml"), &[]);
    let hb_min = hb["tip_min"].as_f64().unwrap();
    let half_amplitude = 0.5 * (hb["tip_max"].as_f64().unwrap() - hb_min);
    let bound = 4.0 * half_amplitude / (std::f64::consts::PI * 20.0);
    let dir = TempDir::new("lcp");
    for (method, extra, counter) in [
        ("lcp-lemke", "time_samples = 128", "lemke_pivots"),
        ("march", "steps_per_period = 256", "time_steps"),
    ] {
        let text = CANONICAL.replace(
            "method = \"ssn-hb\"\nharmonics = 20",
            &format!("method = \"{method}\"\n{extra}"),
        );
        let path = dir.write(&format!("{method}.toml"), &text);
        let (out, json) = solve_json(&path, &[]);
        assert_eq!(out.status.code(), Some(0), "{method}: {}", stderr(&out));
        assert_eq!(json["method"], method);
        assert!(json.get("harmonics").is_none(), "{json}");
        assert!(
            json["time_samples"] == 128 || json["time_samples"] == 256,
            "{json}"
        );
        assert!(json["counters"][counter].as_u64().unwrap() > 0, "{json}");
        assert!(json["max_penetration"].as_f64().unwrap() <= 1e-9, "{json}");
        let diff = (json["tip_min"].as_f64().unwrap() - hb_min).abs();
        assert!(
            diff <= bound,
            "{method}: tip min differs from SSN-HB by {diff} > {bound}"
        );
    }
}

/// The `ssn sweep --json` document of a converged branch: every documented field, the
/// per-point arrays one finite entry per point (at least two points).
fn assert_converged_sweep_json(json: &Value) {
    for key in json_fields::SWEEP {
        assert!(json.get(key).is_some(), "{key}");
    }
    assert_eq!(
        json["converged"],
        Value::Bool(true),
        "{}",
        json["termination"]
    );
    let omega = json["omega"].as_array().expect("omega array");
    assert!(omega.len() >= 2 && json["points"] == omega.len());
    for key in ["omega", "tip_max", "tip_min", "amplitude"] {
        let v = json[key].as_array().expect("array");
        assert_eq!(v.len(), omega.len(), "{key}");
        assert!(
            v.iter().all(|x| x.as_f64().is_some_and(f64::is_finite)),
            "{key}"
        );
    }
}

#[test]
fn sweep_prints_a_branch_and_rejects_scenes_it_cannot_sweep() {
    let fig2 = scenes_dir().join("paper_fig2.toml");
    let out = ssn(&["sweep", "--json", fig2.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let json: Value = serde_json::from_str(&stdout(&out)).expect("sweep JSON");
    assert_converged_sweep_json(&json);

    // No [sweep] section: bad input naming the file and the section.
    let fig1 = scenes_dir().join("paper_fig1.toml");
    let out = ssn(&["sweep", fig1.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("paper_fig1.toml") && stderr(&out).contains("[sweep]"),
        "{}",
        stderr(&out)
    );

    // Lemke cannot be continued in omega: bad input, saying which methods can.
    let dir = TempDir::new("sweep");
    let text = std::fs::read_to_string(&fig2)
        .unwrap()
        .replace("method = \"ssn-hb\"", "method = \"lcp-lemke\"");
    let path = dir.write("lemke_sweep.toml", &text);
    let out = ssn(&["sweep", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("lemke_sweep.toml") && stderr(&out).contains("lcp-lemke"),
        "{}",
        stderr(&out)
    );
}

/// What the library should do: scene-check prints the finite natural frequencies of a
/// valid small rod. With 2 elements and the modified mass (massless tip) the model has one
/// finite frequency, scene-check asks for min(5, dofs) = 2 and exits 2: "2 natural
/// frequencies requested, the model has 1 finite ones" (`ssn solve` on the same scene
/// converges).
#[test]
fn scene_check_accepts_a_two_element_modified_mass_rod() {
    let dir = TempDir::new("two-el");
    let text = CANONICAL.replace("elements = 20", "elements = 2");
    let path = dir.write("two_elements.toml", &text);
    let out = ssn(&["solve", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "solve: {}", stderr(&out));
    let out = ssn(&["scene-check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "scene-check: {}", stderr(&out));
    assert_eq!(natural_frequencies_line(&stdout(&out)).len(), 1);
}

#[test]
fn compare_writes_its_table_and_refuses_an_unwritable_directory() {
    let scene = scenes_dir().join("paper_fig1_modified_mass.toml");
    let scene = scene.to_str().unwrap();
    let dir = TempDir::new("compare");
    let out_dir = dir.0.join("cmp");
    let out = ssn(&["compare", scene, "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let mut written: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    assert_eq!(written, vec!["accuracy_cost.csv", "accuracy_cost.svg"]);
    for method in ["ssn-hb", "penalty-hb", "lcp-lemke", "lcp-ssn", "march"] {
        assert!(
            stdout(&out).contains(method),
            "{method} missing from the table"
        );
    }

    // Output directory under a regular file: exit 3, nothing created.
    let file = dir.write("a-file", "x");
    let out = ssn(&[
        "compare",
        scene,
        "--out",
        file.join("sub").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(stderr(&out).contains("a-file"), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

/// `ssn sweep` with method lcp-ssn (the periodic LCP continued in its gaps and forces):
/// JSON with the documented fields, one entry per point, through the overhang to the end; the
/// last point, at the scene's forcing frequency beyond the overhang (one solution there),
/// equals what `ssn solve` finds by mesh-sequenced Newton from zero on the same scene.
#[test]
fn lcp_ssn_sweep_prints_a_branch_that_ends_on_the_fixed_frequency_solution() {
    let dir = TempDir::new("lcp-sweep");
    let scene = "title = \"lcp-ssn sweep\"\n\
        [rod]\nelements = 20\nmass = \"modified\"\n\
        [damping]\nzeta = 0.01\n\
        [forcing]\namplitude = 0.04\nomega_ratio = 1.1\n\
        [contact]\ngap = 0.5\n\
        [solver]\nmethod = \"lcp-ssn\"\ntime_samples = 128\n\
        [sweep]\nomega_ratio_from = 0.9\nomega_ratio_to = 1.1\n";
    let path = dir.write("lcp_sweep.toml", scene);
    let out = ssn(&["sweep", "--json", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let json: Value = serde_json::from_str(&stdout(&out)).expect("sweep JSON");
    assert_converged_sweep_json(&json);
    assert!(!json["folds"].as_array().expect("folds").is_empty());

    let out = ssn(&["solve", "--json", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let solve: Value = serde_json::from_str(&stdout(&out)).expect("solve JSON");
    let last = |key: &str| {
        json[key]
            .as_array()
            .and_then(|v| v.last())
            .and_then(Value::as_f64)
            .expect("a number")
    };
    assert!((last("omega") - solve["omega"].as_f64().unwrap()).abs() <= 1e-12);
    // Both are solutions of the same LCP to |F| <= 1e-10 (A of order 1): 1e-8 on the tip.
    for key in ["tip_max", "tip_min"] {
        let (a, b) = (last(key), solve[key].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-8, "{key}: sweep {a} vs solve {b}");
    }
}
