//! Where a sweep's stability is not decided, and what it costs: the summary's time is the
//! whole run with the branch and its stability apart, the reasons carry their numbers, and
//! the documentation states the limits with the values the library uses.

use std::path::Path;

#[path = "common/process.rs"]
mod process;

use process::ssn;

/// A rod of `elements` elements, modified mass, swept over a short window at H = 5.
fn rod(elements: usize) -> String {
    format!(
        "[rod]\nelements = {elements}\nmass = \"modified\"\n[damping]\nzeta = 0.01\n\
         [forcing]\namplitude = 0.1\n[contact]\ngap = 0.5\n[solver]\nharmonics = 5\n\
         [sweep]\nomega_ratio_from = 0.9\nomega_ratio_to = 1.0\n"
    )
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The text summary of `ssn sweep` on `scene`, asserted to exit 0.
fn sweep_text(dir: &Path, scene: &str) -> String {
    let file = dir.join("scene.toml");
    std::fs::write(&file, scene).expect("write the scene");
    let o = ssn(&["sweep", file.to_str().expect("a UTF-8 path")]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    text(&o.stdout)
}

/// The seconds printed before each `s` of the summary's `converged` line: the whole run,
/// the branch, its stability and the rest.
fn seconds_of(summary: &str) -> Vec<f64> {
    let line = (summary.lines())
        .find(|l| l.starts_with("converged "))
        .expect("a converged line");
    let words: Vec<&str> = line.split_whitespace().collect();
    (1..words.len())
        .filter(|&i| words[i].trim_end_matches([',', ')']) == "s")
        .filter_map(|i| words[i - 1].parse().ok())
        .collect()
}

#[test]
fn a_sweeps_summary_time_is_the_whole_run_with_its_stability_apart() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let summary = sweep_text(dir.path(), &rod(20));
    let seconds = seconds_of(&summary);
    assert_eq!(seconds.len(), 4, "{summary}");
    let (total, branch, stability, rest) = (seconds[0], seconds[1], seconds[2], seconds[3]);
    assert!(stability > 0.0, "{summary}");
    // The parts add up to the whole within the printed rounding (three 5e-4 s roundings).
    assert!(
        (total - branch - stability - rest).abs() <= 2e-3,
        "{summary}"
    );
    assert!(summary.contains("its stability"), "{summary}");
}

#[test]
fn a_sweep_past_the_dense_monodromys_size_says_so_with_the_numbers() {
    use semismooth_contact::stability::MAX_DOFS;
    let dir = tempfile::tempdir().expect("temporary directory");
    let summary = sweep_text(dir.path(), &rod(MAX_DOFS + 1));
    let expected = format!(
        "{} dofs: the dense monodromy is formed only up to {MAX_DOFS} dofs",
        MAX_DOFS + 1
    );
    assert!(summary.contains(&expected), "{summary}");
    assert!(summary.contains(" 0 stable, 0 unstable"), "{summary}");
}

#[test]
fn the_sweeps_page_states_the_stability_limits_with_the_librarys_values() {
    use semismooth_contact::stability::{MAX_DOFS, MAX_WORK};
    let page = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/sweeps.md"))
        .expect("docs/sweeps.md");
    let section = &page[page
        .find("**Where it is not decided.**")
        .expect("the section")..];
    let section = &section[..section.find("\n\n").unwrap_or(section.len())];
    for stated in [
        format!("`MAX_DOFS` = {MAX_DOFS}"),
        format!("`MAX_WORK` = {MAX_WORK:.0e}"),
        "Friction points".to_string(),
        "stability_seconds".to_string(),
    ] {
        assert!(section.contains(&stated), "`{stated}` in {section}");
    }
}
