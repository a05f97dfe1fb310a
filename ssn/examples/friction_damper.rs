//! The classic friction-damper curve: resonance amplitude of a blade against the normal
//! load pressing a damper between two blades (node-to-node), by SSN-HB with exact
//! Coulomb friction.
//!
//! Two identical cantilever blades (`structures::cantilever_with_tip_pad`, 10 elements,
//! beam units `L = EI = rhoA = 1`, Rayleigh damping `zeta = 0.005` at the first mode),
//! forced out of phase by the uniform load (`+-0.01`), are joined at their platforms
//! (the pads, on the tip springs) by a friction damper: the slip is the relative
//! displacement `u[pad A] - u[pad B]`, the slip limit `mu N` with `mu = 0.5`. For each
//! normal load `N` the first resonance peak of blade A's tip deflection is found by a
//! frequency scan (0.9 to 4 `omega_1`) with warm starts refined by a golden-section search.
//! At `N -> 0` the damper slips freely (the free blades' peak); at `N -> inf` it sticks
//! (the linked blades' peak, at a higher frequency); between, friction dissipates and the
//! peak has a minimum: the figure a damper designer reads the optimal load from.
//!
//! `cargo run --release -p ssn --example friction_damper -- [--write]`: prints the table;
//! `--write` also writes `docs/friction_damper.svg` and the scene's matrices
//! `scenes/friction_damper/{K,M,f}.mtx` (the model of `scenes/friction_damper.toml`).

use std::path::Path;
use std::time::Instant;

use semismooth_contact::matrix_market::model_matrix_files;
use ssn::friction_tables::{resonance, two_blades, HARMONICS, MU};
use ssn::output::{write_line_plot, PlotSpec, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let write = std::env::args().any(|a| a == "--write");
    let start = Instant::now();
    // Normal loads from 1e-4 to 10 (the friction force scale is the blade's elastic force
    // at resonance, about LOAD / (2 zeta) times its static one).
    let loads: Vec<f64> = (0..=20)
        .map(|i| 10f64.powf(-4.0 + 0.25 * i as f64))
        .collect();
    println!("| normal load N | mu N | resonance omega / omega_1 | peak tip amplitude |");
    println!("|---:|---:|---:|---:|");
    let mut curve = Vec::new();
    for &n in &loads {
        let (structure, _) = two_blades(n);
        let (ratio, peak, failed) = resonance(&structure, 0.9, 4.0, 311);
        assert_eq!(failed, 0, "N = {n}: {failed} solves did not converge");
        println!("| {n:.3e} | {:.3e} | {ratio:.4} | {peak:.5e} |", MU * n);
        curve.push((n, peak));
    }
    println!(
        "\n{} loads, each a scan of 311 frequencies and a golden-section search (SSN-HB, \
         H = {HARMONICS}, {} dofs, warm starts), in {:.1} s",
        loads.len(),
        two_blades(1.0).0.model.dofs(),
        start.elapsed().as_secs_f64()
    );
    let (free, stuck) = (curve[0].1, curve[curve.len() - 1].1);
    let (n_best, a_best) = curve
        .iter()
        .copied()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("loads");
    println!(
        "free-slipping peak {free:.4e}, stuck peak {stuck:.4e}, minimum {a_best:.4e} at N = \
         {n_best:.3e} ({:.1} times below the free peak)",
        free / a_best
    );
    if write {
        let (structure, dofs) = two_blades(1.0);
        let model = &structure.model;
        let dir = Path::new("scenes/friction_damper");
        std::fs::create_dir_all(dir)?;
        for (name, text) in
            model_matrix_files(&model.stiffness, &model.mass, &model.load.forcing_cosine())
        {
            std::fs::write(dir.join(name), text)?;
        }
        println!(
            "wrote {} (tip A, pad A, pad B: dofs {:?}, 1-based)",
            dir.display(),
            dofs.map(|d| d + 1)
        );
        let spec = PlotSpec {
            title: "Friction damper between two blades: resonance peak against normal load".into(),
            x_label: "normal load N".into(),
            y_label: "peak tip deflection of blade A".into(),
            log_log: true,
        };
        let (x, y): (Vec<f64>, Vec<f64>) = curve.iter().copied().unzip();
        let ends = vec![x[0], x[x.len() - 1]];
        let series = [
            Series::new(format!("SSN-HB, H = {HARMONICS}, mu = {MU}"), x, y),
            Series::dashed(
                "damper slipping freely (N -> 0)",
                ends.clone(),
                vec![free; 2],
            ),
            Series::dashed("damper stuck (N -> inf)", ends, vec![stuck; 2]),
        ];
        write_line_plot(Path::new("docs/friction_damper.svg"), &spec, &series)?;
        println!("wrote docs/friction_damper.svg");
    }
    Ok(())
}
