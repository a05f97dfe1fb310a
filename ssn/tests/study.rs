//! `ssn study` and `--set` as users run them: a scene key set on the command line gives the
//! run of the edited scene file; a study run in shards by separate processes and merged
//! gives the bytes of the tables of the whole run; a study killed while it runs and started
//! again redoes no finished case and ends with the table of an uninterrupted run; bad
//! studies, cases and directories are refused with exit code 2 and a message naming them.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes")
        .join(name)
}

fn ssn(args: &[&str]) -> Output {
    Command::new(SSN)
        .args(args)
        .output()
        .expect("the ssn binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn path(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 temporary path")
}

/// The document of a run without its wall times and its scene path (the only fields that
/// differ between two runs of one problem from two files).
fn comparable(o: &Output) -> Value {
    let mut doc: Value = serde_json::from_slice(&o.stdout).expect("a JSON document");
    let map = doc.as_object_mut().expect("an object");
    for key in ["solve_seconds", "stability_seconds", "scene"] {
        map.remove(key);
    }
    doc
}

#[test]
fn set_on_the_command_line_gives_the_run_of_the_edited_scene_file() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let original = scene("paper_fig1_modified_mass.toml");
    let edited = std::fs::read_to_string(&original)
        .expect("shipped scene")
        .replace("gap = 0.5", "gap = 0.3")
        .replace("harmonics = 20", "harmonics = 12")
        .replace("amplitude = 0.04", "amplitude = 0.06");
    let edited_path = dir.path().join("edited.toml");
    std::fs::write(&edited_path, edited).expect("write scene");
    let overridden = ssn(&[
        "solve",
        path(&original),
        "--set",
        "contact.gap=0.3",
        "--set",
        "solver.harmonics=12",
        "--set",
        "forcing.amplitude=0.06",
        "--json",
    ]);
    let from_file = ssn(&["solve", path(&edited_path), "--json"]);
    assert_eq!(
        overridden.status.code(),
        Some(0),
        "{}",
        text(&overridden.stderr)
    );
    assert_eq!(
        from_file.status.code(),
        Some(0),
        "{}",
        text(&from_file.stderr)
    );
    // One library, one problem, one process each: the same numbers bit for bit.
    assert_eq!(comparable(&overridden), comparable(&from_file));
    // The tip presses on the stop at 0.3 (the truncated series penetrates a little): the
    // overrides changed the problem.
    let tip_max = comparable(&overridden)["tip_max"].as_f64().unwrap();
    assert!((0.3..0.31).contains(&tip_max), "{tip_max}");
}

#[test]
fn a_bad_set_is_refused_like_the_scene_file_naming_the_key() {
    let original = scene("paper_fig1_modified_mass.toml");
    let cases = [
        ("solver.harmonics=0", "1..=2000"),
        ("contact.gapp=0.3", "gapp"),
        ("contact.gap=wide", "contact.gap"),
        ("forcing=1", "forcing"),
    ];
    for (set, named) in cases {
        let o = ssn(&["solve", path(&original), "--set", set]);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", text(&o.stderr));
        let message = text(&o.stderr);
        assert!(
            message.contains(named) && message.contains("paper_fig1_modified_mass.toml"),
            "{set}: {message}"
        );
    }
    let o = ssn(&["solve", path(&original), "--set", "no-equals-sign"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("key=value"), "{}", text(&o.stderr));
}

/// 3 gaps x 2 frequencies x 2 random dampings: 12 solves of the modified-mass rod.
const SMALL_STUDY: &str = r#"
run = "solve"
[grid]
"contact.gap" = [0.2, 0.3, 0.5]
"forcing.omega_ratio" = [1.0, 1.1]
[random]
samples = 2
seed = 11
[random.keys."damping.zeta"]
distribution = "uniform"
low = 0.005
high = 0.02
"#;

fn study_files(dir: &Path, study: &str) -> (PathBuf, PathBuf) {
    let study_path = dir.join("study.toml");
    std::fs::write(&study_path, study).expect("write study");
    (scene("paper_fig1_modified_mass.toml"), study_path)
}

fn read(p: PathBuf) -> Vec<u8> {
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn shards_run_by_separate_processes_and_merged_give_the_tables_of_the_whole_run() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, study) = study_files(dir.path(), SMALL_STUDY);
    let whole = dir.path().join("whole");
    let o = ssn(&["study", path(&scene), path(&study), "--out", path(&whole)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let sharded = dir.path().join("sharded");
    // Three processes at once on one directory, as the tasks of a job array.
    let shards: Vec<_> = (1..=3)
        .map(|i| {
            Command::new(SSN)
                .args(["study", path(&scene), path(&study), "--out", path(&sharded)])
                .args(["--shard", &format!("{i}/3"), "--jobs", "1"])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("the ssn binary runs")
        })
        .collect();
    for shard in shards {
        let o = shard.wait_with_output().expect("a shard ends");
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
        assert!(text(&o.stdout).contains("4 run now"), "{}", text(&o.stdout));
    }
    // A shard writes no table: only the merge does.
    assert!(!sharded.join("results.csv").exists());
    let o = ssn(&["study", "merge", path(&sharded)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("merged 12 cases"),
        "{}",
        text(&o.stdout)
    );
    let csv = read(whole.join("results.csv"));
    assert_eq!(read(sharded.join("results.csv")), csv);
    assert_eq!(
        read(sharded.join("results.parquet")),
        read(whole.join("results.parquet"))
    );
    // The table: a header and 12 rows, the varied keys and the quantities, every case
    // converged; the random damping is one of two values per sample, equal across the grid
    // (common random numbers).
    let csv = text(&csv);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 13);
    assert!(lines[0].starts_with(
        "case,contact.gap,forcing.omega_ratio,damping.zeta,converged,termination,error,"
    ));
    let zeta: Vec<&str> = lines[1..]
        .iter()
        .map(|l| l.split(',').nth(3).unwrap())
        .collect();
    for pair in zeta.chunks(2) {
        assert_eq!(pair, &zeta[..2]);
    }
    assert_ne!(zeta[0], zeta[1]);
    assert!(lines[1..].iter().all(|l| l.contains(",true,converged,")));
}

#[test]
fn merge_before_every_shard_is_done_names_the_missing_cases() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, study) = study_files(dir.path(), SMALL_STUDY);
    let out = dir.path().join("out");
    let o = ssn(&[
        "study",
        path(&scene),
        path(&study),
        "--out",
        path(&out),
        "--shard",
        "2/3",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = ssn(&["study", "merge", path(&out)]);
    assert_eq!(o.status.code(), Some(2));
    let message = text(&o.stderr);
    assert!(
        message.contains("8 of 12 cases not done yet") && message.contains("0, 2, 3, 5"),
        "{message}"
    );
    assert!(!out.join("results.csv").exists());
}

/// 120 solves of a finer rod, one at a time: long enough to be killed while it runs.
const LONG_STUDY: &str = r#"
run = "solve"
[grid]
"contact.gap" = [0.2, 0.25, 0.3, 0.35, 0.4, 0.45]
"forcing.omega_ratio" = [0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2, 1.25, 1.3, 1.35,
                         1.4, 1.45, 1.5, 1.55, 1.6, 1.65, 1.7, 1.75, 1.8, 1.85]
"#;

fn records(dir: &Path) -> Vec<(PathBuf, u64)> {
    let mut found: Vec<(PathBuf, u64)> = std::fs::read_dir(dir.join("cases"))
        .map(|entries| {
            entries
                .map(|e| e.expect("directory entry").path())
                .filter(|p| {
                    let name = p.file_name().unwrap().to_string_lossy();
                    name.starts_with("case-") && name.ends_with(".json")
                })
                .map(|p| {
                    let inode = std::fs::metadata(&p).expect("a record").ino();
                    (p, inode)
                })
                .collect()
        })
        .unwrap_or_default();
    found.sort();
    found
}

#[test]
fn a_killed_study_started_again_redoes_no_finished_case() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, study) = study_files(dir.path(), LONG_STUDY);
    let finer = ["--set", "rod.elements=60", "--set", "solver.harmonics=30"];
    let out = dir.path().join("out");
    let mut run = Command::new(SSN)
        .args(["study", path(&scene), path(&study), "--out", path(&out)])
        .args(finer)
        .args(["--jobs", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the ssn binary runs");
    let started = Instant::now();
    while records(&out).len() < 3 && started.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(2));
    }
    run.kill().expect("the study is killed (SIGKILL)");
    run.wait().expect("the killed study ends");
    let before = records(&out);
    assert!(
        (3..120).contains(&before.len()),
        "{} records when killed: the study must be stopped part way",
        before.len()
    );
    let o = Command::new(SSN)
        .args(["study", path(&scene), path(&study), "--out", path(&out)])
        .args(finer)
        .output()
        .expect("the ssn binary runs");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let done = before.len();
    assert!(
        text(&o.stdout).contains(&format!("{done} already done, {} run now", 120 - done)),
        "{}",
        text(&o.stdout)
    );
    // Every record of the killed run is the same file (its inode: a re-run case would be
    // written anew by an atomic rename).
    let after = records(&out);
    assert_eq!(after.len(), 120);
    for record in &before {
        assert!(
            after.contains(record),
            "{} was written again",
            record.0.display()
        );
    }
    // And the table is that of a run that was never interrupted.
    let whole = dir.path().join("whole");
    let o = Command::new(SSN)
        .args(["study", path(&scene), path(&study), "--out", path(&whole)])
        .args(finer)
        .output()
        .expect("the ssn binary runs");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(
        read(out.join("results.csv")),
        read(whole.join("results.csv"))
    );
}

#[test]
fn bad_studies_cases_and_directories_are_refused_naming_them() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let scene = scene("paper_fig1_modified_mass.toml");
    let cases = [
        ("run = \"march\"\n", "run"),
        ("[grid]\n\"contact.gap\" = []\n", "contact.gap"),
        ("[grid]\n\"contact.gap\" = 0.5\n", "contact.gap"),
        (
            "[grid]\n\"contact.gap\" = [0.5, \"wide\"]\n",
            "case 1 (contact.gap=\"wide\")",
        ),
        ("[[case]]\n\"solver.harmonic\" = 4\n", "harmonic"),
        (
            "[random]\nsamples = 0\nseed = 1\n[random.keys.\"contact.gap\"]\ndistribution = \"normal\"\nstd = 0.1\n",
            "random.samples",
        ),
        (
            "[random]\nsamples = 3\nseed = 1\n[random.keys.\"contact.gap\"]\ndistribution = \"uniform\"\nlow = 1.0\nhigh = 0.5\n",
            "high",
        ),
        ("unknown = 1\n", "unknown"),
    ];
    for (study, named) in cases {
        let study_path = dir.path().join("bad.toml");
        std::fs::write(&study_path, study).expect("write study");
        let out = dir.path().join("bad-out");
        let o = ssn(&[
            "study",
            path(&scene),
            path(&study_path),
            "--out",
            path(&out),
        ]);
        assert_eq!(o.status.code(), Some(2), "{study}: {}", text(&o.stderr));
        let message = text(&o.stderr);
        assert!(
            message.contains(named) && message.contains("bad.toml"),
            "{study}: {message}"
        );
        // Nothing ran, nothing was written.
        assert!(!out.exists(), "{study}");
    }
    // A directory that holds another study is not mixed with this one.
    let (scene, study) = study_files(dir.path(), SMALL_STUDY);
    let out = dir.path().join("out");
    let o = ssn(&[
        "study",
        path(&scene),
        path(&study),
        "--out",
        path(&out),
        "--shard",
        "1/12",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let other = dir.path().join("other.toml");
    std::fs::write(&other, SMALL_STUDY.replace("seed = 11", "seed = 12")).expect("write");
    let o = ssn(&["study", path(&scene), path(&other), "--out", path(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("holds another study"),
        "{}",
        text(&o.stderr)
    );
    let o = ssn(&[
        "study",
        path(&scene),
        path(&study),
        "--out",
        path(&out),
        "--shard",
        "4/3",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("1 <= I <= N"),
        "{}",
        text(&o.stderr)
    );
}

/// The generated block of `docs/studies.md` written by the `study_throughput` example.
fn throughput_block() -> String {
    let page =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/studies.md"))
            .expect("docs/studies.md");
    let start = ssn::tables::block_start("study-throughput");
    let end = ssn::tables::block_end("study-throughput");
    let open = page.find(&start).expect("the block's opening line") + start.len();
    let close = open + page[open..].find(&end).expect("the block's closing line");
    page[open..close].to_string()
}

#[test]
fn the_throughput_page_holds_the_table_of_its_example() {
    let block = throughput_block();
    assert!(
        block.contains("cargo run --release -p ssn --example study_throughput -- --write"),
        "{block}"
    );
    // Every case of the measured study converged, and each row has a positive per-case
    // time and rate (the wall times themselves vary from run to run and are not compared).
    assert!(
        block.contains("1000 solves of the canonical rod"),
        "{block}"
    );
    assert!(block.contains("; 1000 converged."), "{block}");
    let rows: Vec<&str> = block
        .lines()
        .filter(|l| {
            l.starts_with("| ") && !l.starts_with("| measurement") && !l.starts_with("| ---")
        })
        .collect();
    assert_eq!(rows.len(), 4, "{block}");
    for row in rows {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let ms: f64 = cells[2].trim_end_matches(" ms").parse().expect("a time");
        let rate: f64 = cells[3].parse().expect("a rate");
        assert!(ms > 0.0 && rate > 0.0, "{row}");
    }
    assert!(block.contains("Speed-up of 2 threads over 1"), "{block}");
}
