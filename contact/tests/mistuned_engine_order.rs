//! A mistuned bladed disk under an engine-order excitation, scanned on the full model beside
//! the tuned disk scanned on one cyclic sector, and the amplification factor (the largest
//! blade-tip amplitude over the scan and the blades against the tuned sector's peak).
//! Without contact every point is the dense complex solve of the linear disk; with the
//! casing, the tuned disk scanned whole is the sector, and each mistuned disk's peak is the
//! one of the same pattern turned by one blade (the engine-order load makes that disk's
//! response the first one's, one blade on and `EO T / N` later).

use nalgebra::{Complex, DMatrix, DVector};
use semismooth_contact::model::{StructuralModel, Structure};
use semismooth_contact::settings::{LinearSolverChoice, SolverSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::structures::{BladedDisk, DiskLoading};

mod common;
use common::dense_kmd;

#[path = "common/sector.rs"]
mod sector;
use sector::{nodal_diameter_resonance, settings};

const BLADES: usize = 8;
const ENGINE_ORDER: usize = 3;
const HARMONICS: usize = 5;
/// Frequencies of each scan, over 8 % either side of the nodal-diameter resonance.
const POINTS: usize = 41;
/// Instants of the period on which a blade's amplitude is read: a multiple of `N`, so
/// the delay `EO T / N` between blades is a whole number of them.
const INSTANTS: usize = 144;

fn run() -> SolverSettings {
    settings(HARMONICS, LinearSolverChoice::Structured)
}

/// Three times the shipped load with the casing on every blade (`stops`), or no casing.
fn loading(casing: bool) -> DiskLoading {
    let stops = if casing {
        (0..BLADES).collect()
    } else {
        Vec::new()
    };
    DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped(stops)
    }
}

/// The full disk whose blade `j` has the stiffness `k_b (1 + pattern[j])`, engine-order
/// loaded.
fn mistuned_disk(casing: bool, pattern: &[f64]) -> Structure {
    let disk = BladedDisk::tuned(pattern.len());
    let mut full = disk
        .structure_with_mistuning(&loading(casing), pattern)
        .unwrap();
    full.model.load = (full.model.load.clone())
        .delayed_by_sector(&disk.sector_dofs(), ENGINE_ORDER)
        .unwrap();
    full
}

/// `max_t |u(t)|` of `dof` from harmonic-major coefficients over `n` dofs.
fn amplitude(u: &[f64], n: usize, dof: usize) -> f64 {
    (0..INSTANTS)
        .map(|i| {
            let t = 2.0 * std::f64::consts::PI * i as f64 / INSTANTS as f64;
            (1..=HARMONICS).fold(u[dof], |v, k| {
                let (a, b) = (u[(2 * k - 1) * n + dof], u[2 * k * n + dof]);
                v + a * (k as f64 * t).cos() + b * (k as f64 * t).sin()
            })
        })
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// The largest tip amplitude over the blades `0..blades` of the state `u` (`n` dofs).
fn largest_tip(u: &[f64], n: usize, blades: usize) -> f64 {
    (0..blades).fold(0.0f64, |m, j| m.max(amplitude(u, n, BladedDisk::tip(j))))
}

/// The scan's frequencies: `POINTS` over 8 % either side of the tuned resonance that
/// the engine order excites.
fn frequencies() -> Vec<f64> {
    let (sector, _) = BladedDisk::tuned(BLADES)
        .cyclic_sector(&loading(false), ENGINE_ORDER)
        .unwrap();
    let resonance = nodal_diameter_resonance(&sector);
    (0..POINTS)
        .map(|i| resonance * (0.92 + 0.16 * i as f64 / (POINTS - 1) as f64))
        .collect()
}

/// An upward scan of `structure` (each solve warm-started from the previous converged
/// one): the state of every point (`None` where a solve did not converge).
fn scan(structure: &Structure) -> Vec<Option<Vec<f64>>> {
    let mut warm: Option<Vec<f64>> = None;
    (frequencies().into_iter())
        .map(|omega| {
            let solution = solve(structure, omega, &run(), warm.as_deref()).unwrap();
            warm = solution.converged().then(|| solution.state.clone());
            warm.clone()
        })
        .collect()
}

/// The most points of one scan that may fail to converge (measured: 1 on two of the nine
/// scans, those of the tuned disk with the casing; 0 on the others).
const MAX_UNCONVERGED: usize = 1;

/// The largest tip amplitude over a scan's points and `blades` blades, at most
/// [`MAX_UNCONVERGED`] of them unconverged (a peak over the converged points alone could
/// miss the resonance).
fn scan_peak(structure: &Structure, blades: usize) -> f64 {
    let n = structure.model.dofs();
    let states = scan(structure);
    let unconverged = states.iter().filter(|s| s.is_none()).count();
    eprintln!("unconverged points {unconverged} of {}", states.len());
    assert!(
        unconverged <= MAX_UNCONVERGED,
        "{unconverged} points did not converge"
    );
    (states.iter().flatten()).fold(0.0f64, |m, u| m.max(largest_tip(u, n, blades)))
}

/// The tuned disk's peak by one cyclic sector (its reduced dof 1 is blade 0's tip; every
/// blade does its motion, delayed).
fn tuned_sector_peak(casing: bool) -> f64 {
    let (sector, _) = BladedDisk::tuned(BLADES)
        .cyclic_sector(&loading(casing), ENGINE_ORDER)
        .unwrap();
    scan_peak(&sector.structure(1).unwrap(), 1)
}

/// The harmonic-major coefficients of the linear response `(K - w^2 M + i w D) z = f_1`
/// (dense complex LU; `f = c cos + s sin` is `Re((c - i s) e^{i w t})`, so `u_c = Re z`
/// and `u_s = -Im z`), zero on the harmonics the load does not drive.
fn dense_linear(model: &StructuralModel, w: f64) -> Vec<f64> {
    let n = model.dofs();
    let (k, m, d) = dense_kmd(model);
    let a = DMatrix::from_fn(n, n, |i, j| {
        Complex::new(k[(i, j)] - w * w * m[(i, j)], w * d[(i, j)])
    });
    let (c, s) = model.load.harmonic(1).unwrap();
    let f = DVector::from_fn(n, |i, _| Complex::new(c[i], -s[i]));
    let z = a.lu().solve(&f).unwrap();
    let mut u = vec![0.0; n * (2 * HARMONICS + 1)];
    for i in 0..n {
        u[n + i] = z[i].re;
        u[2 * n + i] = -z[i].im;
    }
    u
}

/// The mistuning patterns of amplitude `m`: the builder's `m sin(2.3 j)`, alternate
/// `(-1)^j m` and one rogue blade (blade 0 at `-m`).
fn patterns(m: f64) -> Vec<(&'static str, Vec<f64>)> {
    let sine = BladedDisk {
        blades: BLADES,
        mistuning: m,
    }
    .deterministic_mistuning();
    let alternate = (0..BLADES)
        .map(|j| if j % 2 == 0 { m } else { -m })
        .collect();
    let rogue = (0..BLADES).map(|j| if j == 0 { -m } else { 0.0 }).collect();
    vec![
        ("builder's", sine),
        ("alternate", alternate),
        ("rogue blade", rogue),
    ]
}

#[test]
fn without_contact_every_point_of_a_mistuned_disks_scan_is_the_dense_linear_solve_and_so_is_its_amplification_factor(
) {
    let tuned_peak = tuned_sector_peak(false);
    let tuned_full = mistuned_disk(false, &[0.0; BLADES]);
    let n = tuned_full.model.dofs();
    let dense_tuned_peak = (frequencies().iter())
        .map(|&w| largest_tip(&dense_linear(&tuned_full.model, w), n, BLADES))
        .fold(0.0f64, f64::max);
    // A linear solve converged to 1e-13 against a dense LU of a damped, well-conditioned
    // dynamic stiffness: both are exact to rounding, 1e-10 leaves a wide margin.
    assert!(((tuned_peak - dense_tuned_peak) / dense_tuned_peak).abs() < 1e-10);
    for (name, pattern) in patterns(0.05) {
        let full = mistuned_disk(false, &pattern);
        let (mut peak, mut dense_peak) = (0.0f64, 0.0f64);
        for (state, w) in scan(&full).iter().zip(frequencies()) {
            let u = state.as_ref().expect("a linear solve converges");
            let exact = dense_linear(&full.model, w);
            let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let gap = (u.iter().zip(&exact)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(gap < 1e-10 * scale, "{name} at {w}: {gap:e}");
            peak = peak.max(largest_tip(u, n, BLADES));
            dense_peak = dense_peak.max(largest_tip(&exact, n, BLADES));
        }
        let (factor, dense_factor) = (peak / tuned_peak, dense_peak / dense_tuned_peak);
        eprintln!("linear, {name} 0.05: amplification factor {factor:.4}");
        assert!(
            (factor - dense_factor).abs() < 1e-10,
            "{name}: {factor} {dense_factor}"
        );
    }
}

#[test]
fn with_the_casing_the_tuned_disk_scanned_whole_is_the_sector_and_a_mistuning_turned_by_one_blade_has_the_same_amplification(
) {
    let tuned_peak = tuned_sector_peak(true);
    let full_peak = scan_peak(&mistuned_disk(true, &[0.0; BLADES]), BLADES);
    // The sector poses the full disk's equations (samples a multiple of N): the scans meet
    // the same points to the solver's 1e-13, the amplification factor of the tuned disk is 1.
    assert!(
        ((full_peak - tuned_peak) / tuned_peak).abs() < 1e-10,
        "{full_peak} {tuned_peak}"
    );
    for (name, pattern) in patterns(0.02) {
        let peak = scan_peak(&mistuned_disk(true, &pattern), BLADES);
        let mut turned = pattern.clone();
        turned.rotate_left(1);
        let turned_peak = scan_peak(&mistuned_disk(true, &turned), BLADES);
        let factor = peak / tuned_peak;
        eprintln!("casing, {name} 0.02: peak {peak:.6}, amplification factor {factor:.4}");
        // The turned disk's equations are the first's with the blades renumbered and the
        // period shifted by a whole number of samples: the same scan to the solver's 1e-13.
        assert!(
            ((peak - turned_peak) / peak).abs() < 1e-10,
            "{name}: {peak} {turned_peak}"
        );
    }
}
