//! Studies and `--set` refuse what they cannot run before anything runs (exit 2, the key
//! named, in well under a second): keys deeper than any scene key, grids and random
//! samples past the case and value limits (with the exact count), a key varied in two
//! places, a sweep without `[sweep]`, bad limits, worker counts past the maximum; a merge
//! takes only whole records of its own study and a manifest of a sensible size; two
//! studies started together on one new directory never mix their records; an interrupted
//! study says what it kept.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

#[path = "common/process.rs"]
mod process;

use process::ssn;

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

/// A small rod without `[sweep]`: each solve takes milliseconds.
const ROD: &str = "[rod]\nelements = 10\nmass = \"modified\"\n[damping]\nzeta = 0.01\n\
                   [forcing]\namplitude = 0.04\n[contact]\ngap = 0.5\n[solver]\nharmonics = 5\n";

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn path(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 temporary path")
}

/// The rod scene and a study file of `study` in `dir`.
fn files(dir: &Path, study: &str) -> (PathBuf, PathBuf) {
    let scene = dir.join("rod.toml");
    std::fs::write(&scene, ROD).expect("write scene");
    let study_path = dir.join("study.toml");
    std::fs::write(&study_path, study).expect("write study");
    (scene, study_path)
}

/// Runs `ssn study` on `study` with `extra` arguments and asserts it is refused (exit 2)
/// up front: within a second, naming every word of `named`, writing no directory.
fn refused_up_front(study: &str, extra: &[&str], env: &[(&str, &str)], named: &[&str]) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, study_path) = files(dir.path(), study);
    let out = dir.path().join("out");
    let started = Instant::now();
    let o = Command::new(SSN)
        .args([
            "study",
            path(&scene),
            path(&study_path),
            "--out",
            path(&out),
        ])
        .args(extra)
        .envs(env.iter().copied())
        .output()
        .expect("the ssn binary runs");
    let seconds = started.elapsed().as_secs_f64();
    let message = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{study}: {message}");
    assert!(seconds < 1.0, "{study}: refused after {seconds} s");
    for word in named {
        assert!(message.contains(word), "{study}: `{word}` in {message}");
    }
    assert!(!out.exists(), "{study}: nothing written");
}

#[test]
fn keys_deeper_than_any_scene_key_are_refused_not_a_stack_overflow() {
    let deep = vec!["a"; 60_000].join(".");
    refused_up_front(
        &format!("[grid]\n\"{deep}\" = [1]\n"),
        &[],
        &[],
        &["[grid]", "at most 8 parts", "60000"],
    );
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, _) = files(dir.path(), "");
    let o = ssn(&["solve", path(&scene), "--set", &format!("{deep}=1")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("--set"), "{}", text(&o.stderr));
}

#[test]
fn grids_past_the_case_limit_are_refused_with_their_exact_count() {
    let grid = |keys: usize, values: &str| {
        let lines: Vec<String> = (0..keys)
            .map(|k| format!("\"forcing.k{k}\" = {values}"))
            .collect();
        format!("[grid]\n{}\n", lines.join("\n"))
    };
    // 2^64 cases: a wrapped product would be 0.
    refused_up_front(
        &grid(64, "[1, 2]"),
        &[],
        &[],
        &["18446744073709551616 cases", "at most 1000000 cases"],
    );
    // 3^41 = 36472996377170786403, more than 2^64.
    refused_up_front(
        &grid(41, "[1, 2, 3]"),
        &[],
        &[],
        &["36472996377170786403 cases"],
    );
}

#[test]
fn random_studies_past_the_case_or_value_limit_are_refused_up_front() {
    let random = |samples: &str, size: &str| {
        format!(
            "[random]\nsamples = {samples}\nseed = 1\n[random.keys.\"forcing.amplitude\"]\n\
             distribution = \"uniform\"\nlow = 0.01\nhigh = 0.02\n{size}"
        )
    };
    refused_up_front(
        &random("10000000", ""),
        &[],
        &[],
        &["random.samples", "1..=1000000"],
    );
    refused_up_front(
        &random("1000000", "size = 100\n"),
        &[],
        &[],
        &["100000000 values", "at most 10000000 values"],
    );
}

#[test]
fn a_key_varied_in_two_places_is_refused() {
    let cases = [
        (
            "[grid]\n\"forcing.amplitude\" = [0.01]\n[[case]]\n\"forcing.amplitude\" = 0.02\n",
            "also in [grid]",
        ),
        (
            "[grid]\n\" forcing.amplitude\" = [0.01]\n[[case]]\n\"forcing.amplitude\" = 0.02\n",
            "also in [grid]",
        ),
        (
            "[[case]]\n\"forcing.amplitude\" = 0.01\n\" forcing . amplitude\" = 0.02\n",
            "twice in one table",
        ),
        (
            "[grid]\n\"forcing.amplitude\" = [0.01]\n[random]\nsamples = 2\nseed = 1\n\
             [random.keys.\"forcing.amplitude\"]\ndistribution = \"normal\"\nstd = 0.1\n",
            "also in [grid]",
        ),
    ];
    for (study, named) in cases {
        refused_up_front(study, &[], &[], &[named, "forcing.amplitude"]);
    }
}

#[test]
fn what_every_case_would_refuse_is_refused_once_up_front() {
    refused_up_front(
        "run = \"sweep\"\n[grid]\n\"forcing.amplitude\" = [0.01, 0.02]\n",
        &[],
        &[],
        &["case 0", "[sweep]"],
    );
    let study = "[grid]\n\"forcing.amplitude\" = [0.01, 0.02]\n";
    refused_up_front(study, &[], &[("SSN_WORK_LIMIT", "x")], &["SSN_WORK_LIMIT"]);
    refused_up_front(
        study,
        &[],
        &[("SSN_MEMORY_LIMIT", "-5")],
        &["SSN_MEMORY_LIMIT"],
    );
    refused_up_front(study, &["--jobs", "65535"], &[], &["--jobs", "1024"]);
    refused_up_front(study, &["--jobs", "-1"], &[], &["--jobs"]);
}

/// A study of two cases run to its end in `out`.
fn finished_study(dir: &Path, out: &Path) {
    let (scene, study) = files(dir, "[grid]\n\"forcing.amplitude\" = [0.01, 0.02]\n");
    let o = ssn(&["study", path(&scene), path(&study), "--out", path(out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

/// `ssn study merge` of `out`, asserted refused naming every word of `named`.
fn merge_refused(out: &Path, named: &[&str]) {
    let started = Instant::now();
    let o = ssn(&["study", "merge", path(out)]);
    let message = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{message}");
    assert!(started.elapsed() < Duration::from_secs(1));
    for word in named {
        assert!(message.contains(word), "`{word}` in {message}");
    }
}

#[test]
fn merge_refuses_a_manifest_case_count_out_of_range() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = dir.path().join("out");
    finished_study(dir.path(), &out);
    let manifest = out.join("study.json");
    let original = std::fs::read_to_string(&manifest).expect("the manifest");
    for cases in ["18446744073709551615", "200000000", "0"] {
        std::fs::write(
            &manifest,
            original.replace("\"cases\": 2,", &format!("\"cases\": {cases},")),
        )
        .expect("edit the manifest");
        merge_refused(&out, &["`cases` is", cases, "allowed 1..=1000000"]);
    }
    std::fs::write(&manifest, original).expect("restore the manifest");
    let o = ssn(&["study", "merge", path(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

#[test]
fn merge_takes_only_whole_records_of_its_own_study() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = dir.path().join("out");
    finished_study(dir.path(), &out);
    let record_path = out.join("cases").join("case-000001.json");
    let record: Value =
        serde_json::from_str(&std::fs::read_to_string(&record_path).expect("a record"))
            .expect("a JSON record");
    // The same case of another study (its identity differs).
    let mut other = record.clone();
    other["study"] = "0123456789abcdef".into();
    // Only the case number.
    let empty = serde_json::json!({ "case": 1 });
    for (bad, named) in [
        (other, "another study"),
        (empty, "another study"),
        (
            {
                let mut r = record.clone();
                r.as_object_mut().expect("an object").remove("result");
                r
            },
            "not a whole record",
        ),
    ] {
        std::fs::write(&record_path, bad.to_string()).expect("replace the record");
        merge_refused(&out, &[named, "case-000001.json"]);
    }
    // A run of the study replaces the foreign record, and the merge then succeeds.
    finished_study(dir.path(), &out);
    let o = ssn(&["study", "merge", path(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

#[test]
fn two_studies_started_together_on_one_new_directory_never_mix() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, _) = files(dir.path(), "");
    let studies: Vec<PathBuf> = ["0.01, 0.02", "0.03, 0.04"]
        .iter()
        .enumerate()
        .map(|(k, values)| {
            let p = dir.path().join(format!("study{k}.toml"));
            std::fs::write(&p, format!("[grid]\n\"forcing.amplitude\" = [{values}]\n"))
                .expect("write study");
            p
        })
        .collect();
    for trial in 0..6 {
        let out = dir.path().join(format!("out{trial}"));
        let runs: Vec<_> = studies
            .iter()
            .map(|study| {
                Command::new(SSN)
                    .args(["study", path(&scene), path(study), "--out", path(&out)])
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .expect("the ssn binary runs")
            })
            .collect();
        let codes: Vec<Option<i32>> = runs
            .into_iter()
            .map(|r| r.wait_with_output().expect("a study ends").status.code())
            .collect();
        let mut sorted = codes.clone();
        sorted.sort();
        assert_eq!(sorted, [Some(0), Some(2)], "trial {trial}: {codes:?}");
        // The table holds the values of one study only.
        let csv = std::fs::read_to_string(out.join("results.csv")).expect("the table");
        let winner = if codes[0] == Some(0) { 0 } else { 1 };
        let values: Vec<&str> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(1).expect("a value"))
            .collect();
        let expected = [["0.01", "0.02"], ["0.03", "0.04"]][winner];
        assert_eq!(values, expected, "trial {trial}");
    }
}

#[test]
fn an_interrupted_study_says_it_kept_the_records_of_the_cases_done() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let values: Vec<String> = (0..400)
        .map(|k| format!("{}", 0.9 + 0.001 * k as f64))
        .collect();
    let (scene, study) = files(
        dir.path(),
        &format!(
            "[grid]\n\"forcing.omega_ratio\" = [{}]\n",
            values.join(", ")
        ),
    );
    let out = dir.path().join("out");
    let run = Command::new(SSN)
        .args(["study", path(&scene), path(&study), "--out", path(&out)])
        .args([
            "--jobs",
            "1",
            "--set",
            "rod.elements=60",
            "--set",
            "solver.harmonics=30",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the ssn binary runs");
    let started = Instant::now();
    while !out.join("cases").join("case-000001.json").exists() {
        assert!(started.elapsed() < Duration::from_secs(60), "no case done");
        std::thread::sleep(Duration::from_millis(2));
    }
    let killed = Command::new("kill")
        .args(["-INT", &run.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(killed.success());
    let o = run.wait_with_output().expect("the study ends");
    let message = text(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{message}");
    assert!(
        message.contains("records of the cases done are kept")
            && !message.contains("no output written"),
        "{message}"
    );
    assert!(out.join("cases").join("case-000000.json").exists());
}
