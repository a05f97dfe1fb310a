//! The canonical rod solved by every formulation: SSN-HB, penalty HB (several k_p), the
//! periodic LCP by Lemke and by semismooth Newton (several Nt) and the time-marching
//! reference, for the modified mass (massless contact node: a well-posed problem on which all
//! methods agree) and the consistent mass (the reference then depends on the impact law).
//!
//! Prints a table per mass model, writes `compare_methods_<mass>.csv` and an SVG overlay of
//! the tip displacement over one period into `out/compare_methods/` (or the first argument).
//!
//! `cargo run --release --example compare_methods [OUT_DIR]`

mod common;

use semismooth_contact::rod::MassModel;
use ssn::output::{csv_table, write_atomically, write_line_plot, PlotSpec, Series};
use ssn::tables::method_comparison;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = common::output_directory("out/compare_methods")?;
    for mass in [MassModel::Modified, MassModel::Consistent] {
        compare(mass, &out)?;
    }
    println!("\nWrote CSV and SVG files to {}", out.display());
    Ok(())
}

fn compare(mass: MassModel, out: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let name = format!("{mass:?}").to_lowercase();
    let (table, rows) = method_comparison(mass)?;
    let reference = rows[0].result.as_ref().ok().cloned();
    println!(
        "\n{} mass (canonical rod, gap 0.5, omega = omega_1). Reference: {}",
        name, rows[0].label
    );
    // The table of `docs/method-comparison.md` (`ms`: wall time of the Newton iterations / pivots / periods of one
    // cold solve, the problem already built).
    print!("\n{}", table.markdown());
    let mut csv_rows: Vec<Vec<f64>> = vec![Vec::new(); 8];
    let mut labels = Vec::new();
    let mut series = Vec::new();
    for row in &rows {
        if let Ok(s) = &row.result {
            let diff = reference
                .as_ref()
                .map(|r| (s.stats.min - r.stats.min).abs() / r.stats.min.abs())
                .unwrap_or(f64::NAN);
            labels.push(row.label.clone());
            for (column, v) in csv_rows.iter_mut().zip([
                if s.converged() { 1.0 } else { 0.0 },
                s.iterations as f64,
                s.solve_seconds,
                s.stats.max,
                s.stats.min,
                s.stats.max_penetration,
                s.stats.mean_contact_force,
                diff,
            ]) {
                column.push(v);
            }
            if s.converged()
                && (row.label.starts_with("march")
                    || row.label == "ssn-hb H=40"
                    || row.label.starts_with("penalty-hb H=40 kp=1e2")
                    || row.label == "lcp-lemke Nt=1024")
            {
                let period = 2.0 * std::f64::consts::PI / s.omega;
                let phase = s.times.iter().map(|t| t / period).collect();
                let item = if row.label.starts_with("march") {
                    Series::dashed(row.label.clone(), phase, s.observed.clone())
                } else {
                    Series::new(row.label.clone(), phase, s.observed.clone())
                };
                series.push(item);
            }
        }
    }
    let mut text = String::from("method,");
    text.push_str(&csv_table(
        &[
            "converged",
            "iterations",
            "solve_seconds",
            "tip_max",
            "tip_min",
            "max_penetration",
            "mean_contact_force",
            "diff_tip_min",
        ],
        &csv_rows.iter().map(Vec::as_slice).collect::<Vec<_>>(),
    ));
    // Prefix each data line with its method label.
    let mut lines = text.lines();
    let mut with_labels = String::from(lines.next().unwrap_or_default());
    with_labels.push('\n');
    for (label, line) in labels.iter().zip(lines) {
        with_labels.push_str(&format!("\"{label}\",{line}\n"));
    }
    write_atomically(
        &out.join(format!("compare_methods_{name}.csv")),
        with_labels.as_bytes(),
    )?;
    write_line_plot(
        &out.join(format!("compare_methods_{name}.svg")),
        &PlotSpec {
            title: format!("Tip displacement over one period, {name} mass"),
            x_label: "t / T".into(),
            y_label: "u_tip".into(),
            log_log: false,
        },
        &series,
    )?;
    if mass == MassModel::Consistent {
        println!(
            "With a massive contact node the time-marching answer depends on the impact law it \
             imposes (here restitution 0), harmonic balance imposes none, and the periodic LCP \
             matrix is far from copositive: Lemke's path grows very long (pivot limit) and the \
             methods need not agree. Use mass = \"modified\" for a well-posed comparison."
        );
    }
    Ok(())
}
