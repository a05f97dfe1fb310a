//! Commands that solve nothing are not refused by a solve's estimates: `scene-check` of
//! scenes whose solve would need a dense factorization of tens of gigabytes checks them in
//! about a second, `export-model` exports them, and an export that fails leaves no new
//! directory behind; `ssn compare` decides first which methods apply and skips the others
//! with a line instead of refusing the whole comparison at its end.

use std::path::Path;
use std::process::{Command, Output};
use std::time::Instant;

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(SSN)
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the ssn binary runs")
}

/// A 2,000-element rod with a stop on every node: one SSN-HB solve at H = 20 would factor
/// a dense condensed matrix of (2000 x 41)^2 entries, 54 GB.
fn rod_with_a_stop_on_every_node(dir: &Path) -> &'static str {
    let points: String = (1..=2000)
        .map(|n| format!("[[contact.point]]\nnode = {n}\ngap = 0.5\n"))
        .collect();
    std::fs::write(
        dir.join("rod.toml"),
        format!(
            "[rod]\nelements = 2000\nmass = \"modified\"\n[damping]\nzeta = 0.01\n\
             [forcing]\namplitude = 0.04\n{points}"
        ),
    )
    .expect("write the scene");
    "rod.toml"
}

/// A 5,000-dof chain with two-sided stops on every dof (10,000 contacts).
fn chain_with_two_sided_stops(dir: &Path) -> &'static str {
    let n = 5000;
    let mut k = format!(
        "%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {}\n",
        2 * n - 1
    );
    for i in 1..=n {
        k += &format!("{i} {i} {}\n", if i < n { 2.0 } else { 1.0 });
        if i < n {
            k += &format!("{} {i} -1\n", i + 1);
        }
    }
    let m: String = format!("%%MatrixMarket matrix coordinate real general\n{n} {n} {n}\n")
        + &(1..=n).map(|i| format!("{i} {i} 1\n")).collect::<String>();
    let f = format!("%%MatrixMarket matrix coordinate real general\n{n} 1 1\n{n} 1 1.0\n");
    for (name, body) in [("K.mtx", k), ("M.mtx", m), ("f.mtx", f)] {
        std::fs::write(dir.join(name), body).expect("write a matrix");
    }
    let points: String = (1..=n)
        .map(|i| {
            format!(
                "[[contact.point]]\ndof = {i}\ngap = 0.5\n\
                 [[contact.point]]\ndof = {i}\ngap = 0.5\ndirection = -1\n"
            )
        })
        .collect();
    std::fs::write(
        dir.join("chain.toml"),
        format!(
            "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\nzeta = 0.02\n\
             [forcing]\nvector = \"f.mtx\"\namplitude = 0.1\n{points}"
        ),
    )
    .expect("write the scene");
    "chain.toml"
}

#[test]
fn scene_check_checks_scenes_whose_solve_is_far_too_large() {
    let dir = tempfile::tempdir().expect("temporary directory");
    for scene in [
        rod_with_a_stop_on_every_node(dir.path()),
        chain_with_two_sided_stops(dir.path()),
    ] {
        let started = Instant::now();
        let o = run(dir.path(), &["scene-check", scene]);
        assert_eq!(o.status.code(), Some(0), "{scene}: {}", text(&o.stderr));
        assert!(text(&o.stdout).contains("natural freqs"), "{scene}");
        // Measured 0.8 s and 1.0 s; a solve's factorization would take hours.
        let seconds = started.elapsed().as_secs_f64();
        assert!(seconds < 20.0, "{scene}: {seconds} s");
    }
}

#[test]
fn export_model_exports_a_scene_whose_solve_is_far_too_large() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let scene = rod_with_a_stop_on_every_node(dir.path());
    let o = run(dir.path(), &["export-model", scene, "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    // The exported scene reads back with its 2,000 contacts.
    let exported = std::fs::read_to_string(dir.path().join("out/scene.toml")).expect("scene");
    assert_eq!(exported.matches("[[contact.point]]").count(), 2000);
}

#[test]
fn a_failed_export_leaves_no_new_directory_behind() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let scene = rod_with_a_stop_on_every_node(dir.path());
    // Files larger than 1 kB cannot be written (EFBIG, as a full disk gives ENOSPC).
    let o = Command::new("sh")
        .current_dir(dir.path())
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f 1; exec '{SSN}' export-model {scene} new/out"
        ))
        .output()
        .expect("sh runs");
    assert_eq!(o.status.code(), Some(3), "{}", text(&o.stderr));
    assert!(
        !dir.path().join("new").exists(),
        "the new directory was left"
    );
}

#[test]
fn compare_skips_the_methods_that_do_not_apply_with_a_line() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let k = "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n3 3 1\n";
    let m = "%%MatrixMarket matrix coordinate real general\n3 3 2\n1 1 1\n2 2 1\n";
    let f = "%%MatrixMarket matrix coordinate real general\n3 1 1\n2 1 1.0\n";
    for (name, body) in [("K.mtx", k), ("M.mtx", m), ("f.mtx", f)] {
        std::fs::write(dir.path().join(name), body).expect("write a matrix");
    }
    std::fs::write(
        dir.path().join("two.toml"),
        "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\nzeta = 0.02\n[forcing]\n\
         vector = \"f.mtx\"\namplitude = 0.1\n[[contact.point]]\ndof = 3\ngap = 0.05\n\
         [[contact.point]]\ndof = 3\ngap = 0.05\ndirection = -1\n",
    )
    .expect("write the scene");
    let o = run(
        dir.path(),
        &["compare", "two.toml", "--out", "cmp", "--accuracy", "0.1"],
    );
    let out = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    for method in ["lcp-lemke", "lcp-ssn"] {
        assert!(
            out.contains(&format!("{method} skipped: does not apply (")),
            "{out}"
        );
    }
    // The methods that apply ran.
    assert!(
        out.contains("\nssn-hb ") && out.contains("\nmarch "),
        "{out}"
    );
    assert!(dir.path().join("cmp/accuracy_cost.csv").exists());
}
