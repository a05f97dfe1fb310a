//! The `ssn` program's contract under hostile conditions: standard output that is full,
//! closed or a closed pipe (exit code 3, never a panic), scene inputs that are not regular
//! files, outputs that are not regular files or clash with each other or the scene, the
//! all-or-nothing rule for several outputs, `--quiet`, `--out` where it does not apply and
//! control characters in a scene's title.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

#[path = "common/exit_status.rs"]
mod exit_status;
#[path = "common/process.rs"]
mod process;

use exit_status::{assert_exit, err};
use process::{out, ssn};

const SSN: &str = env!("CARGO_BIN_EXE_ssn");

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes")
        .join(name)
        .to_str()
        .expect("utf-8 path")
        .to_string()
}

fn fig1() -> String {
    scene("paper_fig1_modified_mass.toml")
}

fn ssn_with_stdout(args: &[&str], stdout: Stdio) -> Output {
    Command::new(SSN)
        .args(args)
        .stdout(stdout)
        .stderr(Stdio::piped())
        .output()
        .expect("ssn runs")
}

/// Every subcommand that prints something, as `ssn` arguments.
fn printing_commands() -> Vec<Vec<String>> {
    let sweep = scene("paper_fig2.toml");
    vec![
        vec!["solve".into(), fig1(), "--json".into()],
        vec!["solve".into(), fig1()],
        vec!["sweep".into(), sweep.clone(), "--json".into()],
        vec!["sweep".into(), sweep],
        vec!["scene-check".into(), fig1()],
        vec!["--help".into()],
        vec!["solve".into(), "--help".into()],
    ]
}

#[test]
fn a_full_standard_output_exits_3_in_every_command() {
    for args in printing_commands() {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let full = File::options().write(true).open("/dev/full").unwrap();
        let o = ssn_with_stdout(&args, Stdio::from(full));
        assert_exit(&o, 3, &args.join(" "));
        assert!(err(&o).contains("standard output"), "{}", err(&o));
    }
}

#[test]
fn a_closed_pipe_exits_3_in_every_command() {
    for args in printing_commands() {
        // A pipe whose reading end is closed before the program starts (no race).
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = ssn_with_stdout(&args, Stdio::from(writer));
        assert_exit(&o, 3, &args.join(" "));
    }
}

#[test]
fn a_closed_standard_output_exits_3_and_dev_null_stays_a_silent_output() {
    for args in printing_commands() {
        let o = Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" >&-")
            .arg(SSN)
            .args(&args)
            .output()
            .unwrap();
        assert_exit(&o, 3, &args.join(" "));
        assert!(err(&o).contains("closed"), "{}", err(&o));
    }
    let null = File::options().write(true).open("/dev/null").unwrap();
    let o = ssn_with_stdout(&["solve", &fig1(), "--json"], Stdio::from(null));
    assert_exit(&o, 0, "> /dev/null");
}

#[test]
fn a_fifo_a_device_a_directory_or_a_huge_file_is_not_read_as_a_scene() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("scene.fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let huge = dir.path().join("huge.toml");
    std::fs::write(&huge, vec![b'#'; (1 << 20) + 1]).unwrap();
    for (path, says) in [
        (fifo.clone(), "a FIFO"),
        (PathBuf::from("/dev/zero"), "a device"),
        (dir.path().to_path_buf(), "a directory"),
        (huge, "limit of 1048576 bytes"),
    ] {
        let p = path.to_str().unwrap();
        // A FIFO without a writer would block this test forever if it were opened.
        let o = ssn(&["solve", p]);
        assert_exit(&o, 2, p);
        assert!(err(&o).contains(p) && err(&o).contains(says), "{}", err(&o));
    }
}

#[test]
fn an_output_that_is_a_symlink_or_a_device_is_refused_and_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("target.txt");
    std::fs::write(&target, "keep").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    for flag in ["--csv", "--svg"] {
        for path in [link.to_str().unwrap(), "/dev/null"] {
            let o = ssn(&["solve", &fig1(), "--json", flag, path]);
            assert_exit(&o, 3, path);
            assert!(err(&o).contains("only regular files"), "{}", err(&o));
            assert!(out(&o).is_empty(), "nothing printed before the refusal");
        }
    }
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
    // As root a regular file would have replaced the device: it is still one.
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
}

#[test]
fn an_output_on_the_scene_or_two_outputs_on_one_file_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = dir.path().join("s.toml");
    std::fs::copy(fig1(), &scene_path).unwrap();
    let before = std::fs::read_to_string(&scene_path).unwrap();
    let s = scene_path.to_str().unwrap();
    let o = ssn(&["solve", s, "--csv", s]);
    assert_exit(&o, 2, "--csv SCENE");
    assert!(err(&o).contains("the scene") && err(&o).contains("--csv"));
    let same = dir.path().join("x");
    let x = same.to_str().unwrap();
    let o = ssn(&["solve", s, "--csv", x, "--svg", x]);
    assert_exit(&o, 2, "--csv X --svg X");
    assert!(err(&o).contains("--csv and --svg"), "{}", err(&o));
    let o = ssn(&["solve", s, "--json", "--csv", "-"]);
    assert_exit(&o, 2, "--json --csv -");
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), before);
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "only the scene is left");
}

#[test]
fn several_outputs_are_written_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("t.csv");
    let svg = dir.path().join("missing").join("t.svg");
    let o = ssn(&[
        "solve",
        &fig1(),
        "--json",
        "--csv",
        csv.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_exit(&o, 3, "svg into a missing directory");
    assert!(out(&o).is_empty(), "no JSON for a run whose outputs failed");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "the CSV (or a temporary file) was left behind"
    );
}

#[test]
fn a_dash_writes_the_csv_to_standard_output() {
    let o = ssn(&["solve", &fig1(), "--quiet", "--csv", "-"]);
    assert_exit(&o, 0, "--csv -");
    let text = out(&o);
    assert!(
        text.starts_with("t,u_tip,lambda_0,lambda_series_0\n"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 1025);
    // Without --quiet the text summary already has standard output.
    let o = ssn(&["solve", &fig1(), "--csv", "-"]);
    assert_exit(&o, 2, "--csv - with the summary");
}

#[test]
fn quiet_prints_nothing_but_errors_and_json() {
    for args in [
        vec!["solve", "--quiet"],
        vec!["scene-check", "-q"],
        vec!["sweep", "--quiet"],
    ] {
        let path = if args[0] == "sweep" {
            scene("paper_fig2.toml")
        } else {
            fig1()
        };
        let mut a = args.clone();
        a.insert(1, &path);
        let o = ssn(&a);
        assert_exit(&o, 0, &a.join(" "));
        assert!(out(&o).is_empty() && err(&o).is_empty(), "{}", out(&o));
    }
    let o = ssn(&["solve", &fig1(), "--quiet", "--json"]);
    assert_exit(&o, 0, "--quiet --json");
    assert!(out(&o).contains("\"converged\": true"));
    let o = ssn(&["solve", "/nonexistent.toml", "--quiet"]);
    assert_exit(&o, 2, "missing scene");
    assert!(err(&o).contains("/nonexistent.toml"));
}

#[test]
fn out_is_refused_where_it_does_not_apply() {
    for cmd in ["solve", "scene-check", "sweep"] {
        let o = ssn(&[cmd, &fig1(), "--out", "somewhere"]);
        assert_exit(&o, 2, cmd);
        assert!(
            err(&o).contains("--out") && err(&o).contains(cmd),
            "{}",
            err(&o)
        );
        assert!(!Path::new("somewhere").exists());
    }
}

#[test]
fn control_characters_of_a_title_are_escaped_by_scene_check() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(fig1()).unwrap();
    let text = format!(
        "title = \"red \\u001b[31mALERT\\r\"\n{}",
        strip_title(&text)
    );
    let path = dir.path().join("ansi.toml");
    std::fs::write(&path, text).unwrap();
    let o = ssn(&["scene-check", path.to_str().unwrap()]);
    assert_exit(&o, 0, "scene-check");
    let printed = out(&o);
    assert!(!printed.contains('\u{1b}') && !printed.contains('\r'));
    assert!(
        printed.contains("title             red \\u{1b}[31mALERT\\u{d}"),
        "{printed}"
    );
}

fn strip_title(text: &str) -> String {
    text.lines()
        .filter(|l| !l.starts_with("title"))
        .map(|l| format!("{l}\n"))
        .collect()
}

/// A scene of `elements` elements with the given `[solver]` lines, in `dir`.
fn sized_scene(dir: &Path, elements: usize, solver: &str) -> String {
    let path = dir.join(format!("e{elements}.toml"));
    std::fs::write(
        &path,
        format!(
            "[rod]\nelements = {elements}\nmass = \"modified\"\n[forcing]\namplitude = 0.04\n\
             omega_ratio = 1.0\n[contact]\ngap = 0.5\n[solver]\n{solver}\n"
        ),
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn a_run_too_large_for_memory_is_refused_up_front_naming_the_keys_need_and_limit() {
    let dir = tempfile::tempdir().unwrap();
    let ssn_limited = |args: &[&str]| {
        Command::new(SSN)
            .args(args)
            .env("SSN_MEMORY_LIMIT", "4e9")
            .output()
            .unwrap()
    };
    // Ten million elements at H = 20: about 130 GB.
    let huge = sized_scene(dir.path(), 10_000_000, "harmonics = 20");
    for cmd in ["solve", "sweep", "scene-check"] {
        let o = ssn_limited(&[cmd, &huge]);
        assert_exit(&o, 2, cmd);
        for word in [huge.as_str(), "rod.elements", "GB", "4.0 GB available"] {
            assert!(err(&o).contains(word), "{cmd} {word}: {}", err(&o));
        }
    }
    // The dense solver on 400 elements at H = 40: 32,481 unknowns, about 10.6 GB.
    let dense = sized_scene(dir.path(), 400, "harmonics = 40\nlinear_solver = \"dense\"");
    let o = ssn_limited(&["solve", &dense]);
    assert_exit(&o, 2, "dense");
    for word in [
        "solver.linear_solver",
        "32481 unknowns",
        "\"structured\" needs",
    ] {
        assert!(err(&o).contains(word), "{word}: {}", err(&o));
    }
    // ssn compare runs the SSN-HB reference at H = 320: refused at 10^5 elements.
    let large = sized_scene(dir.path(), 100_000, "harmonics = 20");
    let o = ssn_limited(&["compare", &large, "--out", dir.path().to_str().unwrap()]);
    assert_exit(&o, 2, "compare");
    assert!(err(&o).contains("solver.harmonics"), "{}", err(&o));
}

#[test]
fn a_march_that_does_not_settle_exits_1_with_its_json() {
    let dir = tempfile::tempdir().unwrap();
    let path = sized_scene(
        dir.path(),
        20,
        "method = \"march\"\nsteps_per_period = 200\nmax_periods = 3",
    );
    let o = ssn(&["solve", &path, "--json"]);
    assert_exit(&o, 1, "march");
    let json: serde_json::Value = serde_json::from_str(&out(&o)).expect("JSON");
    assert_eq!(json["converged"], false);
    assert_eq!(json["iterations"], 3, "{json}");
    let termination = json["termination"].as_str().unwrap();
    assert!(
        termination.starts_with("not-steady") && termination.contains("solver.max_periods"),
        "{termination}"
    );
    // The last change is reported and is above the tolerance the run was judged against.
    let change = json["residual_norm"].as_f64().unwrap();
    let tolerance = json["effective_tolerance"].as_f64().unwrap();
    assert!(change > tolerance && change.is_finite(), "{json}");
    // The answer of the last period is there: the tip moved and stayed behind the gap.
    let (tip_min, tip_max) = (
        json["tip_min"].as_f64().unwrap(),
        json["tip_max"].as_f64().unwrap(),
    );
    assert!(tip_min < tip_max && tip_max <= 0.5 + 1e-12, "{json}");
}

/// `ssn solve --json` of a scene text, converged.
fn solve_json_text(dir: &Path, name: &str, text: &str) -> serde_json::Value {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let o = ssn(&["solve", path.to_str().unwrap(), "--json"]);
    assert_exit(&o, 0, name);
    serde_json::from_str(&out(&o)).expect("JSON")
}

#[test]
fn every_contact_is_reported_and_the_mean_force_is_their_sum() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene("two_contacts.toml")).unwrap();
    let ssn_hb = solve_json_text(dir.path(), "ssn.toml", &text);
    let penalty = solve_json_text(
        dir.path(),
        "penalty.toml",
        &text.replace("[solver]\n", "[solver]\nmethod = \"penalty-hb\"\n"),
    );
    for json in [&ssn_hb, &penalty] {
        let contacts = json["contacts"].as_array().expect("contacts list");
        assert_eq!(contacts.len(), 2, "{json}");
        let f = |i: usize, key: &str| contacts[i][key].as_f64().unwrap();
        assert_eq!(
            (contacts[0]["node"].as_u64(), contacts[0]["dof"].as_u64()),
            (Some(20), Some(19))
        );
        assert_eq!(contacts[1]["node"].as_u64(), Some(10));
        assert_eq!((f(0, "gap"), f(1, "gap")), (0.5, 0.3));
        // The tip never reaches its gap; the mid-span node carries the whole force.
        assert_eq!(f(0, "force_mean"), 0.0, "{json}");
        assert_eq!(f(0, "contact_fraction"), 0.0);
        assert!(f(0, "displacement_max") < 0.5);
        assert!(f(1, "force_mean") < -0.01, "{json}");
        assert!(f(1, "contact_fraction") > 0.0 && f(1, "contact_fraction") < 1.0);
        assert!(f(1, "displacement_max") >= 0.3 - 1e-3 && f(1, "displacement_min") < 0.0);
        let sum = f(0, "force_mean") + f(1, "force_mean");
        assert_eq!(json["contact_force_mean"].as_f64().unwrap(), sum);
    }
    // Two formulations of the same contact agree on its mean force: SSN-HB (contact on
    // the projection) and penalty HB (at the AFT samples) differ by 1.3 % (measured).
    let force = |j: &serde_json::Value| j["contacts"][1]["force_mean"].as_f64().unwrap();
    let rel = (force(&ssn_hb) - force(&penalty)).abs() / force(&ssn_hb).abs();
    assert!(rel < 0.02, "{rel:e}");
}

#[test]
fn lemke_at_its_pivot_limit_marks_its_values_as_those_of_an_unfinished_path() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene("paper_fig1.toml"))
        .unwrap()
        .replace(
            "method = \"ssn-hb\"",
            "method = \"lcp-lemke\"\ntime_samples = 256",
        );
    let path = dir.path().join("lemke.toml");
    std::fs::write(&path, text).unwrap();
    let o = ssn(&["solve", path.to_str().unwrap(), "--json"]);
    assert_exit(&o, 1, "lemke");
    let json: serde_json::Value = serde_json::from_str(&out(&o)).unwrap();
    let termination = json["termination"].as_str().unwrap();
    assert!(
        termination.starts_with("pivot-limit") && termination.contains("unfinished path"),
        "{termination}"
    );
    // The pivot limit measured on this scene (consistent mass, Nt = 256).
    assert_eq!(json["iterations"], 12900, "{json}");
}

#[test]
fn refusals_name_the_file_the_key_the_value_and_what_is_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let scene = |name: &str, rod: &str, rest: &str| {
        let path = dir.path().join(name);
        std::fs::write(
            &path,
            format!(
                "[rod]\n{rod}\n{rest}\n[forcing]\namplitude = 0.04\n[contact]\ngap = 0.5\n\
                 [solver]\n"
            ),
        )
        .unwrap();
        path.to_str().unwrap().to_string()
    };
    for (path, words) in [
        (
            scene("one.toml", "elements = 1\nmass = \"modified\"", ""),
            &["rod.elements", "= 1", "at least 2"][..],
        ),
        (
            scene("long.toml", "elements = 20\nlength = 1e300", ""),
            &["rod.length", "1e300", "[1e-100, 1e100]"][..],
        ),
        (
            scene("short.toml", "elements = 20\nlength = 5e-324", ""),
            &["rod.length", "5e-324", "[1e-100, 1e100]"][..],
        ),
        (
            scene(
                "rayleigh.toml",
                "elements = 20",
                "[damping]\nmodel = \"rayleigh\"",
            ),
            &["damping.model", "rayleigh", "alpha", "beta"][..],
        ),
        (
            scene("overflow.toml", "elements = 20\nlength = 1e309", ""),
            &["line 3", "overflowed", "allowed", "1.7976931348623157e308"][..],
        ),
    ] {
        let o = ssn(&["solve", &path]);
        assert_exit(&o, 2, &path);
        for word in std::iter::once(path.as_str()).chain(words.iter().copied()) {
            assert!(err(&o).contains(word), "{word}: {}", err(&o));
        }
    }
    // An amplitude that would make the response overflow in the residual norms, with any
    // method (Lemke's LCP data included).
    let huge = scene("huge.toml", "elements = 20", "");
    let text = std::fs::read_to_string(&huge)
        .unwrap()
        .replace("amplitude = 0.04", "amplitude = 1e300")
        + "method = \"lcp-lemke\"\n";
    std::fs::write(&huge, text).unwrap();
    let o = ssn(&["solve", &huge]);
    assert_exit(&o, 2, "huge amplitude");
    for word in [
        huge.as_str(),
        "forcing.amplitude",
        "1e300",
        "|value| <= 1e100",
    ] {
        assert!(err(&o).contains(word), "{word}: {}", err(&o));
    }
    let lcp = scene("lcp.toml", "elements = 20", "").to_string();
    let text =
        std::fs::read_to_string(&lcp).unwrap() + "method = \"lcp-lemke\"\ntime_samples = 10000\n";
    std::fs::write(&lcp, text).unwrap();
    let o = ssn(&["solve", &lcp]);
    assert_exit(&o, 2, "lcp");
    for word in ["invalid `solver.time_samples` = 10000", "8..=8192"] {
        assert!(err(&o).contains(word), "{word}: {}", err(&o));
    }
    // A value nested 5,000 deep (arrays of arrays): the parser's recursion limit, reported with the
    // line and column where it stopped.
    let deep = dir.path().join("deep.toml");
    std::fs::write(
        &deep,
        format!(
            "title = \"deep\"\nx = {}{}\n",
            "[".repeat(5000),
            "]".repeat(5000)
        ),
    )
    .unwrap();
    let o = ssn(&["solve", deep.to_str().unwrap()]);
    assert_exit(&o, 2, "deep nesting");
    for word in [deep.to_str().unwrap(), "line 2", "recurs"] {
        assert!(err(&o).contains(word), "{word}: {}", err(&o));
    }
    // The LCP's dense matrix has order contacts x time_samples <= 8192: with two contacts
    // 4096 samples pass the loader and 4097 are refused by solve, sweep and scene-check,
    // naming the key, the value and the range for that number of contacts.
    let two = |samples: usize, method: &str| {
        let path = dir.path().join(format!("two_{samples}_{method}.toml"));
        std::fs::write(
            &path,
            format!(
                "[rod]\nelements = 20\nmass = \"modified\"\n[forcing]\namplitude = 0.04\n\
                 [[contact.point]]\nnode = 20\ngap = 0.5\n[[contact.point]]\nnode = 10\n\
                 gap = 0.3\n[solver]\nmethod = \"{method}\"\ntime_samples = {samples}\n\
                 [sweep]\nomega_ratio_from = 0.9\nomega_ratio_to = 1.1\n"
            ),
        )
        .unwrap();
        path.to_str().unwrap().to_string()
    };
    for method in ["lcp-lemke", "lcp-ssn"] {
        let ok = two(4096, method);
        assert_exit(&ssn(&["scene-check", &ok]), 0, "4096 samples, two contacts");
        let refused = two(4097, method);
        for command in ["solve", "sweep", "scene-check"] {
            let o = ssn(&[command, &refused]);
            assert_exit(&o, 2, &format!("{command} {refused}"));
            for word in [
                refused.as_str(),
                "invalid `solver.time_samples` = 4097",
                "8..=4096",
                method,
                "2 contacts",
            ] {
                assert!(err(&o).contains(word), "{command} {word}: {}", err(&o));
            }
        }
    }
}

#[test]
fn a_default_run_that_fails_leaves_no_directory_behind() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("new").join("out");
    // The figures are written, then the summary cannot be printed: exit 3, and the
    // directory the run created is gone with its files.
    let full = File::options().write(true).open("/dev/full").unwrap();
    let o = ssn_with_stdout(&["--out", out_dir.to_str().unwrap()], Stdio::from(full));
    assert_exit(&o, 3, "default run");
    assert!(
        !dir.path().join("new").exists(),
        "the output directory was left behind"
    );
}

/// `ssn sweep` reports every contact at every point, in its JSON (`contacts`, with the
/// numbers of `ssn solve`) and its CSV (`contact{k}_...` columns); `contact_force_mean` is
/// their sum. The sweep of `two_contacts.toml` ends at the scene's frequency `omega_1`,
/// where `ssn solve` gives the same solution independently (a Newton solve from zero, not
/// the continuation): the same equations solved to the same tolerance, so the mean forces
/// (exact means of the reconstructed trigonometric polynomials) agree to 1e-6 relative.
#[test]
fn a_sweep_reports_every_contact_at_every_point_as_solve_does() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene("two_contacts.toml")).unwrap()
        + "\n[sweep]\nomega_ratio_from = 0.9\nomega_ratio_to = 1.0\n";
    let path = dir.path().join("two_contacts_sweep.toml");
    std::fs::write(&path, text).unwrap();
    let path = path.to_str().unwrap();
    let csv = dir.path().join("sweep.csv");
    let o = ssn(&["sweep", path, "--json", "--csv", csv.to_str().unwrap()]);
    assert_exit(&o, 0, "sweep");
    let sweep: serde_json::Value = serde_json::from_str(&out(&o)).expect("JSON");
    let o = ssn(&["solve", path, "--json"]);
    assert_exit(&o, 0, "solve");
    let solve: serde_json::Value = serde_json::from_str(&out(&o)).expect("JSON");

    let points = sweep["points"].as_u64().unwrap() as usize;
    let contacts = sweep["contacts"].as_array().expect("contacts per point");
    assert_eq!(contacts.len(), points);
    let sums = sweep["contact_force_mean"].as_array().unwrap();
    for (point, sum) in contacts.iter().zip(sums) {
        let list = point.as_array().unwrap();
        assert_eq!(list.len(), 2);
        assert_eq!(list[0]["node"].as_u64(), Some(20));
        assert_eq!(list[1]["node"].as_u64(), Some(10));
        // serde_json's default float parser may be off by one unit in the last place.
        let total: f64 = list.iter().map(|c| c["force_mean"].as_f64().unwrap()).sum();
        assert!((sum.as_f64().unwrap() - total).abs() <= 1e-15 * total.abs());
    }
    let ratio = sweep["omega_ratio"].as_array().unwrap();
    assert!((ratio[points - 1].as_f64().unwrap() - 1.0).abs() < 1e-9);
    let last = &contacts[points - 1];
    let node10 = |j: &serde_json::Value, key: &str| j[1][key].as_f64().unwrap();
    let (swept, solved) = (
        node10(last, "force_mean"),
        node10(&solve["contacts"], "force_mean"),
    );
    println!("node 10 mean force at omega_1: sweep {swept:.9}, solve {solved:.9}");
    assert!(solved < -0.01, "{solve}");
    assert!((swept - solved).abs() <= 1e-6 * solved.abs());
    let sum = sums[points - 1].as_f64().unwrap();
    let solved_sum = solve["contact_force_mean"].as_f64().unwrap();
    assert!((sum - solved_sum).abs() <= 1e-6 * solved_sum.abs());
    // Displacement extremes: the same trigonometric polynomial sampled on two grids (the
    // sweep's and the solve's), both of at least 1024 points per period: within 1e-4.
    for key in ["displacement_min", "displacement_max"] {
        let (a, b) = (node10(last, key), node10(&solve["contacts"], key));
        assert!((a - b).abs() <= 1e-4, "{key}: {a} vs {b}");
    }

    let table = std::fs::read_to_string(&csv).unwrap();
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for k in 0..2 {
        for field in [
            "force_mean",
            "max_penetration",
            "contact_fraction",
            "displacement_min",
            "displacement_max",
        ] {
            let name = format!("contact{k}_{field}");
            assert!(header.contains(&name.as_str()), "{header:?}");
        }
    }
    let rows: Vec<Vec<f64>> = lines
        // An empty cell is a value that is not a number (the undecided stability of the
        // massive mid-span contact).
        .map(|l| {
            l.split(',')
                .map(|v| {
                    if v.is_empty() {
                        f64::NAN
                    } else {
                        v.parse().unwrap()
                    }
                })
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), points);
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let row = &rows[points - 1];
    assert!((row[column("contact1_force_mean")] - swept).abs() <= 1e-15 * swept.abs());
    assert!((row[column("contact_force_mean")] - sum).abs() <= 1e-15 * sum.abs());
}

/// A run that fits in memory but would take hours is refused up front (exit 2) with the
/// keys, the operations it needs and the limit; `SSN_WORK_LIMIT` moves the limit.
#[test]
fn a_run_that_cannot_finish_in_time_is_refused_with_its_work_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dense.toml");
    std::fs::write(
        &path,
        "[rod]\nelements = 400\n[forcing]\namplitude = 0.04\n[contact]\ngap = 0.5\n\
         [solver]\nharmonics = 40\nlinear_solver = \"dense\"\n",
    )
    .unwrap();
    let path = path.to_str().unwrap();
    // Memory (10.5 GB for the dense LU) is not the question here: a machine that has it.
    let o = Command::new(SSN)
        .args(["solve", path])
        .env("SSN_MEMORY_LIMIT", "1e12")
        .env_remove("SSN_WORK_LIMIT")
        .output()
        .unwrap();
    assert_exit(&o, 2, "dense 400 elements H = 40");
    for word in [
        path,
        "solver.linear_solver",
        "2.3e14",
        "1.0e12",
        "SSN_WORK_LIMIT",
    ] {
        assert!(err(&o).contains(word), "{word}: {}", err(&o));
    }
    // The canonical scene (structured solver, 41 condensed unknowns: 4.6e5 operations)
    // runs by default and is refused below that limit.
    let o = Command::new(SSN)
        .args(["solve", &fig1()])
        .env("SSN_WORK_LIMIT", "1e5")
        .output()
        .unwrap();
    assert_exit(&o, 2, "work limit 1e5");
    assert!(err(&o).contains("limit of 1.0e5"), "{}", err(&o));
    let o = Command::new(SSN)
        .args(["solve", &fig1()])
        .env_remove("SSN_WORK_LIMIT")
        .output()
        .unwrap();
    assert_exit(&o, 0, "canonical");
}

/// A tolerance the formulation cannot reach is raised to its round-off floor and reported
/// (`effective_tolerance` in the JSON, a `tolerance ... effective` line in the text), never
/// a silent "converged": penalty HB's floor is `eps k_p sqrt(n) min(max|U|, max|g|)` (its
/// force term is `k_p` times a gap, `max|U|` the answer's largest displacement
/// coefficient), with the default `k_p = 1e5 K[tip, tip] = 2e6` on the 20-element rod,
/// `n = 20 x 41` unknowns at H = 20 and the gap 0.5: about 5e-9, above the default 1e-10
/// too. The LCP's min-map (a length) has the floor `eps sqrt(n) max|q|`.
#[test]
fn a_tolerance_below_the_round_off_floor_is_reported_for_every_newton_method() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(fig1()).unwrap();
    let penalty_per_unit = f64::EPSILON * 2e6 * (20.0f64 * 41.0).sqrt();
    for (method, tolerance, per_unit) in [
        ("penalty-hb", "1e-300", Some(penalty_per_unit)),
        ("penalty-hb", "1e-10", Some(penalty_per_unit)),
        ("lcp-ssn", "1e-300", None),
    ] {
        let text = base.replace(
            "method = \"ssn-hb\"",
            &format!("method = \"{method}\"\ntolerance = {tolerance}"),
        );
        let path = dir.path().join(format!("{method}_{tolerance}.toml"));
        std::fs::write(&path, text).unwrap();
        let state = dir.path().join(format!("{method}_{tolerance}.state.json"));
        let path = path.to_str().unwrap();
        let mut args = vec!["solve", path, "--json"];
        if per_unit.is_some() {
            args.extend(["--state", state.to_str().unwrap()]);
        }
        let o = ssn(&args);
        assert_exit(&o, 0, path);
        let json: serde_json::Value = serde_json::from_str(&out(&o)).expect("JSON");
        let used = json["effective_tolerance"].as_f64().unwrap();
        let asked: f64 = tolerance.parse().unwrap();
        assert!(used > asked, "{method} {tolerance}: {json}");
        assert!(json["residual_norm"].as_f64().unwrap() <= used);
        match per_unit {
            Some(per_unit) => {
                let state: serde_json::Value =
                    serde_json::from_str(&std::fs::read_to_string(&state).unwrap()).unwrap();
                let largest = (state["displacement"].as_array().unwrap().iter())
                    .fold(0.0f64, |m, u| m.max(u.as_f64().unwrap().abs()));
                let f = per_unit * largest.min(0.5);
                assert!((used / f - 1.0).abs() < 1e-12, "{used:e} vs {f:e}");
            }
            // The LCP's q is of the gap's size: the floor is a few ulps of 0.5 x 16.
            None => assert!(used < 1e-13, "{used:e}"),
        }
        let o = ssn(&["solve", path]);
        assert_exit(&o, 0, path);
        let text = out(&o);
        assert!(
            text.contains("effective") && text.contains(&format!("{asked:e}")),
            "{text}"
        );
    }
}

/// `ssn solve --csv` carries one force column per contact (`lambda_0`, `lambda_1`, in the
/// order of the JSON's `contacts`: the law on the samples), then the truncated series
/// (`lambda_series_0`, `lambda_series_1`), the mean of which over the period (uniform
/// samples of a trigonometric polynomial of lower degree: exactly its constant term) is the
/// JSON's `force_mean` of that contact, whose sum is `contact_force_mean`.
#[test]
fn the_solve_csv_has_a_force_column_per_contact_matching_the_json() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("two.csv");
    let o = ssn(&[
        "solve",
        &scene("two_contacts.toml"),
        "--json",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_exit(&o, 0, "two contacts");
    let json: serde_json::Value = serde_json::from_str(&out(&o)).expect("JSON");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "t",
            "u_tip",
            "lambda_0",
            "lambda_1",
            "lambda_series_0",
            "lambda_series_1"
        ]
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let contacts = json["contacts"].as_array().unwrap();
    let mut sum = 0.0;
    for (i, contact) in contacts.iter().enumerate() {
        let mean = rows.iter().map(|r| r[4 + i]).sum::<f64>() / rows.len() as f64;
        // The law's samples (never tension) stay at or below zero.
        assert!(rows.iter().all(|r| r[2 + i] <= 0.0), "contact {i}: tension");
        let reported = contact["force_mean"].as_f64().unwrap();
        // Measured: equal to the last bit.
        assert!(
            (mean - reported).abs() <= 1e-15 + 1e-12 * reported.abs(),
            "contact {i}: CSV mean {mean:e}, JSON {reported:e}"
        );
        sum += reported;
    }
    assert!(sum < -0.01, "the mid-span contact carries force: {sum}");
    assert_eq!(json["contact_force_mean"].as_f64().unwrap(), sum);
}
