//! `ssn study` and `--set` as users run them: a scene key set on the command line gives the
//! run of the edited scene file; a study run in shards by separate processes and merged
//! gives the bytes of the tables of the whole run; a study killed while it runs and started
//! again redoes no finished case and ends with the table of an uninterrupted run; bad
//! studies, cases and directories are refused with exit code 2 and a message naming them.
//! The `[bladed_disk]` scene of the shipped mistuning study gives the run of the shipped
//! Matrix Market disk with the same blades, and its study table holds, row by row, what
//! `ssn solve --set` answers for that row's gap and mistuning pattern.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

#[path = "common/process.rs"]
mod process;

use process::{json_success, ssn};

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes")
        .join(name)
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
    if let Some(estimate) = map.get_mut("error_estimate").and_then(Value::as_object_mut) {
        estimate.remove("seconds");
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

/// `ssn study SCENE STUDY --out OUT EXTRA...`.
fn run_study(scene: &Path, study: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["study", path(scene), path(study), "--out", path(out)];
    args.extend_from_slice(extra);
    ssn(&args)
}

fn read(p: PathBuf) -> Vec<u8> {
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn shards_run_by_separate_processes_and_merged_give_the_tables_of_the_whole_run() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, study) = study_files(dir.path(), SMALL_STUDY);
    let whole = dir.path().join("whole");
    let o = run_study(&scene, &study, &whole, &[]);
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
    let o = run_study(&scene, &study, &out, &["--shard", "2/3"]);
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
                    name.starts_with("case-") && name.ends_with(".json") && p.is_file()
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

/// The study is stopped part way whatever the timing: a directory stands where case 3's
/// record goes, so the run (one worker, cases in order) cannot write more than the records
/// of cases 0, 1 and 2. Once they are there it is killed, while it works on case 3 or
/// after it ended at that record with an output error: either way exactly three whole
/// records, and the run started again (the directory removed) does the 117 others.
#[test]
fn a_killed_study_started_again_redoes_no_finished_case() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (scene, study) = study_files(dir.path(), LONG_STUDY);
    let finer = ["--set", "rod.elements=60", "--set", "solver.harmonics=30"];
    let out = dir.path().join("out");
    let in_the_way = out.join("cases").join("case-000003.json");
    std::fs::create_dir_all(&in_the_way).expect("a directory in the way of case 3");
    let mut run = Command::new(SSN)
        .args(["study", path(&scene), path(&study), "--out", path(&out)])
        .args(finer)
        .args(["--jobs", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the ssn binary runs");
    let started = Instant::now();
    while records(&out).len() < 3 {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "three cases never done"
        );
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
    assert_eq!(before.len(), 3, "no record beyond the directory in the way");
    std::fs::remove_dir(&in_the_way).expect("the directory in the way removed");
    let o = run_study(&scene, &study, &out, &finer);
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
    let o = run_study(&scene, &study, &whole, &finer);
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
        let o = run_study(&scene, &study_path, &out, &[]);
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
    let o = run_study(&scene, &study, &out, &["--shard", "1/12"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let other = dir.path().join("other.toml");
    std::fs::write(&other, SMALL_STUDY.replace("seed = 11", "seed = 12")).expect("write");
    let o = run_study(&scene, &other, &out, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("holds another study"),
        "{}",
        text(&o.stderr)
    );
    let o = run_study(&scene, &study, &out, &["--shard", "4/3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("1 <= I <= N"),
        "{}",
        text(&o.stderr)
    );
}

/// The generated block `name` of `docs/studies.md` (written by an example).
fn docs_block(name: &str) -> String {
    let page =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/studies.md"))
            .expect("docs/studies.md");
    let start = ssn::tables::block_start(name);
    let end = ssn::tables::block_end(name);
    let open = page.find(&start).expect("the block's opening line") + start.len();
    let close = open + page[open..].find(&end).expect("the block's closing line");
    page[open..close].to_string()
}

#[test]
fn the_throughput_page_holds_the_table_of_its_example() {
    let block = docs_block("study-throughput");
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

// The bladed disk of the shipped mistuning study.

/// A TOML list of numbers in shortest round-trip form (read back exactly).
fn toml_list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// The largest `max |u|` over the contacts of a solve's document (the table's
/// `contact_amplitude_max`).
fn contact_amplitude_max(doc: &Value) -> f64 {
    let contacts = doc["contacts"].as_array().expect("the contacts");
    contacts
        .iter()
        .map(|c| {
            let lo = c["displacement_min"].as_f64().expect("a minimum");
            let hi = c["displacement_max"].as_f64().expect("a maximum");
            lo.abs().max(hi.abs())
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// `|a - b| <= tol max(|a|, |b|, 1)`, refusing NaN.
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn the_disk_built_from_its_mistuning_is_the_shipped_matrix_market_disk() {
    // The shipped files hold the blades 1 + 0.02 sin(2.3 j) (`--example bladed_disk`).
    let mistuning: Vec<f64> = (0..100)
        .map(|j| semismooth_contact::structures::SHIPPED_MISTUNING * (2.3 * j as f64).sin())
        .collect();
    let set = format!("bladed_disk.mistuning={}", toml_list(&mistuning));
    let built = json_success(&ssn(&[
        "solve",
        path(&scene("bladed_disk_mistuned.toml")),
        "--set",
        &set,
        "--json",
    ]));
    let files = json_success(&ssn(&[
        "solve",
        path(&scene("bladed_disk_casing.toml")),
        "--json",
    ]));
    assert_eq!(built["converged"], Value::Bool(true), "{built}");
    // The files print every stiffness to 17 digits, so both structures are the same to
    // round-off; the solves then agree far inside the solver's 1e-10 tolerance scaled by
    // the conditioning of 100 near-resonant blades (1e-7 relative).
    for key in ["tip_max", "tip_min", "contact_force_mean", "omega"] {
        let (a, b) = (built[key].as_f64(), files[key].as_f64());
        let (a, b) = (a.expect(key), b.expect(key));
        assert!(close(a, b, 1e-7), "{key}: built {a}, files {b}");
    }
    let (a, b) = (contact_amplitude_max(&built), contact_amplitude_max(&files));
    assert!(
        close(a, b, 1e-7),
        "largest pad amplitude: built {a}, files {b}"
    );
}

#[test]
fn a_mistuning_study_table_holds_the_solve_of_each_case() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let small = dir.path().join("disk.toml");
    let text = std::fs::read_to_string(scene("bladed_disk_mistuned.toml"))
        .expect("shipped scene")
        .replace("blades = 100", "blades = 6");
    std::fs::write(&small, text).expect("write scene");
    let study = dir.path().join("study.toml");
    let study_text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/bladed_disk_mistuning.toml"),
    )
    .expect("shipped study")
    .replace("samples = 100", "samples = 3")
    .replace("size = 100", "size = 6")
    .replace("[0.5, 1.0, 1.5, 1e3]", "[0.5, 1e3]");
    std::fs::write(&study, study_text).expect("write study");
    let out = dir.path().join("out");
    let run = run_study(&small, &study, &out, &["--quiet"]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let csv = std::fs::read_to_string(out.join("results.csv")).expect("the table");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let at = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 6, "two gaps times three patterns");
    let mut amplitudes = Vec::new();
    for row in &rows {
        let gap: f64 = row[at("contact.gap")].parse().expect("a gap");
        let pattern: Vec<f64> = (0..6)
            .map(|j| {
                row[at(&format!("bladed_disk.mistuning[{j}]"))]
                    .parse()
                    .expect("a blade's mistuning")
            })
            .collect();
        assert!(pattern.iter().all(|d| d.abs() < 0.2), "{pattern:?}");
        let alone = json_success(&ssn(&[
            "solve",
            path(&small),
            "--set",
            &format!("contact.gap={gap:?}"),
            "--set",
            &format!("bladed_disk.mistuning={}", toml_list(&pattern)),
            "--json",
        ]));
        // The same problem solved twice (the study's case single-threaded, the program's
        // with its default threads): equal to round-off of a 1e-10 solve.
        for key in ["contact_amplitude_max", "tip_max", "tip_min"] {
            let table: f64 = row[at(key)].parse().expect("a number");
            let solve = match key {
                "contact_amplitude_max" => contact_amplitude_max(&alone),
                _ => alone[key].as_f64().expect(key),
            };
            assert!(
                close(table, solve, 1e-9),
                "{key}: table {table}, solve {solve}"
            );
        }
        assert_eq!(row[at("converged")], "true");
        amplitudes.push((
            gap,
            row[at("contact_amplitude_max")].parse::<f64>().unwrap(),
        ));
    }
    // The casing bounds what the linear disk (gap 1e3) exceeds: for every pattern the
    // largest amplitude with the casing at 0.5 is the smaller.
    for s in 0..3 {
        let (near, far) = (amplitudes[s], amplitudes[3 + s]);
        assert!(near.0 < far.0 && near.1 < far.1, "{near:?} {far:?}");
    }
}

#[test]
fn a_bad_mistuning_is_refused_naming_the_key() {
    let disk = scene("bladed_disk_mistuned.toml");
    for (set, key) in [
        ("bladed_disk.mistuning=[0.1, 0.2]", "bladed_disk.mistuning"),
        ("bladed_disk.blades=0", "bladed_disk.blades"),
    ] {
        let out = ssn(&["solve", path(&disk), "--set", set]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(key), "{set}: {err}");
    }
    let mut pattern = vec![0.0; 100];
    pattern[7] = -1.0;
    let set = format!("bladed_disk.mistuning={}", toml_list(&pattern));
    let out = ssn(&["solve", path(&disk), "--set", &set]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bladed_disk.mistuning[7]"), "{err}");
}

/// The mistuning page's quantiles (written by the `mistuning_study` example from 400 solves,
/// too long for a test) are checked for what a test can afford: every clearance of the
/// study file with all its samples converged, the quantiles in order, the last column the
/// 95 % quantile over the tuned amplitude, and the tuned amplitude the solve of the tuned
/// disk at that clearance (printed to 4 decimals: within 1e-4 relative).
#[test]
fn the_mistuning_page_holds_ordered_quantiles_over_the_tuned_disks_solves() {
    let block = docs_block("mistuning-study");
    let study = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/bladed_disk_mistuning.toml"),
    )
    .expect("the study file");
    let study: toml::Table = study.parse().expect("the study file's TOML");
    let samples = study["random"]["samples"].as_integer().expect("samples");
    let gaps: Vec<f64> = study["grid"]["contact.gap"]
        .as_array()
        .expect("the clearances")
        .iter()
        .map(|g| g.as_float().expect("a clearance"))
        .collect();
    let rows: Vec<Vec<&str>> = block
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| casing") && !l.starts_with("| ---"))
        .map(|l| {
            l.split('|')
                .map(str::trim)
                .filter(|c| !c.is_empty())
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), gaps.len(), "{block}");
    for (row, gap) in rows.iter().zip(&gaps) {
        let number = |i: usize| -> f64 { row[i].parse().expect("a number") };
        assert_eq!(number(0), *gap, "{row:?}");
        assert_eq!(row[2], format!("{samples} ({samples})"), "{row:?}");
        let quantiles: Vec<f64> = (3..8).map(number).collect();
        assert!(quantiles.windows(2).all(|w| w[0] <= w[1]), "{row:?}");
        let tuned = number(1);
        // The ratio is printed to 3 decimals (5e-4) from values printed to 4 (a further
        // 1e-4 at most for amplitudes above 0.5).
        assert!((number(8) - quantiles[3] / tuned).abs() <= 1e-3, "{row:?}");
        let set = format!("contact.gap={gap:?}");
        let solved = json_success(&ssn(&[
            "solve",
            path(&scene("bladed_disk_mistuned.toml")),
            "--set",
            &set,
            "--json",
        ]));
        let amplitude = contact_amplitude_max(&solved);
        assert!(
            close(tuned, amplitude, 1e-4),
            "gap {gap}: the page's tuned {tuned}, the solve {amplitude}"
        );
    }
}
