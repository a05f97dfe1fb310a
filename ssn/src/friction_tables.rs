//! The friction tables of `docs/friction.md`: harmonic balance against Den Hartog's exact
//! continuous-sliding amplitude by `H`, and the classic friction-damper curve (the
//! resonance peak of two blades joined by a damper against its normal load) of
//! `examples/friction_damper.rs`.

use std::time::Instant;

use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::Residual;
use semismooth_contact::builder::sparse_matrix;
use semismooth_contact::exact::den_hartog;
use semismooth_contact::hb::{HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::model::{ContactRow, FrictionPoint, StructuralModel, Structure};
use semismooth_contact::settings::{default_hb_time_samples, SolverSettings};
use semismooth_contact::structures::cantilever_with_tip_pad;

use crate::tables::{Table, TableError};

/// Elements per blade.
pub const ELEMENTS: usize = 10;
/// Load amplitude on each blade (blade B in opposite phase).
pub const LOAD: f64 = 0.01;
/// Modal damping ratio at the first mode.
pub const ZETA: f64 = 0.005;
/// Coulomb coefficient of the damper.
pub const MU: f64 = 0.5;
/// Harmonics of the scan.
pub const HARMONICS: usize = 7;

/// The two blades joined by the damper under normal load `normal_load`, and the 0-based
/// dofs (tip of blade A, pad A, pad B).
pub fn two_blades(normal_load: f64) -> (Structure, [usize; 3]) {
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
pub fn amplitude(structure: &Structure, omega: f64, x: &mut Vec<f64>) -> Option<f64> {
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
pub fn resonance(structure: &Structure, from: f64, to: f64, points: usize) -> (f64, f64, usize) {
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

/// The harmonics of the Den Hartog table.
pub const DEN_HARTOG_HARMONICS: [usize; 5] = [5, 10, 20, 40, 80];

/// The Den Hartog cases `(w, c)` of `x'' + c x' + x + F sign(x') = cos(w t)` with
/// `F = 0.3`: below and above resonance undamped, and below with `zeta = 0.01`.
pub const DEN_HARTOG_CASES: [(f64, f64); 3] = [(0.7, 0.0), (1.3, 0.0), (0.7, 0.02)];

/// SSN-HB's amplitude `max |x|` (1024 reconstruction points) against Den Hartog's exact
/// one, relative error by `H` for each of [`DEN_HARTOG_CASES`].
pub fn den_hartog_convergence() -> Result<Table, TableError> {
    let mut header = vec!["H".to_string()];
    for (w, c) in DEN_HARTOG_CASES {
        header.push(format!("w = {w}, zeta = {}", c / 2.0));
    }
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut table = Table::new(&header, &[]);
    for h in DEN_HARTOG_HARMONICS {
        let mut row = vec![h.to_string()];
        for (w, c) in DEN_HARTOG_CASES {
            let exact = den_hartog(1.0, c, 1.0, 1.0, 0.3, w)
                .ok_or_else(|| TableError::Figure(format!("no continuous sliding at w = {w}")))?;
            let structure = oscillator(c, 0.3);
            let settings = SolverSettings {
                harmonics: h,
                time_samples: default_hb_time_samples(h),
                estimate_error: false,
                ..SolverSettings::default()
            };
            let s = semismooth_contact::solve(&structure, w, &settings, None)?;
            if !s.converged() {
                return Err(TableError::Figure(format!(
                    "H = {h}, w = {w}: {}",
                    s.termination
                )));
            }
            let amplitude = s.stats.max.max(-s.stats.min);
            row.push(format!("{:.2e}", (amplitude - exact).abs() / exact));
        }
        table.rows.push(row);
    }
    Ok(table)
}

/// `x'' + c x' + x = cos(w t) + lambda_t` with the slip limit `slip_limit` on its dof.
fn oscillator(c: f64, slip_limit: f64) -> Structure {
    let one = |v: f64| sparse_matrix(1, &[(0, 0, v)]).expect("one entry");
    let mut model = StructuralModel::new(one(1.0), one(1.0), vec![1.0]).with_friction(
        FrictionPoint::prescribed(ContactRow::unit(0, 1.0), 1.0, slip_limit),
    );
    if c > 0.0 {
        model = model.with_damping(one(c));
    }
    Structure::new(model, 0).expect("a valid oscillator")
}

/// The normal loads of the damper table.
pub const DAMPER_LOADS: [f64; 7] = [1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1, 1e1];

/// The damper curve: for each of [`DAMPER_LOADS`] the resonance ratio and peak of blade
/// A's tip ([`resonance`] over 0.9 to 4 `omega_1`, 63 scan points) and the seconds it took.
pub fn damper_curve() -> Result<Table, TableError> {
    let mut table = Table::new(
        &[
            "normal load N",
            "mu N",
            "resonance omega / omega_1",
            "peak tip amplitude",
            "seconds",
        ],
        &[4],
    );
    for n in DAMPER_LOADS {
        let started = Instant::now();
        let (structure, _) = two_blades(n);
        let (ratio, peak, failed) = resonance(&structure, 0.9, 4.0, 63);
        if failed > 0 {
            return Err(TableError::Figure(format!(
                "N = {n}: {failed} solves did not converge"
            )));
        }
        table.rows.push(vec![
            format!("{n:.0e}"),
            format!("{:.1e}", MU * n),
            format!("{ratio:.4}"),
            format!("{peak:.4e}"),
            format!("{:.2}", started.elapsed().as_secs_f64()),
        ]);
    }
    Ok(table)
}
