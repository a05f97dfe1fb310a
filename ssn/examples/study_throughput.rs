//! Throughput of a study of many small solves: `CASES` solves of the canonical rod
//! (`scenes/paper_fig1.toml`, H = 20) at seeded random frequencies `omega / omega_1` in
//! [0.8, 1.2], run as `ssn study` runs them (scene text and the case's overrides parsed and
//! validated, the structure built, the solve, the JSON document, the record written
//! atomically) on 1 and 2 worker threads, against the bare solves of the same frequencies
//! on a structure built once. Prints cases per second, the speed-up of 2 threads and the
//! overhead per case over the bare solve, with its parts.
//!
//! `cargo run --release -p ssn --example study_throughput -- [CASES] [--write]` (default
//! 1000 cases); `--write` puts the table into `docs/studies.md` (its generated block,
//! checked by `tests/study.rs`).

mod common;

use std::path::Path;
use std::time::Instant;

use ssn::source::SceneSource;
use ssn::study::run::{run_document, run_study, RunOptions, Shard};
use ssn::study::{RunKind, Study};

/// The generated block of `docs/studies.md` that this example writes.
const THROUGHPUT_BLOCK: &str = "study-throughput";

/// Rounds of every measurement; the median round is reported.
const ROUNDS: usize = 5;

/// The median of a few positive measurements.
fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len() / 2]
}

fn main() -> std::process::ExitCode {
    common::exit_code(run())
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let write = args.iter().any(|a| a == "--write");
    let cases: usize = match args.iter().find(|a| *a != "--write") {
        Some(n) => n.parse().map_err(|_| "CASES: a positive integer")?,
        None => 1000,
    };
    // Every measurement single-threaded inside a case, as in a study.
    faer::set_global_parallelism(faer::Par::Seq);
    let scene_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/paper_fig1.toml");
    let scene = SceneSource::from_path(&scene_path)?;
    let study_text = format!(
        "run = \"solve\"\n[random]\nsamples = {cases}\nseed = 2026\n\
         [random.keys.\"forcing.omega_ratio\"]\ndistribution = \"uniform\"\nlow = 0.8\nhigh = 1.2\n"
    );
    let study = Study::from_toml(&study_text, Path::new("<throughput>"), &scene)?;
    let omegas: Vec<f64> = study
        .cases
        .iter()
        .map(|c| c.values[0].value.as_float().expect("a sampled frequency"))
        .collect();

    let loaded = scene
        .load(ssn::cli::Workload::Solve)
        .map_err(|e| e.to_string())?;
    let omega_1 = loaded.structure.omega_1;
    // Each measurement in every round, the rounds interleaved so that a change of the
    // machine's load falls on all of them alike; the median round of each is reported.
    let mut bare_rounds = Vec::new();
    let mut document_rounds = Vec::new();
    let mut study_rounds = [Vec::new(), Vec::new()];
    let mut converged = 0;
    for _ in 0..ROUNDS {
        // The bare solves: the structure built once, only `solve` timed.
        let started = Instant::now();
        converged = 0;
        for ratio in &omegas {
            let s = semismooth_contact::solve(
                &loaded.structure,
                ratio * omega_1,
                &loaded.scene.solver,
                None,
            )?;
            converged += usize::from(s.converged());
        }
        bare_rounds.push(started.elapsed().as_secs_f64() / cases as f64);

        // A case without its record: scene, structure, solve, JSON document.
        let started = Instant::now();
        for case in &study.cases {
            run_document(&scene.with(&case.values), RunKind::Solve).map_err(|e| e.to_string())?;
        }
        document_rounds.push(started.elapsed().as_secs_f64() / cases as f64);

        // The study itself, into a fresh directory per thread count.
        for (jobs, rounds) in [1, 2].into_iter().zip(&mut study_rounds) {
            let dir = tempfile::tempdir()?;
            let started = Instant::now();
            let outcome = run_study(
                &scene,
                &study,
                &study_text,
                dir.path(),
                RunOptions {
                    shard: Shard::ALL,
                    jobs: Some(jobs),
                },
            )
            .map_err(|e| e.to_string())?;
            rounds.push(started.elapsed().as_secs_f64());
            assert_eq!(outcome.ran, cases);
            assert_eq!(outcome.not_converged, cases - converged);
        }
    }
    let bare = median(&bare_rounds);
    let document = median(&document_rounds);
    let study_seconds = [median(&study_rounds[0]), median(&study_rounds[1])];
    let per_case_1 = study_seconds[0] / cases as f64;
    let ms = |s: f64| format!("{:.3} ms", 1e3 * s);
    let mut page = format!(
        "`cargo run --release -p ssn --example study_throughput -- --write` ({})\n\n\
         {cases} solves of the canonical rod (`scenes/paper_fig1.toml`, H = 20) at seeded \
         random omega/omega_1 in [0.8, 1.2]; {converged} converged. Each time is the median of \
         {ROUNDS} interleaved rounds.\n\n\
         | measurement | per case | cases per second |\n| --- | --- | --- |\n",
        ssn::tables::machine_note()
    );
    page += &format!(
        "| bare solve (structure built once) | {} | {:.0} |\n",
        ms(bare),
        1.0 / bare
    );
    page += &format!(
        "| scene + structure + solve + JSON (no file) | {} | {:.0} |\n",
        ms(document),
        1.0 / document
    );
    for (jobs, seconds) in [1, 2].iter().zip(&study_seconds) {
        page += &format!(
            "| `ssn study`, {jobs} thread{} (records, table) | {} | {:.0} |\n",
            if *jobs == 1 { "" } else { "s" },
            ms(seconds / cases as f64),
            cases as f64 / seconds
        );
    }
    let parts = if per_case_1 >= document {
        format!(
            "scene, structure and JSON: {}; record and table: {}",
            ms(document - bare),
            ms(per_case_1 - document)
        )
    } else {
        // The record and the table cost less than the rounds' spread.
        format!(
            "scene, structure and JSON: {}; the record and the table below the rounds' spread",
            ms(document - bare)
        )
    };
    page += &format!(
        "\nSpeed-up of 2 threads over 1: {:.2} (ideal 2). Cost per case over the bare solve, \
         1 thread: {} = {:.2} x the solve ({parts}).\n",
        study_seconds[0] / study_seconds[1],
        ms(per_case_1 - bare),
        (per_case_1 - bare) / bare,
    );
    print!("{page}");
    if write {
        common::write_studies_block(THROUGHPUT_BLOCK, &page)?;
    }
    Ok(())
}
