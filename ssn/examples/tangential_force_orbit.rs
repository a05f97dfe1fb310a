//! The tangential force orbit of a 3-D frictional contact in its plane
//! (`docs/tangential_force_orbit.svg`): the oscillator of `contact/tests/frictional_march.rs`
//! in stick-slip with a turning slip direction (an elliptical in-plane load, the normal
//! force varying in `[0.2, 0.8]`), by SSN-HB at H = 40 and by the exact 3-D Moreau–Jean
//! march (4000 steps per period), with the Coulomb disk's largest and smallest radius
//! `mu N` over the period. Where the orbit lies on the moving disk's boundary the contact
//! slips; inside it, it sticks.
//!
//! `cargo run --release -p ssn --example tangential_force_orbit` (writes the figure and
//! prints its numbers).

#[path = "../../contact/tests/common/disk_march.rs"]
mod disk_march;

use std::f64::consts::PI;
use std::path::Path;

use disk_march::{harmonic_balance, march, STICK_SLIP};
use ssn::output::{write_line_plot, PlotSpec, Series};

/// A closed polygon of `n` points on the circle of `radius`.
fn circle(radius: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
    (0..=n)
        .map(|k| {
            let (s, c) = (2.0 * PI * k as f64 / n as f64).sin_cos();
            (radius * c, radius * s)
        })
        .unzip()
}

/// The orbit `(lambda_1, lambda_2)` closed on its first sample.
fn closed(force: &[Vec<f64>; 2]) -> (Vec<f64>, Vec<f64>) {
    let mut x = force[0].clone();
    let mut y = force[1].clone();
    x.push(x[0]);
    y.push(y[0]);
    (x, y)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let case = STICK_SLIP;
    let hb = harmonic_balance(&case, 40);
    let marched = march(&case, 4000);
    let normal = &hb.report.normal_force;
    let (n_max, n_min) = normal.iter().fold((0.0f64, f64::INFINITY), |(hi, lo), f| {
        (hi.max(-f), lo.min(-f))
    });
    let mu = 0.4;
    let (hx, hy) = closed(&hb.report.tangential_force);
    let (mx, my) = closed(&marched.report.tangential_force);
    let (ox, oy) = circle(mu * n_max, 256);
    let (ix, iy) = circle(mu * n_min, 256);
    let series = [
        Series::new("SSN-HB, H = 40", hx, hy),
        Series::dashed("3-D Moreau-Jean march, 4000 steps per period", mx, my),
        Series::dashed(
            format!("Coulomb disk at the largest N = {n_max:.3}"),
            ox,
            oy,
        ),
        Series::dashed(
            format!("Coulomb disk at the smallest N = {n_min:.3}"),
            ix,
            iy,
        ),
    ];
    let spec = PlotSpec {
        title: "Tangential force orbit of a 3-D frictional contact (stick-slip, turning slip)"
            .into(),
        x_label: "tangential force lambda_1".into(),
        y_label: "tangential force lambda_2".into(),
        log_log: false,
    };
    let path = Path::new("docs/tangential_force_orbit.svg");
    write_line_plot(path, &spec, &series)?;
    for (name, m) in [("SSN-HB H = 40", &hb), ("march 4000", &marched)] {
        let r = &m.report;
        println!(
            "{name}: energy per cycle {:.6}, stick / slip / separated {:.3} / {:.3} / {:.3}",
            r.dissipated_energy, r.stick_fraction, r.slip_fraction, r.separated_fraction
        );
    }
    println!(
        "normal force in [{n_min:.4}, {n_max:.4}]; wrote {}",
        path.display()
    );
    Ok(())
}
