//! The program's contract on the files of `[model]` scenes, exports and states: every file a
//! run reads is an input no output replaces, matrix files are read only from regular files
//! and named with their line and value when wrong, exports read back (titles, banner) and
//! stay whole when two run at once, states are checked with checked arithmetic.

use std::path::{Path, PathBuf};
#[path = "common/exit_status.rs"]
mod exit_status;

use std::process::{Command, Output, Stdio};

#[path = "common/process.rs"]
mod process;
use exit_status::{assert_exit, assert_mentions, err};
use process::ssn;
use std::time::{Duration, Instant};

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

/// A three-dof chain `[model]` scene (K, M, f and `model.toml`) in a new directory.
fn chain(extra: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
    write(
        "K.mtx",
        "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n3 3 1\n",
    );
    write(
        "M.mtx",
        "%%MatrixMarket matrix coordinate real general\n3 3 2\n1 1 1\n2 2 1\n",
    );
    write(
        "f.mtx",
        "%%MatrixMarket matrix coordinate real general\n3 1 1\n2 1 1.0\n",
    );
    let scene = dir.path().join("model.toml");
    std::fs::write(
        &scene,
        format!(
            "title = \"chain\"\n[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\n\
             zeta = 0.02\n[forcing]\nvector = \"f.mtx\"\namplitude = 0.1\n{extra}\n\
             [[contact.point]]\ndof = 3\ngap = 0.05\n"
        ),
    )
    .unwrap();
    (dir, scene)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn an_output_naming_a_file_the_scene_reads_is_refused_and_the_file_kept() {
    let (dir, scene) = chain("");
    let k = dir.path().join("K.mtx");
    let f = dir.path().join("f.mtx");
    let before = (std::fs::read(&k).unwrap(), std::fs::read(&f).unwrap());
    let o = ssn(&["solve", s(&scene), "--csv", s(&k)]);
    assert_exit(&o, 2, "--csv on K.mtx");
    assert_mentions(&o, &["K.mtx", "--csv", "[model] stiffness"]);
    let o = ssn(&["solve", s(&scene), "--state", s(&f)]);
    assert_exit(&o, 2, "--state on f.mtx");
    assert_mentions(&o, &["f.mtx", "--state", "[forcing] vector"]);
    let o = ssn(&["sweep", s(&scene), "--svg", s(&k)]);
    assert_exit(&o, 2, "sweep --svg on K.mtx");
    // Exporting into the scene's own directory would replace its matrices.
    let o = ssn(&["export-model", s(&scene), s(dir.path())]);
    assert_exit(&o, 2, "export-model into the scene's directory");
    assert_mentions(&o, &["export-model", "an input is never replaced"]);
    assert_eq!(
        (std::fs::read(&k).unwrap(), std::fs::read(&f).unwrap()),
        before
    );
    assert!(!dir.path().join("scene.toml").exists());
    // The scene still loads.
    assert_exit(&ssn(&["scene-check", s(&scene)]), 0, "scene-check after");
}

/// Runs `ssn` with `args`; kills it and fails when it has not ended after `limit`.
fn ssn_within(args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(SSN)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("ssn {args:?} still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

#[test]
fn a_matrix_file_that_is_a_fifo_or_a_device_is_refused_without_reading_it() {
    let (dir, scene) = chain("");
    let k = dir.path().join("K.mtx");
    std::fs::remove_file(&k).unwrap();
    let fifo = Command::new("mkfifo").arg(&k).status().unwrap();
    assert!(fifo.success());
    // A FIFO nobody writes would block a reader forever.
    let o = ssn_within(&["solve", s(&scene)], Duration::from_secs(60));
    assert_exit(&o, 2, "K.mtx a FIFO");
    assert_mentions(&o, &["K.mtx", "not a regular file"]);
    std::fs::remove_file(&k).unwrap();
    // A device through a symbolic link would be read until memory runs out.
    std::os::unix::fs::symlink("/dev/zero", &k).unwrap();
    let o = ssn_within(&["solve", s(&scene)], Duration::from_secs(60));
    assert_exit(&o, 2, "K.mtx -> /dev/zero");
    assert_mentions(&o, &["K.mtx", "not a regular file"]);
}

#[test]
fn matrix_market_defects_and_hostile_sizes_are_named_with_line_and_value() {
    let c = "%%MatrixMarket matrix coordinate real general\n";
    for (file, text, words) in [
        (
            "K.mtx",
            format!("{c}1000000000 1000000000 1\n1 1 1\n"),
            &["K.mtx", "line 2", "1000000000 rows", "at most"][..],
        ),
        (
            "K.mtx",
            format!("{c}3 3 1\n0 1 1\n"),
            &["line 3", "row index `0`"],
        ),
        ("K.mtx", format!("{c}3 3 1\n-1 1 1\n"), &["line 3", "`-1`"]),
        (
            "K.mtx",
            "%%MatrixMarket matrix coordinate pattern general\n3 3 1\n1 1\n".into(),
            &["line 1", "`pattern`"],
        ),
        (
            "M.mtx",
            format!("{c}3 3 18446744073709551615\n"),
            &["M.mtx", "line 2", "at most 9"],
        ),
        (
            "f.mtx",
            format!("{c}3 1 1\n2 1 1e300\n"),
            &["f.mtx", "line 3", "1e300", "at most 1e100"],
        ),
        (
            "K.mtx",
            format!("{c}3 3 3\n1 1 2e300\n2 2 1\n3 3 1\n"),
            &["line 3", "at most 1e100"],
        ),
    ] {
        let (dir, scene) = chain("");
        std::fs::write(dir.path().join(file), text).unwrap();
        let o = ssn(&["solve", s(&scene)]);
        assert_exit(&o, 2, file);
        assert_mentions(&o, words);
    }
    // The load amplitude times a load entry obeys the rod's amplitude rule.
    let (dir, scene) = chain("");
    std::fs::write(dir.path().join("f.mtx"), format!("{c}3 1 1\n2 1 1e99\n")).unwrap();
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("amplitude = 0.1", "amplitude = 1e10");
    std::fs::write(&scene, text).unwrap();
    let o = ssn(&["solve", s(&scene)]);
    assert_exit(&o, 2, "amplitude x f");
    assert_mentions(&o, &["load amplitude", "f.mtx", "at most 1e100"]);
}

#[test]
fn an_export_reads_back_with_any_title_and_the_standard_banner() {
    let (_dir, scene) = chain("");
    // No-break space, combining accent, DEL, ESC, zero-width space, right-to-left override,
    // a quote and a backslash.
    let title = "a\u{a0}e\u{301}\u{7f}\u{1b}[1m\u{200b}\u{202e}\"\\";
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "title = \"chain\"",
        &format!("title = {}", toml_string(title)),
    );
    std::fs::write(&scene, text).unwrap();
    let out = tempfile::tempdir().unwrap();
    let o = ssn(&["export-model", s(&scene), s(out.path())]);
    assert_exit(&o, 0, "export");
    for m in ["K.mtx", "M.mtx", "f.mtx", "D.mtx"] {
        let text = std::fs::read_to_string(out.path().join(m)).unwrap();
        assert!(
            text.starts_with("%%MatrixMarket matrix coordinate real general\n"),
            "{m}: {}",
            text.lines().next().unwrap_or_default()
        );
    }
    let exported = std::fs::read_to_string(out.path().join("scene.toml")).unwrap();
    let doc: toml::Table = exported.parse().expect("the exported scene is TOML");
    assert_eq!(
        doc["title"].as_str(),
        Some(format!("{title} (exported)").as_str())
    );
    let o = ssn(&["scene-check", s(&out.path().join("scene.toml"))]);
    assert_exit(&o, 0, "the export loads");
    assert!(!o.stdout.contains(&0x1b), "raw ESC printed by scene-check");
}

/// `text` as a TOML basic string.
fn toml_string(text: &str) -> String {
    toml::Value::String(text.into()).to_string()
}

#[test]
fn concurrent_exports_into_one_directory_leave_one_scene_whole() {
    // Two structures of different sizes: every file of the directory must be of one of them.
    let rods: Vec<(tempfile::TempDir, PathBuf, usize)> = [7, 11]
        .iter()
        .map(|&n| {
            let dir = tempfile::tempdir().unwrap();
            let scene = dir.path().join("rod.toml");
            std::fs::write(
                &scene,
                format!(
                    "title = \"rod {n}\"\n[rod]\nelements = {n}\n[damping]\nzeta = 0.01\n\
                     [forcing]\namplitude = 0.1\n[contact]\ngap = 0.5\n"
                ),
            )
            .unwrap();
            (dir, scene, n)
        })
        .collect();
    for trial in 0..8 {
        let out = tempfile::tempdir().unwrap();
        let children: Vec<_> = rods
            .iter()
            .map(|(_, scene, _)| {
                Command::new(SSN)
                    .args(["export-model", s(scene), s(out.path())])
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let o = c.wait_with_output().unwrap();
            assert_exit(&o, 0, "a concurrent export");
        }
        let scene = std::fs::read_to_string(out.path().join("scene.toml")).unwrap();
        let n = rods
            .iter()
            .map(|r| r.2)
            .find(|n| scene.contains(&format!("rod {n} (exported)")))
            .expect("a title of one of the rods");
        for m in ["K.mtx", "M.mtx", "D.mtx", "f.mtx"] {
            let text = std::fs::read_to_string(out.path().join(m)).unwrap();
            let size = text.lines().nth(1).unwrap();
            assert!(
                size.starts_with(&format!("{n} ")),
                "trial {trial}: {m} is `{size}` beside the scene of rod {n}"
            );
        }
    }
}

#[test]
fn a_state_with_a_hostile_size_or_values_is_refused_naming_the_field() {
    let (dir, scene) = chain("");
    let state = dir.path().join("state.json");
    let o = ssn(&["solve", s(&scene), "--state", s(&state)]);
    assert_exit(&o, 0, "state written");
    let good: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&state).unwrap()).unwrap();
    for (field, value, words) in [
        (
            "harmonics",
            serde_json::json!(9223372036854775808u64),
            &["harmonics", "0..=2000"][..],
        ),
        (
            "harmonics",
            serde_json::json!(u64::MAX),
            &["harmonics", "18446744073709551615", "0..=2000"],
        ),
        ("dofs", serde_json::json!(u64::MAX), &["dofs", "overflows"]),
    ] {
        let mut doc = good.clone();
        doc[field] = value;
        let path = dir.path().join(format!("bad_{field}.json"));
        std::fs::write(&path, doc.to_string()).unwrap();
        let o = ssn(&["solve", s(&scene), "--start", s(&path)]);
        assert_exit(&o, 2, field);
        assert_mentions(&o, words);
    }
    let mut doc = good.clone();
    doc["displacement"][0] = serde_json::json!(1.7e308);
    let path = dir.path().join("huge.json");
    std::fs::write(&path, doc.to_string()).unwrap();
    let o = ssn(&["solve", s(&scene), "--start", s(&path), "--json"]);
    assert_exit(&o, 2, "a coefficient of 1.7e308");
    assert_mentions(&o, &["displacement[0]", "at most 1e100"]);
    let o = ssn(&["solve", s(&scene), "--start", s(&state), "--entry", "-1"]);
    assert_exit(&o, 2, "--entry -1");
    assert_mentions(&o, &["--entry", "`-1`", "allowed 1, 2"]);
}

#[test]
fn scene_keys_are_named_as_the_scene_writes_them() {
    // Two stops on one dof without room between them: the entries and the dof, 1-based.
    let (_dir, scene) = chain("");
    let text = std::fs::read_to_string(&scene).unwrap()
        + "[[contact.point]]\ndof = 3\ngap = -0.06\ndirection = -1\n";
    std::fs::write(&scene, text).unwrap();
    let o = ssn(&["solve", s(&scene)]);
    assert_exit(&o, 2, "no clearance");
    assert_mentions(
        &o,
        &[
            "contact.point.gap",
            "entry 2",
            "entry 1",
            "dof 3",
            "sum is > 0",
        ],
    );
    // A rod scene's `direction`.
    let dir = tempfile::tempdir().unwrap();
    let rod = dir.path().join("rod.toml");
    std::fs::write(
        &rod,
        "[rod]\nelements = 10\n[forcing]\namplitude = 0.1\n[[contact.point]]\nnode = 10\n\
         gap = 0.5\ndirection = -1\n",
    )
    .unwrap();
    let o = ssn(&["solve", s(&rod)]);
    assert_exit(&o, 2, "direction in a rod scene");
    assert_mentions(&o, &["contact.point.direction"]);
    // `ssn solutions` outside the window names the scene's own frequency key.
    std::fs::write(
        &rod,
        "[rod]\nelements = 10\nmass = \"modified\"\n[damping]\nzeta = 0.01\n[forcing]\n\
         amplitude = 0.1\nomega = 3.0\n[contact]\ngap = 0.5\n[sweep]\nomega_ratio_from = 0.5\n\
         omega_ratio_to = 0.9\n",
    )
    .unwrap();
    let o = ssn(&["solutions", s(&rod)]);
    assert_exit(&o, 2, "solutions outside the window");
    assert_mentions(&o, &["forcing.omega` = 3", "[0.5, 0.9]"]);
    assert!(!err(&o).contains("omega_ratio` ="), "{}", err(&o));
}

#[test]
fn a_missing_file_with_control_characters_and_a_deep_table_are_named_printably() {
    // A matrix file named with an ESC that does not exist: the name is escaped.
    let (dir, scene) = chain("");
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("\"M.mtx\"", "\"M\\u001b[31m.mtx\"");
    std::fs::write(&scene, text).unwrap();
    let o = ssn(&["scene-check", s(&scene)]);
    assert_exit(&o, 2, "missing file with ESC");
    assert!(!o.stderr.contains(&0x1b), "raw ESC: {}", err(&o));
    assert_mentions(&o, &["M\\u{1b}[31m.mtx"]);
    // A table header nested 5,000 deep: toml's limit, placed on its line.
    let deep = dir.path().join("deep.toml");
    std::fs::write(&deep, format!("title = \"t\"\n[{}a]\n", "a.".repeat(5000))).unwrap();
    let o = ssn(&["solve", s(&deep)]);
    assert_exit(&o, 2, "deep header");
    assert_mentions(&o, &["deep.toml", "at line 2", "5001 deep"]);
}
