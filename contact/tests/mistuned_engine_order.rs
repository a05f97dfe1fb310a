//! A mistuned bladed disk under an engine-order excitation on the full model beside the
//! tuned disk on one cyclic sector, and the amplification factor (the largest blade-tip
//! amplitude over the blades against the tuned sector's peak). Without contact, scanned:
//! every point is the dense complex solve of the linear disk. With the casing, swept by
//! pseudo-arclength continuation with the peak located along the branch: the tuned disk
//! swept whole is the sector, each mistuned disk's branch is the one of the same pattern
//! turned by one blade (the engine-order load makes that disk's response the first one's,
//! one blade on and `EO T / N` later), and each peak is a fixed-frequency solution.

use nalgebra::{Complex, DMatrix, DVector};
use semismooth_contact::model::{StructuralModel, Structure};
use semismooth_contact::settings::{LinearSolverChoice, SolverSettings, SweepSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::structures::{BladedDisk, DiskLoading};
use semismooth_contact::sweep::frequency_response;
use semismooth_contact::sweep::peak::{locate_peak, PeakLocation};

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
/// Instants of the period on which a blade's amplitude is read in a scan: a multiple of
/// `N`, so the delay `EO T / N` between blades is a whole number of them.
const INSTANTS: usize = 144;
/// Instants on which a branch point's amplitude is read: the sweep's own
/// (`solve::HB_OUTPUT_POINTS`, a multiple of `N` too), so that the branch points and the
/// peak search's solves measure alike.
const BRANCH_INSTANTS: usize = 1024;

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
    amplitude_on(u, n, dof, INSTANTS)
}

/// `max_t |u(t)|` of `dof` on `instants` instants of the period.
fn amplitude_on(u: &[f64], n: usize, dof: usize, instants: usize) -> f64 {
    (0..instants)
        .map(|i| {
            let t = 2.0 * std::f64::consts::PI * i as f64 / instants as f64;
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

/// The largest relative difference between a peak's amplitude and the fixed-frequency
/// solve at its frequency: both solved to 1e-13 (measured at most 2.4e-14, at the window's
/// end and at folds).
const CHECK_TOLERANCE: f64 = 1e-10;

/// The most mistuned branches (of three) that may stop short of the upper bound. Measured
/// 2: the builder's pattern and the rogue blade turn at a fold above the casing's grazing
/// and go back down to the lower bound (309 and 306 points, one fold each); the alternate
/// pattern reaches the upper bound (168 points).
const MAX_SHORT_BRANCHES: usize = 2;

/// A swept branch and its peak over the blades.
struct Traced {
    points: usize,
    folds: usize,
    reached_upper_bound: bool,
    omega: f64,
    amplitude: f64,
    location: PeakLocation,
}

/// The branch of `structure` over 8 % either side of the resonance (default steps but the
/// smallest 1e-7: with the default 1e-5 the rogue blade's branch and its twin turned by one
/// blade part at a corner, measured 389 points reaching the upper bound against 341
/// stalled, so rounding decides there), its peak over the tip dofs `tips` located along it
/// on the tip that has the largest branch point (`sweep::peak`), and that peak checked: the
/// largest tip amplitude of `structure` solved at the peak's frequency from the nearest
/// branch point moved by 1e-3, relative to the peak's.
fn traced(structure: &Structure, tips: &[usize]) -> (Traced, f64) {
    let omegas = frequencies();
    let ratio = |w: f64| w / structure.omega_1;
    let sweep = SweepSettings {
        stability: false,
        min_step: 1e-7,
        ..SweepSettings::new(ratio(omegas[0]), ratio(omegas[POINTS - 1]))
    };
    let mut response = frequency_response(structure, &run(), &sweep, None).unwrap();
    let n = structure.model.dofs();
    let tip_amplitude = |u: &[f64], dof| amplitude_on(u, n, dof, BRANCH_INSTANTS);
    let (mut tip, mut best) = (tips[0], f64::NEG_INFINITY);
    for point in &response.points {
        for &dof in tips {
            if tip_amplitude(&point.state, dof) > best {
                (tip, best) = (dof, tip_amplitude(&point.state, dof));
            }
        }
    }
    for point in &mut response.points {
        point.amplitude = tip_amplitude(&point.state, tip);
    }
    let observed = Structure {
        observed_dof: tip,
        ..structure.clone()
    };
    let peak = locate_peak(&observed, &run(), &response).unwrap();
    let (i, _) = response.peak().unwrap();
    let start: Vec<f64> = (response.points[i].state.iter())
        .map(|v| v * 1.001)
        .collect();
    let check = solve(&observed, peak.omega, &run(), Some(&start)).unwrap();
    assert!(check.converged(), "{:?}", check.termination);
    let largest = (tips.iter()).fold(0.0f64, |m, &dof| m.max(tip_amplitude(&check.state, dof)));
    let traced = Traced {
        points: response.points.len(),
        folds: response.folds.len(),
        reached_upper_bound: response.converged(),
        omega: peak.omega,
        amplitude: peak.amplitude,
        location: peak.location,
    };
    eprintln!(
        "{} points, {} folds, reached {}, peak {:.6} at {:.6} ({:?}), check {:e}; {}",
        traced.points,
        traced.folds,
        traced.reached_upper_bound,
        traced.amplitude,
        traced.omega,
        traced.location,
        (largest - peak.amplitude).abs() / peak.amplitude,
        response.termination
    );
    (traced, (largest - peak.amplitude).abs() / peak.amplitude)
}

/// The tips of every blade of the full disk.
fn all_tips() -> Vec<usize> {
    (0..BLADES).map(BladedDisk::tip).collect()
}

#[test]
fn with_the_casing_the_tuned_disk_swept_whole_is_the_sector_and_a_mistuning_turned_by_one_blade_has_the_same_branch_and_peak(
) {
    let (sector, _) = BladedDisk::tuned(BLADES)
        .cyclic_sector(&loading(true), ENGINE_ORDER)
        .unwrap();
    let sector = sector.structure(1).unwrap();
    let (tuned, tuned_check) = traced(&sector, &[sector.observed_dof]);
    let (full, full_check) = traced(&mistuned_disk(true, &[0.0; BLADES]), &all_tips());
    // The sector poses the full disk's equations (samples a multiple of N): both peaks are
    // the solution at one frequency (the window's end, or located to 1e-5 omega_1 on the
    // same curve), solved to 1e-13.
    assert!(
        ((full.amplitude - tuned.amplitude) / tuned.amplitude).abs() < 1e-10,
        "{} {}",
        full.amplitude,
        tuned.amplitude
    );
    let mut short = 0;
    for (name, pattern) in patterns(0.02) {
        let (branch, check) = traced(&mistuned_disk(true, &pattern), &all_tips());
        let mut turned = pattern.clone();
        turned.rotate_left(1);
        let (turned, _) = traced(&mistuned_disk(true, &turned), &all_tips());
        let factor = branch.amplitude / tuned.amplitude;
        eprintln!("casing, {name} 0.02: amplification factor {factor:.4}");
        // The turned disk's equations are the first's with the blades renumbered and the
        // period shifted by a whole number of samples, under which the sweep's arclength
        // is invariant: the same branch, the same peak to the solver's 1e-13.
        assert_eq!(
            (branch.points, branch.folds),
            (turned.points, turned.folds),
            "{name}"
        );
        assert!(
            ((branch.amplitude - turned.amplitude) / branch.amplitude).abs() < 1e-10,
            "{name}: {} {}",
            branch.amplitude,
            turned.amplitude
        );
        assert!(check < CHECK_TOLERANCE, "{name}: {check:e}");
        short += usize::from(!branch.reached_upper_bound);
    }
    assert!(tuned_check < CHECK_TOLERANCE && full_check < CHECK_TOLERANCE);
    assert!(
        short <= MAX_SHORT_BRANCHES,
        "{short} branches stopped short"
    );
}
