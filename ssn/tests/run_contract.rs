//! The program's contract on whole runs: memory refused up front within the process's
//! address-space limit (`ulimit -v`), limits given in the environment checked, work
//! estimates of time marching, branches, penalty HB and scene-check, interrupted runs and
//! failing outputs leave nothing, a search that did not finish exits 1, and numbers out of
//! the floating-point range or a structure without a periodic solution are refused before
//! they reach an output.

use std::path::Path;
#[path = "common/exit_status.rs"]
mod exit_status;

use std::process::{Command, Output, Stdio};

use exit_status::{assert_exit, assert_mentions, err};
use std::time::{Duration, Instant};

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

fn ssn(args: &[&str]) -> Output {
    Command::new(SSN).args(args).output().expect("ssn runs")
}

fn ssn_env(args: &[&str], key: &str, value: &str) -> Output {
    Command::new(SSN)
        .args(args)
        .env(key, value)
        .output()
        .expect("ssn runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A rod scene with `rod` and `rest` appended, in `dir`.
fn rod_scene(dir: &Path, name: &str, rod: &str, rest: &str) -> String {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!("[rod]\n{rod}\n[forcing]\namplitude = 0.04\n{rest}\n"),
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn the_address_space_limit_bounds_the_memory_a_run_may_use() {
    let dir = tempfile::tempdir().unwrap();
    let big = rod_scene(
        dir.path(),
        "big.toml",
        "elements = 1000000\nmass = \"modified\"",
        "[contact]\ngap = 0.5",
    );
    // 13 GB estimated; the machine may have that available, the process under ulimit not.
    for limit_kb in ["4000000", "6000000"] {
        let o = Command::new("sh")
            .args([
                "-c",
                &format!("ulimit -v {limit_kb}; exec {SSN} solve {big}"),
            ])
            .output()
            .unwrap();
        assert_exit(&o, 2, limit_kb);
        assert_mentions(&o, &["rod.elements", "ulimit -v", "GB"]);
    }
}

#[test]
fn limits_in_the_environment_that_are_not_numbers_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = rod_scene(
        dir.path(),
        "r.toml",
        "elements = 10",
        "[contact]\ngap = 0.5",
    );
    for (key, value) in [
        ("SSN_MEMORY_LIMIT", "lots"),
        ("SSN_MEMORY_LIMIT", "-5"),
        ("SSN_MEMORY_LIMIT", "inf"),
        ("SSN_WORK_LIMIT", "0"),
        ("SSN_WORK_LIMIT", "x"),
    ] {
        let o = ssn_env(&["solve", &scene], key, value);
        assert_exit(&o, 2, &format!("{key}={value}"));
        assert_mentions(&o, &[key, value, "allowed a finite number"]);
    }
    assert_exit(
        &ssn_env(&["solve", &scene], "SSN_MEMORY_LIMIT", "8e9"),
        0,
        "a number",
    );
}

#[test]
fn marches_and_branches_that_would_take_hours_are_refused_naming_the_keys() {
    let dir = tempfile::tempdir().unwrap();
    let march = |name: &str, elements: usize, steps: usize| {
        rod_scene(
            dir.path(),
            name,
            &format!("elements = {elements}\nmass = \"modified\""),
            &format!(
                "[contact]\ngap = 0.5\n[solver]\nmethod = \"march\"\nsteps_per_period = {steps}"
            ),
        )
    };
    // 2000 periods x 2000 steps x 1e5 dofs = 4e11 dof-steps x 1500 = 6e14.
    let o = ssn(&["solve", &march("m5.toml", 100_000, 2000)]);
    assert_exit(&o, 2, "march on 1e5 elements");
    assert_mentions(
        &o,
        &[
            "6.0e14",
            "solver.max_periods",
            "rod.elements",
            "SSN_WORK_LIMIT",
        ],
    );
    let o = ssn(&["solve", &march("steps.toml", 1000, 1_048_576)]);
    assert_exit(&o, 2, "steps_per_period = 1048576");
    assert_mentions(&o, &["solver.steps_per_period"]);
    // A sweep of 1.5e5 points (steps of 1e-5 over [0.5, 2]) on 1,000 elements.
    let sweep = rod_scene(
        dir.path(),
        "sweep.toml",
        "elements = 1000\nmass = \"modified\"",
        "[damping]\nzeta = 0.01\n[contact]\ngap = 0.5\n[sweep]\nomega_ratio_from = 0.5\n\
         omega_ratio_to = 2.0\nstep = 1e-5\nmin_step = 1e-5\nmax_step = 1e-5\n\
         max_points = 1000000",
    );
    let o = ssn(&["sweep", &sweep]);
    assert_exit(&o, 2, "a sweep of 1.5e5 points");
    assert_mentions(&o, &["150000 points", "sweep.max_step"]);
    // The same sweep with the default steps runs.
    let text = std::fs::read_to_string(&sweep).unwrap();
    let ok = text
        .replace("step = 1e-5\nmin_step = 1e-5\nmax_step = 1e-5\n", "")
        .replace("elements = 1000", "elements = 20");
    std::fs::write(&sweep, ok).unwrap();
    assert_exit(&ssn(&["sweep", &sweep]), 0, "the default steps");
}

/// Starts `ssn args`, waits until `ready` holds, sends SIGINT and returns the output.
///
/// No delay is needed after `ready`: the program installs its interrupt handler before it
/// reads its arguments, and registers an output directory for removal before it creates
/// it, so once the directory exists an interrupt finds both in place (and the run, which
/// takes seconds, is still going).
fn interrupt(args: &[&str], ready: impl Fn() -> bool) -> Output {
    let child = Command::new(SSN)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < Duration::from_secs(60), "never ready");
        std::thread::sleep(Duration::from_millis(20));
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    child.wait_with_output().unwrap()
}

#[test]
fn an_interrupted_default_run_or_compare_leaves_no_directory_behind() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("new/figures");
    let o = interrupt(&["--out", s(&out)], || out.exists());
    assert_eq!(o.status.code(), Some(130), "{}", err(&o));
    assert!(err(&o).contains("interrupted"), "{}", err(&o));
    assert!(
        !dir.path().join("new").exists(),
        "the created directories stay"
    );
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper_fig1_modified_mass.toml");
    let out = dir.path().join("compare");
    let o = interrupt(&["compare", s(&scene), "--out", s(&out)], || out.exists());
    assert_eq!(o.status.code(), Some(130), "{}", err(&o));
    assert!(!out.exists(), "the compare directory stays");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn no_output_is_left_when_standard_output_or_another_target_fails() {
    let dir = tempfile::tempdir().unwrap();
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper_fig1_modified_mass.toml");
    let svg = dir.path().join("tip.svg");
    for json in [true, false] {
        let mut args = vec!["solve", s(&scene), "--svg", s(&svg)];
        if json {
            args.push("--json");
        }
        let full = std::fs::File::options()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = Command::new(SSN)
            .args(&args)
            .stdout(Stdio::from(full))
            .output()
            .unwrap();
        assert_exit(&o, 3, "stdout full");
        assert!(!svg.exists(), "the SVG was written though stdout failed");
    }
    // compare: a target that is a directory is refused before the study, and nothing is
    // written.
    let out = dir.path().join("cmp");
    std::fs::create_dir_all(out.join("accuracy_cost.svg")).unwrap();
    let o = ssn(&["compare", s(&scene), "--out", s(&out)]);
    assert_exit(&o, 3, "compare with a directory target");
    assert!(!out.join("accuracy_cost.csv").exists());
    // The default run: a Fig. 2 target that is a directory leaves none of the Fig. 1 files.
    let out = dir.path().join("figs");
    std::fs::create_dir_all(out.join("fig2_H5.svg")).unwrap();
    let o = ssn(&["--quiet", "--out", s(&out)]);
    assert_exit(&o, 3, "default run with a directory target");
    let left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["fig2_H5.svg"], "files left: {left:?}");
}

#[test]
fn solutions_exits_1_and_says_what_it_missed_when_its_search_did_not_finish() {
    let dir = tempfile::tempdir().unwrap();
    let scene = rod_scene(
        dir.path(),
        "short.toml",
        "elements = 20\nmass = \"modified\"",
        "omega_ratio = 1.0\n[damping]\nzeta = 0.01\n[contact]\ngap = 0.5\n[sweep]\n\
         omega_ratio_from = 0.5\nomega_ratio_to = 1.5\nmax_points = 2",
    );
    let o = ssn(&["solutions", &scene, "--json"]);
    assert_exit(&o, 1, "a branch of two points");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["converged"], false);
    assert!(
        v["incomplete"].as_str().unwrap().contains("branch stopped"),
        "{v}"
    );
    let o = ssn(&["solutions", &scene]);
    assert_exit(&o, 1, "text");
    assert!(String::from_utf8_lossy(&o.stdout).contains("incomplete search"));
}

#[test]
fn numbers_beyond_the_floating_point_range_are_refused_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    for (rod, rest, words) in [
        (
            "",
            "[damping]\nzeta = 1e300\n[contact]\ngap = 0.5",
            &["damping.zeta", "at most 1e6"][..],
        ),
        (
            "",
            "[damping]\nalpha = 1e300\n[contact]\ngap = 0.5",
            &["damping.alpha", "at most 1e6"],
        ),
        (
            "",
            "omega_ratio = 1e300\n[contact]\ngap = 0.5",
            &["forcing.omega_ratio", "1e300"],
        ),
        (
            "",
            "[contact]\ngap = 0.5\n[solver]\nmethod = \"march\"\nmax_periods = 1",
            &["solver.max_periods", "2..="],
        ),
        (
            "",
            "[contact]\ngap = 0.5\n[sweep]\nomega_ratio_from = 1e-300\nomega_ratio_to = 1",
            &["sweep.omega_ratio_from"],
        ),
    ] {
        let scene = rod_scene(
            dir.path(),
            "n.toml",
            &format!("elements = 20\nmass = \"modified\"\n{rod}"),
            rest,
        );
        let o = ssn(&["solve", &scene, "--json"]);
        assert_exit(&o, 2, rest);
        assert_mentions(&o, words);
        assert!(o.stdout.is_empty());
    }
}

#[test]
fn an_undamped_structure_without_contact_at_a_natural_frequency_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let scene = rod_scene(dir.path(), "res.toml", "elements = 20", "omega_ratio = 1.0");
    let o = ssn(&["solve", &scene]);
    assert_exit(&o, 2, "resonance");
    assert_mentions(
        &o,
        &[
            "forcing.omega_ratio",
            "natural frequency",
            "no periodic solution",
        ],
    );
    // Off resonance or damped it runs.
    let off = rod_scene(dir.path(), "off.toml", "elements = 20", "omega_ratio = 0.5");
    let o = ssn(&["solve", &off, "--json"]);
    assert_exit(&o, 0, "off resonance");
    let damped = rod_scene(
        dir.path(),
        "damped.toml",
        "elements = 20",
        "omega_ratio = 1.0\n[damping]\nzeta = 0.01",
    );
    assert_exit(&ssn(&["solve", &damped]), 0, "damped at resonance");
}

/// Penalty HB at H = 2000 on 1,000 elements is refused before it runs (measured 37.8 s at
/// H = 200 and more than 400 s at H = 400; estimated 1.2e15 operations, hours), naming the
/// keys and the estimate; H = 200 is within the limit (`limits`' unit test).
#[test]
fn penalty_hb_at_h_2000_on_1000_elements_is_refused_naming_harmonics_and_iterations() {
    let dir = tempfile::tempdir().unwrap();
    let big = rod_scene(
        dir.path(),
        "penalty.toml",
        "elements = 1000\nmass = \"modified\"",
        "[contact]\ngap = 0.5\n[solver]\nmethod = \"penalty-hb\"\nharmonics = 2000",
    );
    let o = ssn(&["solve", &big]);
    assert_exit(&o, 2, "penalty HB at H = 2000");
    assert_mentions(
        &o,
        &[
            "penalty.toml",
            "solver.harmonics",
            "solver.max_iterations",
            "1.2e15",
        ],
    );
}

/// `scene-check` counts the natural frequencies it prints: 1e6 elements need 2.6e12
/// operations (measured 88 s), refused under a limit of 1e11; 1e4 elements (2.6e10) run.
#[test]
fn scene_check_counts_the_natural_frequencies_in_its_work_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let scene = |name: &str, elements: usize| {
        let rod = format!("elements = {elements}\nmass = \"modified\"");
        rod_scene(dir.path(), name, &rod, "[contact]\ngap = 0.5")
    };
    let big = scene("big.toml", 1_000_000);
    let o = ssn_env(&["scene-check", &big], "SSN_WORK_LIMIT", "1e11");
    assert_exit(&o, 2, "scene-check of 1e6 elements");
    assert_mentions(
        &o,
        &["big.toml", "rod.elements", "natural frequencies", "2.6e12"],
    );
    let small = scene("small.toml", 10_000);
    let o = ssn_env(&["scene-check", &small], "SSN_WORK_LIMIT", "1e11");
    assert_exit(&o, 0, "1e4 elements");
}

/// A rod of `elements` elements with `stops` evenly spaced stops of gap 0.5 at H = 20, and
/// `solver` appended to its `[solver]`.
fn stops_scene(dir: &Path, name: &str, elements: usize, stops: usize, solver: &str) -> String {
    let points: String = (1..=stops)
        .map(|k| {
            format!(
                "[[contact.point]]\nnode = {}\ngap = 0.5\n",
                k * elements / stops
            )
        })
        .collect();
    rod_scene(
        dir,
        name,
        &format!("elements = {elements}\nmass = \"modified\""),
        &format!("[damping]\nzeta = 0.01\n{points}[solver]\nharmonics = 20\n{solver}"),
    )
}

/// The GMRES iterations of a short matrix-free run (10 stops on 100 elements, the
/// condensed system solved by GMRES on request) are within a factor 3 of those the work
/// estimate counts, and its answer is the dense condensed solve's.
#[test]
fn a_matrix_free_run_takes_the_gmres_iterations_its_estimate_counts() {
    let dir = tempfile::tempdir().unwrap();
    let run = |solver: &str| {
        let scene = stops_scene(dir.path(), "stops.toml", 100, 10, solver);
        let o = ssn(&["solve", &scene, "--json"]);
        assert_exit(&o, 0, solver);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        (scene, v)
    };
    let (scene, krylov) = run("linear_solver = \"condensed-krylov\"");
    // The text summary counts the GMRES iterations too.
    let text = ssn(&["solve", &scene]);
    assert_exit(&text, 0, "condensed-krylov, text");
    let gmres = format!(
        "{} GMRES iterations",
        krylov["counters"]["krylov_iterations"]
    );
    assert!(
        String::from_utf8_lossy(&text.stdout).contains(&gmres),
        "{gmres}"
    );
    let text = std::fs::read_to_string(&scene).unwrap();
    let settings = ssn::scene::Scene::from_toml(&text, &scene).unwrap().solver;
    let counted = ssn::limits::estimated_krylov_iterations(100, 10, &settings);
    let measured = krylov["counters"]["krylov_iterations"].as_f64().unwrap();
    assert!(
        (measured / 3.0..3.0 * measured).contains(&counted),
        "{counted} GMRES iterations counted, {measured} taken"
    );
    // GMRES stops at 1e-10 of the step's right-hand side: the tips agree to 1e-8.
    let (_, dense) = run("linear_solver = \"condensed-dense\"");
    assert_eq!(dense["counters"]["krylov_iterations"], 0);
    for key in ["tip_max", "tip_min"] {
        let (a, b) = (krylov[key].as_f64().unwrap(), dense[key].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-8 * b.abs().max(1.0), "{key}: {a} {b}");
    }
}

/// The matrix-free path is estimated by its GMRES iterations: 1,000 stops on 1,000
/// elements (measured 194 s of CPU, estimated 9.2e12 operations) are refused up front under
/// a limit of 1e12, naming the keys and the estimate, where a count of its dense
/// factorizations alone (none) let it run.
#[test]
fn many_stops_are_refused_beyond_the_work_limit_naming_gmres_and_the_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let scene = stops_scene(dir.path(), "stops.toml", 1000, 1000, "");
    let o = ssn_env(&["solve", &scene], "SSN_WORK_LIMIT", "1e12");
    assert_exit(&o, 2, "1,000 stops under a limit of 1e12");
    assert_mentions(
        &o,
        &[
            "stops.toml",
            "GMRES iterations",
            "41000 unknowns",
            "solver.harmonics and the number of contacts",
            "9.2e12",
        ],
    );
}

/// `ssn solutions` on the paper's rod at H = 2000 (measured more than 1,058 s of CPU, 2.4e13
/// operations) is estimated above it and refused under a limit of 1e13.
#[test]
fn solutions_at_h_2000_are_estimated_by_their_measured_growth() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper_fig1.toml");
    let o = ssn_env(
        &["solutions", s(&scene), "--set", "solver.harmonics=2000"],
        "SSN_WORK_LIMIT",
        "1e13",
    );
    assert_exit(&o, 2, "solutions at H = 2000");
    assert_mentions(&o, &["points", "solver.harmonics", "SSN_WORK_LIMIT"]);
    let estimate: f64 = err(&o)
        .split("need about ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .and_then(|t| t.parse().ok())
        .expect("the estimate in the message");
    assert!(estimate >= 1058.0 * 2.3e10, "{}", err(&o));
}

/// The beam sweep at H = 200 takes about the points and corrector iterations its work
/// estimate counts (0.3 points per harmonic, 4 iterations a point): measured 83 points and
/// 244 iterations, counted 60 and 240, within a factor 2.
#[test]
fn a_beam_sweep_at_high_h_takes_the_points_and_iterations_its_estimate_counts() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/beam_tip_stop.toml");
    let o = ssn(&[
        "sweep",
        s(&scene),
        "--set",
        "solver.harmonics=200",
        "--json",
    ]);
    assert_exit(&o, 0, "beam sweep at H = 200");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let text = std::fs::read_to_string(&scene).unwrap();
    let mut parsed = ssn::scene::Scene::from_toml(&text, &scene).unwrap();
    parsed.solver.harmonics = 200;
    let points = ssn::work::counted_branch_points(&parsed, &parsed.solver);
    let iterations = points * ssn::work::CORRECTOR_ITERATIONS_PER_POINT;
    for (counted, key) in [
        (points, &v["points"]),
        (iterations, &v["counters"]["corrector_iterations"]),
    ] {
        let measured = key.as_f64().unwrap();
        assert!(
            (measured / 2.0..2.0 * measured).contains(&counted),
            "{counted} counted, {measured} taken"
        );
    }
}

/// The text summaries of `sweep` and `solutions` count the GMRES iterations of a
/// matrix-free run (4 stops on 40 elements, `condensed-krylov`, H = 5), as the sweep's JSON
/// does.
#[test]
fn sweep_and_solutions_summaries_count_the_gmres_iterations() {
    let dir = tempfile::tempdir().unwrap();
    let points: String = (1..=4)
        .map(|k| format!("[[contact.point]]\nnode = {}\ngap = 0.5\n", 10 * k))
        .collect();
    let scene = rod_scene(
        dir.path(),
        "krylov.toml",
        "elements = 40\nmass = \"modified\"",
        &format!(
            "[damping]\nzeta = 0.01\n{points}[solver]\nharmonics = 5\n\
             linear_solver = \"condensed-krylov\"\n[sweep]\nomega_ratio_from = 0.9\n\
             omega_ratio_to = 1.1"
        ),
    );
    let json = ssn(&["sweep", &scene, "--json"]);
    assert_exit(&json, 0, "sweep --json");
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let krylov = v["counters"]["krylov_iterations"].as_u64().unwrap();
    assert!(krylov > 0);
    let text = ssn(&["sweep", &scene]);
    assert_exit(&text, 0, "sweep");
    let words = format!("{krylov} GMRES iterations");
    assert!(
        String::from_utf8_lossy(&text.stdout).contains(&words),
        "{words}"
    );
    let text = ssn(&["solutions", &scene]);
    assert_exit(&text, 0, "solutions");
    assert!(String::from_utf8_lossy(&text.stdout).contains("GMRES iterations"));
}
