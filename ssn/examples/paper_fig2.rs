//! The paper's Fig. 2: frequency-response curves of the rod against a rigid obstacle, by
//! pseudo-arclength continuation of SSN-HB in the forcing frequency.
//!
//! ```text
//! cargo run --release --example paper_fig2 [OUTPUT_DIR]      # default out/paper_fig2
//! ```
//!
//! Writes `fig2.csv` (long format: `curve, harmonics, omega_ratio, tip_max, tip_min,
//! amplitude`, one row per branch point in branch order) and one SVG per `H`
//! (`fig2_h5.svg`, `fig2_h20.svg`: max tip displacement and amplitude `max |u_tip|` against
//! `omega / omega_1`), prints a table per curve, then the strong-forcing case
//! (`p0 = 0.2`, modified mass) with both folds of each branch (the jump-down and jump-up
//! frequencies a slow sweep would see) and the difference between `H = 5` and `H = 20`, and
//! the measured timings.

mod common;

use std::time::Instant;

use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};
use ssn::figures::{fig2_rod, figure_2_sweep, FIG2_GAPS as GAPS};
use ssn::output::{write_atomically, write_line_plot};
use ssn::output::{PlotSpec, Series};
use ssn::scene::{GlobalizationChoice, SolverSettings, SweepSettings};

fn settings(harmonics: usize) -> SolverSettings {
    SolverSettings {
        max_iterations: 100,
        globalization: GlobalizationChoice::Nonmonotone,
        steps_per_period: 1024,
        ..SolverSettings::with_harmonics(harmonics)
    }
}

fn sweep() -> SweepSettings {
    figure_2_sweep()
}

fn rod(gap: Option<f64>, amplitude: f64, mass: MassModel) -> RodModel {
    let spec = RodSpec {
        amplitude,
        mass,
        ..fig2_rod(gap)
    };
    build_rod(&spec).expect("the paper's rod builds")
}

fn label(gap: Option<f64>) -> String {
    match gap {
        Some(g) => format!("gap {g}"),
        None => "no contact".to_string(),
    }
}

struct Curve {
    name: String,
    harmonics: usize,
    response: FrequencyResponse,
    seconds: f64,
}

fn run(name: String, rod: &RodModel, harmonics: usize) -> Curve {
    let start = Instant::now();
    let response =
        frequency_response(rod, &settings(harmonics), &sweep(), None).expect("the sweep starts");
    let seconds = start.elapsed().as_secs_f64();
    Curve {
        name,
        harmonics,
        response,
        seconds,
    }
}

fn print_row(c: &Curve) {
    let r = &c.response;
    let (peak_i, peak) = r.peak().unwrap_or((0, f64::NAN));
    let folds: Vec<String> = r
        .folds
        .iter()
        .map(|w| format!("{:.4}", w / r.omega_1))
        .collect();
    println!(
        "{:<12} {:>3} {:>6} {:>6} {:>9.5} {:>9.4} {:>8.4} {:>6} {:>7} {:>6}  [{}] {}",
        c.name,
        c.harmonics,
        r.points.len(),
        r.folds.len(),
        peak,
        r.points
            .get(peak_i)
            .map_or(f64::NAN, |p| p.omega / r.omega_1),
        c.seconds,
        r.continuation.corrector_iterations,
        r.continuation.rejected_steps,
        r.counters.factorizations,
        folds.join(", "),
        if r.converged() {
            String::new()
        } else {
            ssn::words::sweep_termination(r)
        },
    );
}

fn header() {
    println!(
        "{:<12} {:>3} {:>6} {:>6} {:>9} {:>9} {:>8} {:>6} {:>7} {:>6}  folds (omega/omega_1)",
        "curve",
        "H",
        "points",
        "folds",
        "peak amp",
        "at w/w1",
        "seconds",
        "iters",
        "rejects",
        "factor"
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = common::output_directory("out/paper_fig2")?;

    // Warm-up (page faults, FFT plans) so that the timings below measure the sweeps.
    let _ = run(
        "warm-up".into(),
        &rod(Some(0.5), 0.04, MassModel::Consistent),
        5,
    );

    println!("Fig. 2: canonical rod (20 elements, zeta = 0.01, p0 = 0.04), SSN-HB, omega/omega_1 in [0.5, 2]");
    header();
    let mut curves = Vec::new();
    for harmonics in [5, 20] {
        for gap in GAPS {
            let c = run(
                label(gap),
                &rod(gap, 0.04, MassModel::Consistent),
                harmonics,
            );
            print_row(&c);
            curves.push(c);
        }
    }

    let mut csv = String::from("curve,harmonics,omega_ratio,tip_max,tip_min,amplitude\n");
    for c in &curves {
        let r = &c.response;
        for i in 0..r.points.len() {
            csv.push_str(&format!(
                "{},{},{:e},{:e},{:e},{:e}\n",
                c.name,
                c.harmonics,
                r.points[i].omega / r.omega_1,
                r.points[i].observed_max,
                r.points[i].observed_min,
                r.points[i].amplitude
            ));
        }
    }
    write_atomically(&dir.join("fig2.csv"), csv.as_bytes())?;
    for harmonics in [5, 20] {
        let mut series = Vec::new();
        for c in curves.iter().filter(|c| c.harmonics == harmonics) {
            let r = &c.response;
            series.push(Series::new(
                format!("{}: max u_tip", c.name),
                r.omega_ratio(),
                r.column(|p| p.observed_max),
            ));
            series.push(Series::dashed(
                format!("{}: max |u_tip|", c.name),
                r.omega_ratio(),
                r.column(|p| p.amplitude),
            ));
        }
        let spec = PlotSpec {
            title: format!("Frequency response of the tip, SSN-HB, H = {harmonics}"),
            x_label: "omega / omega_1".into(),
            y_label: "tip displacement".into(),
            log_log: false,
        };
        write_line_plot(&dir.join(format!("fig2_h{harmonics}.svg")), &spec, &series)?;
    }

    // Strong forcing, massless tip: the contact branches overhang far to the right.
    println!();
    println!("Strong forcing (p0 = 0.2, modified mass), SSN-HB");
    header();
    let mut strong = Vec::new();
    for gap in GAPS {
        for harmonics in [5, 20] {
            let c = run(label(gap), &rod(gap, 0.2, MassModel::Modified), harmonics);
            print_row(&c);
            strong.push(c);
        }
    }
    println!();
    println!("Folds of the strong-forcing branches: the branch turns back at the jump-down");
    println!("frequency (largest fold, an upward sweep falls off there) and again at the jump-up");
    println!("frequency (smallest fold after it, a downward sweep jumps up there).");
    println!(
        "{:<12} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "curve",
        "down H=5",
        "down H=20",
        "up H=5",
        "up H=20",
        "peak H=5",
        "peak H=20",
        "d(down)",
        "d(peak)"
    );
    for pair in strong.chunks(2) {
        let folds = |c: &Curve| {
            let r = &c.response;
            let ratios: Vec<f64> = r.folds.iter().map(|w| w / r.omega_1).collect();
            // Jump-down: the largest fold; jump-up: the smallest fold after it.
            let (i_down, down) =
                ratios
                    .iter()
                    .copied()
                    .enumerate()
                    .fold((0, f64::NAN), |b, (i, w)| {
                        if b.1.is_nan() || w > b.1 {
                            (i, w)
                        } else {
                            b
                        }
                    });
            let up = ratios
                .iter()
                .skip(i_down + 1)
                .copied()
                .fold(f64::NAN, f64::min);
            (down, up, r.peak().map_or(f64::NAN, |p| p.1))
        };
        let (d5, u5, p5) = folds(&pair[0]);
        let (d20, u20, p20) = folds(&pair[1]);
        println!(
            "{:<12} {:>10.4} {:>10.4} {:>10.4} {:>10.4} {:>10.4} {:>10.4} {:>10.4} {:>10.4}",
            pair[0].name,
            d5,
            d20,
            u5,
            u20,
            p5,
            p20,
            d5 - d20,
            p5 - p20
        );
    }

    let h5: f64 = curves
        .iter()
        .filter(|c| c.harmonics == 5)
        .map(|c| c.seconds)
        .sum();
    let h20_contact = curves
        .iter()
        .find(|c| c.harmonics == 20 && c.name == "gap 0.5")
        .map_or(f64::NAN, |c| c.seconds);
    println!();
    println!(
        "timings (wall clock, release build, {} logical cores available): four H = 5 curves {:.3} s in total \
         (target 0.2 s); one contact curve (gap 0.5) at H = 20 {:.3} s (target 0.5 s)",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        h5,
        h20_contact
    );
    println!("wrote {}", dir.display());
    Ok(())
}
