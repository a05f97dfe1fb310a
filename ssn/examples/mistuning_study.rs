//! The shipped study: the mistuning Monte Carlo of the 100-blade disk rubbing its casing
//! (`scenes/bladed_disk_mistuned.toml`, `studies/bladed_disk_mistuning.toml`). Runs the
//! study as `ssn study` does (every core; a run into a directory that holds some of its
//! records runs only the others), then draws the distribution of the largest pad amplitude
//! over the blades at each casing clearance (empirical distribution functions, one per
//! clearance: `docs/bladed_disk_mistuning.svg`) and prints its quantiles against the tuned
//! disk's amplitude.
//!
//! `cargo run --release -p ssn --example mistuning_study -- [--out DIR] [--samples N]
//! [--write]` (default `target/mistuning-study` and the study file's 100 samples); `--write`
//! puts the figure into `docs/` and the quantile table into `docs/studies.md` (its generated
//! block).

mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use ssn::output::{line_plot_svg, PlotSpec, Series};
use ssn::source::SceneSource;
use ssn::study::run::{merge, run_document, run_study, RunOptions, Shard};
use ssn::study::table::Cell;
use ssn::study::{RunKind, Study};

/// The generated block of `docs/studies.md` that this example writes.
const QUANTILE_BLOCK: &str = "mistuning-study";
/// The quantity drawn: the largest `max |u|` over the contacts (the blades' pads).
const AMPLITUDE: &str = "contact_amplitude_max";
const GAP: &str = "contact.gap";

/// The value after `flag` in `args`.
fn option<'a>(args: &'a [String], flag: &str) -> Option<&'a str> {
    let at = args.iter().position(|a| a == flag)?;
    args.get(at + 1).map(String::as_str)
}

/// The `q`-quantile of sorted `v` (linear between order statistics).
fn quantile(v: &[f64], q: f64) -> f64 {
    let at = q * (v.len() - 1) as f64;
    let (i, t) = (at.floor() as usize, at.fract());
    v[i] + t * (v[(i + 1).min(v.len() - 1)] - v[i])
}

fn number(cell: &Cell) -> Option<f64> {
    match cell {
        Cell::Float(v) => Some(*v),
        Cell::Int(i) => Some(*i as f64),
        _ => None,
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let write = args.iter().any(|a| a == "--write");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out =
        option(&args, "--out").map_or_else(|| root.join("target/mistuning-study"), PathBuf::from);
    let scene = SceneSource::from_path(root.join("scenes/bladed_disk_mistuned.toml"))?;
    let study_path = root.join("studies/bladed_disk_mistuning.toml");
    let mut study_text = std::fs::read_to_string(&study_path)?;
    if let Some(n) = option(&args, "--samples") {
        let n: usize = n.parse().map_err(|_| "--samples: a positive integer")?;
        study_text = study_text.replace("samples = 100\n", &format!("samples = {n}\n"));
    }
    let study = Study::from_toml(&study_text, &study_path, &scene)?;
    let started = Instant::now();
    let outcome = run_study(
        &scene,
        &study,
        &study_text,
        &out,
        RunOptions {
            shard: Shard::ALL,
            jobs: None,
        },
    )
    .map_err(|e| e.to_string())?;
    let seconds = started.elapsed().as_secs_f64();
    eprintln!(
        "{} cases ({} run, {} already done) in {seconds:.1} s into {}",
        outcome.cases,
        outcome.ran,
        outcome.skipped,
        out.display()
    );
    let table = merge(&out).map_err(|e| e.to_string())?;
    let column = |name: &str| -> Result<Vec<Option<f64>>, String> {
        Ok(table
            .column(name)
            .ok_or(format!("the table has no column {name}"))?
            .cells
            .iter()
            .map(number)
            .collect())
    };
    let (gaps, amplitudes) = (column(GAP)?, column(AMPLITUDE)?);
    let converged: Vec<bool> = table
        .column("converged")
        .ok_or("the table has no converged column")?
        .cells
        .iter()
        .map(|c| matches!(c, Cell::Bool(true)))
        .collect();
    let mut levels: Vec<f64> = gaps.iter().flatten().copied().collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();

    let mut page = format!(
        "`cargo run --release -p ssn --example mistuning_study -- {}--write` ({}; {} cases \
         in {seconds:.0} s on every core)\n\n",
        option(&args, "--samples").map_or(String::new(), |n| format!("--samples {n} ")),
        ssn::tables::machine_note(),
        outcome.ran
    );
    page += "| casing gap | tuned | samples (converged) | min | 5 % | median | 95 % | max | \
             95 % / tuned |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    let mut series = Vec::new();
    for (color, &gap) in levels.iter().enumerate() {
        let mut v: Vec<f64> = (0..table.rows())
            .filter(|&r| gaps[r] == Some(gap) && converged[r])
            .filter_map(|r| amplitudes[r])
            .collect();
        let samples = (0..table.rows()).filter(|&r| gaps[r] == Some(gap)).count();
        if v.is_empty() {
            page += &format!("| {gap} | | {samples} (0) | | | | | | |\n");
            continue;
        }
        v.sort_by(f64::total_cmp);
        // The tuned disk at this clearance: every blade alike, no mistuning key.
        let (tuned, _) = run_document(
            &scene.with(&[ssn::scene::Override::parse(&format!("{GAP}={gap}"))?]),
            RunKind::Solve,
        )
        .map_err(|e| e.to_string())?;
        let tuned = ssn::study::table::quantities(RunKind::Solve, &tuned)
            .into_iter()
            .find(|(name, _)| *name == AMPLITUDE)
            .and_then(|(_, cell)| number(&cell))
            .unwrap_or(f64::NAN);
        let q = |p: f64| quantile(&v, p);
        page += &format!(
            "| {gap} | {tuned:.4} | {samples} ({}) | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | \
             {:.3} |\n",
            v.len(),
            v[0],
            q(0.05),
            q(0.5),
            q(0.95),
            v[v.len() - 1],
            q(0.95) / tuned
        );
        // The empirical distribution function as a staircase.
        let n = v.len() as f64;
        let (mut x, mut y) = (vec![v[0]], vec![0.0]);
        for (i, a) in v.iter().enumerate() {
            x.extend([*a, *a]);
            y.extend([i as f64 / n, (i + 1) as f64 / n]);
        }
        let label = if gap >= 100.0 {
            format!("no casing (gap {gap}), tuned {tuned:.3}")
        } else {
            format!("gap {gap}, tuned {tuned:.3}")
        };
        series.push(Series::new(label, x, y).with_color(color));
    }
    page += &format!(
        "\nThe largest pad amplitude `max_j max_t |u_p,j(t)|` over the 100 blades, at the \
         tuned resonance (`omega_ratio = 1`), blade stiffness `1 + delta_j` with `delta_j ~ \
         N(0, 0.02^2)`, the same {} patterns at every clearance.\n",
        study.cases.len() / levels.len().max(1)
    );
    print!("{page}");
    let svg = line_plot_svg(
        &PlotSpec {
            title: "100-blade disk on its casing: largest blade amplitude over random \
                    mistuning (std 2 %)"
                .into(),
            x_label: "largest pad amplitude over the blades".into(),
            y_label: "fraction of mistuning patterns below".into(),
            log_log: false,
        },
        &series,
    )?;
    let figure = if write {
        root.join("docs/bladed_disk_mistuning.svg")
    } else {
        out.join("bladed_disk_mistuning.svg")
    };
    std::fs::write(&figure, svg)?;
    eprintln!("wrote {}", figure.display());
    if write {
        common::write_studies_block(QUANTILE_BLOCK, &page)?;
    }
    Ok(())
}
