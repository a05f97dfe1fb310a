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

use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::Residual;
use semismooth_contact::builder::sparse_matrix;
use semismooth_contact::hb::{HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::matrix_market::model_matrix_files;
use semismooth_contact::model::{ContactRow, FrictionPoint, StructuralModel, Structure};
use semismooth_contact::structures::cantilever_with_tip_pad;
use ssn::output::{write_line_plot, PlotSpec, Series};

/// Elements per blade.
const ELEMENTS: usize = 10;
/// Load amplitude on each blade (blade B in opposite phase).
const LOAD: f64 = 0.01;
/// Modal damping ratio at the first mode.
const ZETA: f64 = 0.005;
/// Coulomb coefficient of the damper.
const MU: f64 = 0.5;
/// Harmonics of the scan.
const HARMONICS: usize = 7;

/// The two blades joined by the damper under normal load `normal_load`, and the 0-based
/// dofs (tip of blade A, pad A, pad B).
fn two_blades(normal_load: f64) -> (Structure, [usize; 3]) {
    let (k1, m1, f1) = cantilever_with_tip_pad(ELEMENTS);
    let n = k1.nrows();
    let entries = |a: &semismooth_contact::model::SparseMatrix| {
        let mut e = Vec::new();
        for j in 0..n {
            let col = a.as_ref();
            for (i, v) in col.row_idx_of_col(j).zip(col.val_of_col(j)) {
                e.push((i, j, *v));
                e.push((i + n, j + n, *v));
            }
        }
        e
    };
    let k = sparse_matrix(2 * n, &entries(&k1)).expect("entries within the dofs");
    let m = sparse_matrix(2 * n, &entries(&m1)).expect("entries within the dofs");
    let load: Vec<f64> = f1
        .iter()
        .map(|v| LOAD * v)
        .chain(f1.iter().map(|v| -LOAD * v))
        .collect();
    let (tip, pad_a, pad_b) = (2 * ELEMENTS - 2, 2 * ELEMENTS, 2 * ELEMENTS + n);
    let free = StructuralModel::new(m, k, load);
    let omega_1 = Structure::new(free.clone(), tip)
        .expect("a valid model")
        .omega_1;
    let slip = ContactRow::new(vec![pad_a, pad_b], vec![1.0, -1.0]).expect("a valid row");
    let model = free
        .with_rayleigh_damping(0.0, 2.0 * ZETA / omega_1)
        .with_friction(FrictionPoint::prescribed(slip, MU, normal_load));
    let structure = Structure::new(model, tip).expect("a valid model");
    (structure, [tip, pad_a, pad_b])
}

/// `max |u[dof]|` over the period of the SSN-HB solution at `omega` from `x` (warm start,
/// replaced by the solution); `None` when Newton did not converge from it nor from rest.
fn amplitude(structure: &Structure, omega: f64, x: &mut Vec<f64>) -> Option<f64> {
    let options = HbOptions {
        harmonics: HARMONICS,
        ..HbOptions::default()
    };
    let mut hb = SsnHb::new(&structure.model, omega, &options).ok()?;
    let newton = PolyalgorithmOptions::default();
    for start in [x.clone(), vec![0.0; hb.dim()]] {
        let mut y = start;
        y.resize(hb.dim(), 0.0);
        let report = solve_smoothing(&mut hb, &mut StructuredHbSolver::new(), &mut y, &newton);
        if report.is_ok_and(|r| r.converged()) {
            let u = hb
                .displacement_samples(&y, structure.observed_dof, 512)
                .ok()?;
            *x = y;
            return Some(u.iter().fold(0.0, |a, v| a.max(v.abs())));
        }
    }
    None
}

/// The peak of the amplitude over `omega / omega_1` in `[from, to]`: a scan of `points`
/// with warm starts, then a golden-section search on the two scan intervals around the
/// best point (to 1e-6 in the ratio); the peak, its ratio and the solves that failed.
fn resonance(structure: &Structure, from: f64, to: f64, points: usize) -> (f64, f64, usize) {
    let mut x = Vec::new();
    let mut scan = Vec::with_capacity(points);
    let mut failed = 0;
    let step = (to - from) / (points - 1) as f64;
    for i in 0..points {
        let r = from + step * i as f64;
        match amplitude(structure, r * structure.omega_1, &mut x) {
            Some(a) => scan.push((r, a, x.clone())),
            None => failed += 1,
        }
    }
    let best = (0..scan.len())
        .max_by(|&i, &j| scan[i].1.total_cmp(&scan[j].1))
        .expect("at least one solve converged");
    let (mut lo, mut hi) = (scan[best].0 - step, scan[best].0 + step);
    let mut x = scan[best].2.clone();
    let mut at = |r: f64, failed: &mut usize| {
        amplitude(structure, r * structure.omega_1, &mut x).unwrap_or_else(|| {
            *failed += 1;
            0.0
        })
    };
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fa, mut fb) = (at(a, &mut failed), at(b, &mut failed));
    while hi - lo > 1e-6 {
        if fa > fb {
            (hi, b, fb) = (b, a, fa);
            a = hi - g * (hi - lo);
            fa = at(a, &mut failed);
        } else {
            (lo, a, fa) = (a, b, fb);
            b = lo + g * (hi - lo);
            fb = at(b, &mut failed);
        }
    }
    let (ratio, peak) = if fa > fb { (a, fa) } else { (b, fb) };
    if peak >= scan[best].1 {
        (ratio, peak, failed)
    } else {
        (scan[best].0, scan[best].1, failed)
    }
}

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
        for (name, text) in model_matrix_files(&model.stiffness, &model.mass, &model.load) {
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
