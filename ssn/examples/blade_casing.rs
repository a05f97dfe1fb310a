//! The blade-casing rubbing scene (`scenes/blade_casing.toml`): its matrices, and SSN-HB
//! against the exact 3-D Moreau–Jean march on it as `H` grows.
//!
//! The blade is a cantilever along the radius `x` (4 elements, `L = rhoA = 1`): an axial
//! bar (`EA = 1000`) and Hermite bending in its two principal planes (`EI = 1` flapwise,
//! `4` edgewise), the principal axes staggered by 30 degrees from the engine's
//! circumferential (`y`) and axial (`z`) directions. The casing's normal at the tip is the
//! radius leaned by 0.1 rad towards `y`, so bending moves the tip along the normal. A
//! massless pad (the abradable coating's spring, 30) carries the normal row; the two
//! tangent rows are the tip's circumferential and axial displacements in the casing's
//! tangent plane. Rayleigh damping (2 % at the first and third natural frequencies) on
//! the blade. Dofs (0-based): node `i = 1..4` holds `5 (i - 1) + [u, a, theta_a, b,
//! theta_b]`; the pad is dof 20.
//!
//! `cargo run --release -p ssn --example blade_casing -- [--write]`: prints the table of
//! `docs/blade-casing.md`; `--write` writes `scenes/blade_casing/{K,M,D}.mtx`.

#[path = "../tests/common/blade_casing.rs"]
mod blade_casing;

use std::path::Path;

use blade_casing::{compare_to_march, BladeMatrices, COMPARED_RATIOS};
use semismooth_contact::matrix_market::matrix_market_text;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    if std::env::args().any(|a| a == "--write") {
        let blade = BladeMatrices::build();
        let dir = Path::new("scenes/blade_casing");
        std::fs::create_dir_all(dir)?;
        for (name, matrix) in [
            ("K.mtx", &blade.stiffness),
            ("M.mtx", &blade.mass),
            ("D.mtx", &blade.damping),
        ] {
            std::fs::write(dir.join(name), matrix_market_text(matrix))?;
        }
        println!("wrote {}", dir.display());
        return Ok(());
    }
    println!("| omega / omega_1 | H | tip y amplitude | tip z amplitude | energy per cycle | contact fraction | difference to the march |");
    println!("|---|---|---|---|---|---|---|");
    for ratio in COMPARED_RATIOS {
        let (reference, coarse, fine, rows) = compare_to_march(ratio, &[5, 10, 20, 40, 80]);
        let row = |label: String, m: &blade_casing::Measures, difference: String| {
            println!(
                "| {ratio} | {label} | {:.6} | {:.6} | {:.6e} | {:.4} | {difference} |",
                m.amplitude[0],
                m.amplitude[1],
                m.report.dissipated_energy,
                1.0 - m.report.separated_fraction
            );
        };
        for (h, hb) in &rows {
            row(
                h.to_string(),
                hb,
                format!("{:.2e}", hb.difference(&reference)),
            );
        }
        for (label, m) in [("march 2000", &coarse), ("march 4000", &fine)] {
            row(label.into(), m, format!("{:.2e}", m.difference(&reference)));
        }
        row("march extrapolated".into(), &reference, "reference".into());
    }
    Ok(())
}
