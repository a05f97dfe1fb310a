//! The first nonlinear mode of a cantilever with a friction damper at its tip: frequency and
//! damping ratio against the tip amplitude by EPMC on SSN-HB (`scenes/beam_friction_modes.toml`,
//! exact Coulomb friction), against the single-harmonic (describing-function) mode of the
//! same structure computed without harmonic balance
//! (`semismooth_contact::describing_function`).
//!
//! The beam is `structures::cantilever_with_tip_spring` (10 elements, beam units), its pad's
//! spring `k_t = 0.3` (a tenth of the static tip stiffness), the pad held to the ground by a
//! Coulomb slider of slip force `0.003`: a Jenkins element on the tip deflection that slips
//! from the tip amplitude `a_s = 0.01` on. Stuck, it raises `omega_1` from 3.516 to 3.68; at
//! large amplitude the slider slides most of the period and the mode returns to the free
//! cantilever's; between, friction damps it, most at a few `a_s`.
//!
//! `cargo run --release -p ssn --example friction_beam_modes -- [--write]`: prints the
//! table; `--write` also writes the scene's matrices `scenes/beam_friction/{K,M,f}.mtx` and
//! the figure `docs/beam_friction_modes.svg`.

use std::path::Path;
use std::time::Instant;

use semismooth_contact::describing_function::{
    jenkins_mode, terms_without_slider, SingleHarmonicPoint,
};
use semismooth_contact::matrix_market::model_matrix_files;
use semismooth_contact::modes::Backbone;
use semismooth_contact::structures::cantilever_with_tip_spring;
use ssn::output::{write_line_plot, LineStyle, PlotSpec, Series};

/// Elements, the Jenkins element's stiffness and slip force, the scene's `alpha`.
const ELEMENTS: usize = 10;
const KT: f64 = 0.3;
const SLIP: f64 = 3e-3;
const ALPHA: f64 = 0.05;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let write = std::env::args().any(|a| a == "--write");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let (k, m, f) = cantilever_with_tip_spring(ELEMENTS, KT);
    if write {
        let dir = root.join("scenes/beam_friction");
        std::fs::create_dir_all(&dir)?;
        for (name, text) in model_matrix_files(&k, &m, &f) {
            std::fs::write(dir.join(name), text)?;
        }
    }
    let path = root.join("scenes/beam_friction_modes.toml");
    let loaded = ssn::cli::load_for(&path, ssn::cli::Workload::Branch)?;
    let started = Instant::now();
    let branch = ssn::modes::run(&loaded.scene, &loaded.structure)?;
    let seconds = started.elapsed().as_secs_f64();
    // The reference: the beam without its pad (the spring k_t comes off the tip).
    let tip = 2 * ELEMENTS - 2;
    let (terms, _) = terms_without_slider(&k, &m, (ALPHA, 0.0), tip, 2 * ELEMENTS)
        .ok_or("the beam's mass matrix is not positive definite")?;
    let amplitudes: Vec<f64> = (0..=120)
        .map(|i| 10f64.powf(-3.0 + 2.7 * i as f64 / 120.0))
        .collect();
    let reference = jenkins_mode(&terms, KT, SLIP, 1, &amplitudes)?;
    println!("| tip amplitude | omega (EPMC) | omega (1 harmonic) | damping ratio (EPMC) | damping ratio (1 harmonic) |");
    println!("|---:|---:|---:|---:|---:|");
    for p in branch.points.iter().step_by(4) {
        let r = jenkins_mode(&terms, KT, SLIP, 1, &[p.amplitude])?[0];
        println!(
            "| {:.3e} | {:.5} | {:.5} | {:.4e} | {:.4e} |",
            p.amplitude, p.omega, r.omega, p.damping_ratio, r.damping_ratio
        );
    }
    println!(
        "\n{} points (H = {}) in {seconds:.2} s; {:?}",
        branch.points.len(),
        loaded.scene.solver.harmonics,
        branch.termination
    );
    if write {
        write_figure(&root, &branch, terms[0].omega, &amplitudes, &reference)?;
    }
    Ok(())
}

/// `docs/beam_friction_modes.svg`: the frequency shift over the free `omega_1` and the
/// damping ratio against log10 of the tip amplitude, EPMC's and the single-harmonic mode's.
fn write_figure(
    root: &Path,
    branch: &Backbone,
    omega_1: f64,
    amplitudes: &[f64],
    reference: &[SingleHarmonicPoint],
) -> Result<(), Box<dyn std::error::Error>> {
    // Linear axes over log10 of the amplitude: the frequency shift and the damping
    // ratio share a scale (a few per cent).
    let log = |a: &[f64]| a.iter().map(|v| v.log10()).collect::<Vec<f64>>();
    let epmc_a = log(&branch
        .points
        .iter()
        .map(|p| p.amplitude)
        .collect::<Vec<_>>());
    let reference_a = log(amplitudes);
    let series = |label: &str, x: &[f64], y: Vec<f64>, style, color| Series {
        label: label.into(),
        x: x.to_vec(),
        y,
        style,
        color: Some(color),
    };
    let plot = [
        series(
            "omega / omega_1 - 1 (EPMC, H = 15)",
            &epmc_a,
            branch
                .points
                .iter()
                .map(|p| p.omega / omega_1 - 1.0)
                .collect(),
            LineStyle::Solid,
            0,
        ),
        series(
            "omega / omega_1 - 1 (single harmonic)",
            &reference_a,
            reference.iter().map(|r| r.omega / omega_1 - 1.0).collect(),
            LineStyle::Dashed,
            0,
        ),
        series(
            "damping ratio (EPMC, H = 15)",
            &epmc_a,
            branch.points.iter().map(|p| p.damping_ratio).collect(),
            LineStyle::Solid,
            1,
        ),
        series(
            "damping ratio (single harmonic)",
            &reference_a,
            reference.iter().map(|r| r.damping_ratio).collect(),
            LineStyle::Dashed,
            1,
        ),
    ];
    let spec = PlotSpec {
        title: "Cantilever with a friction damper at its tip: first nonlinear mode".into(),
        x_label: "log10 of the tip amplitude (the slider slips from -2 on)".into(),
        y_label: "frequency shift over the free omega_1, damping ratio".into(),
        log_log: false,
    };
    write_line_plot(&root.join("docs/beam_friction_modes.svg"), &spec, &plot)?;
    Ok(())
}
