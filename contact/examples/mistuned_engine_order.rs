//! A mistuned bladed disk under an engine-order excitation, swept on the full model (a
//! mistuned disk has no cyclic symmetry) by pseudo-arclength continuation beside the tuned
//! disk swept on one cyclic sector: the branch's points, folds and whether it reached the
//! upper bound, the peak of the largest blade-tip amplitude located along the branch
//! (`sweep::peak`), and its amplification factor against the tuned sector's peak.
//!
//! 24 blades, a casing contact on every blade (gap 1, three times the shipped load), engine
//! order 3, 5 harmonics, 72 samples (a multiple of `N / gcd(N, EO) = 8`), swept from 0.92
//! to 1.30 times nodal diameter 3's resonance (`SweepSettings::new` steps, no stability):
//! the casing moves the tuned peak above the resonance, and the window's upper end is past
//! it, so the tuned sector's peak is an interior maximum of its branch (checked: a peak at
//! the window's end stops the example with an error).
//! Each peak is checked by a fixed-frequency solve at its frequency started from the
//! peak's state moved by 1e-3 (the tuned sector's on the full tuned disk, from the
//! recovered state): the relative difference of the largest blade-tip amplitude is
//! printed. Beside each branch, the former upward scan (161 frequencies, warm starts): its
//! largest amplitude and its failed solves.
//!
//! The builder's pattern `delta_j = m sin(2.3 j)` (`structures::BladedDisk`) at several
//! amplitudes `m`, then other patterns at 0.01 and 0.05: random (uniform in `[-m, m]`
//! from a seeded xorshift generator, seed 1), alternate (`(-1)^j m`) and one rogue blade
//! (blade 0 at `-m`, the others tuned).
//!
//! `cargo run --release --example mistuned_engine_order [-- --write]`; `--write` puts the
//! tables into `docs/mistuning_patterns.md`.

use std::time::Instant;

use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::structures::{BladedDisk, DiskLoading};
use semismooth_contact::sweep::peak::{locate_peak, PeakLocation};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

const BLADES: usize = 24;
const HARMONICS: usize = 5;
const ENGINE_ORDER: usize = 3;
/// Frequencies of each scan.
const POINTS: usize = 161;
/// Instants on which a tip amplitude is read: the sweep's own (`solve::HB_OUTPUT_POINTS`),
/// so that the branch points and the peak search's solves measure alike.
const INSTANTS: usize = 1024;
/// The sweep window in units of the nodal-diameter resonance: its upper end is past the
/// tuned sector's peak, which the casing moves above the resonance.
const WINDOW: (f64, f64) = (0.92, 1.30);

fn settings() -> SolverSettings {
    SolverSettings {
        harmonics: HARMONICS,
        time_samples: 72,
        tolerance: 1e-12,
        c: Some(5.0),
        estimate_error: false,
        ..SolverSettings::default()
    }
}

/// `max_t |u(t)|` of one dof from its harmonic-major coefficients (`n` dofs), on
/// [`INSTANTS`] instants of the period.
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

/// The largest tip amplitude of the state `u` (`n` dofs) over the dofs `tips`, and the
/// position in `tips` of the tip that has it.
fn largest_tip(u: &[f64], n: usize, tips: &[usize]) -> (usize, f64) {
    (tips.iter().enumerate())
        .map(|(j, &dof)| (j, amplitude(u, n, dof)))
        .fold(
            (0, 0.0),
            |best, (j, a)| if a > best.1 { (j, a) } else { best },
        )
}

/// An upward scan of `structure` over `POINTS` frequencies from `from` to `to`, each solve
/// warm-started from the previous one (so it follows the upper branch of an overhang until
/// it jumps): the largest amplitude over the points and the tips `tips`, and the solves
/// that did not converge.
fn scan_peak(structure: &Structure, (from, to): (f64, f64), tips: &[usize]) -> (f64, usize) {
    let n = structure.model.dofs();
    let (mut largest, mut failed, mut warm): (f64, usize, Option<Vec<f64>>) = (0.0, 0, None);
    for i in 0..POINTS {
        let omega = from + (to - from) * i as f64 / (POINTS - 1) as f64;
        let solution = solve(structure, omega, &settings(), warm.as_deref()).expect("a solve");
        if !solution.converged() {
            failed += 1;
            warm = None;
            continue;
        }
        largest = largest.max(largest_tip(&solution.state, n, tips).1);
        warm = Some(solution.state);
    }
    (largest, failed)
}

/// A branch and its peak over the blades.
struct Traced {
    response: FrequencyResponse,
    /// The branch's continuation time, seconds.
    seconds: f64,
    /// The tip dof whose amplitude peaks, and the peak located along the branch on it.
    tip: usize,
    omega: f64,
    amplitude: f64,
    location: PeakLocation,
    /// The state of the branch point nearest the peak (the largest of the branch's).
    nearest: Vec<f64>,
}

/// The branch of `structure` over the window (units of `resonance`), and its peak
/// over the tip dofs `tips`: the tip of the largest amplitude over the branch points is
/// observed, and `sweep::peak::locate_peak` locates the peak between the branch points on
/// it.
fn trace(structure: &Structure, resonance: f64, tips: &[usize]) -> Traced {
    let ratio = resonance / structure.omega_1;
    let sweep = SweepSettings {
        stability: false,
        ..SweepSettings::new(WINDOW.0 * ratio, WINDOW.1 * ratio)
    };
    let start = Instant::now();
    let mut response = frequency_response(structure, &settings(), &sweep, None).expect("a sweep");
    let seconds = start.elapsed().as_secs_f64();
    let n = structure.model.dofs();
    let (mut blade, mut best) = (0, f64::NEG_INFINITY);
    for point in &response.points {
        let (j, a) = largest_tip(&point.state, n, tips);
        if a > best {
            (blade, best) = (j, a);
        }
    }
    let observed = Structure {
        observed_dof: tips[blade],
        ..structure.clone()
    };
    for point in &mut response.points {
        point.amplitude = amplitude(&point.state, n, tips[blade]);
    }
    let peak = locate_peak(&observed, &settings(), &response).expect("a branch with points");
    let (i, _) = response.peak().expect("a branch with points");
    let nearest = response.points[i].state.clone();
    Traced {
        response,
        seconds,
        tip: tips[blade],
        omega: peak.omega,
        amplitude: peak.amplitude,
        location: peak.location,
        nearest,
    }
}

/// The relative difference between the peak amplitude of `traced` and the largest tip
/// amplitude (over `tips`) of `check` solved at the peak's frequency from `start` (the
/// state of the branch point nearest the peak, or the full disk's recovered from it) moved
/// by 1e-3; NaN when that solve does not converge.
fn fixed_frequency_gap(check: &Structure, traced: &Traced, start: &[f64], tips: &[usize]) -> f64 {
    let moved: Vec<f64> = start.iter().map(|v| v * 1.001).collect();
    let solution = solve(check, traced.omega, &settings(), Some(&moved)).expect("a solve");
    if !solution.converged() {
        return f64::NAN;
    }
    let (_, largest) = largest_tip(&solution.state, check.model.dofs(), tips);
    (largest - traced.amplitude).abs() / traced.amplitude
}

/// The short name of where a peak was found.
fn location_name(location: &PeakLocation) -> String {
    match location {
        PeakLocation::Located => "between points".into(),
        PeakLocation::AtEdge => "at the branch's end".into(),
        PeakLocation::AtFold => "at a fold".into(),
        PeakLocation::NotLocated(reason) => format!("largest point ({reason})"),
        other => format!("{other:?}"),
    }
}

/// Where a branch ended: the upper bound, or the termination and the last point's
/// frequency (units of `resonance`).
fn end(traced: &Traced, resonance: f64) -> String {
    let r = &traced.response;
    let last = r.points.last().map_or(f64::NAN, |p| p.omega / resonance);
    if r.converged() {
        "reached the upper bound".into()
    } else if last <= WINDOW.0 + 1e-12 {
        format!("turned back to the lower bound {last:.2}")
    } else {
        format!("{} (last point {last:.6})", r.termination)
    }
}

/// One row of a table: a disk's branch and peak, its amplification factor against the
/// tuned peak, the fixed-frequency check and the scan beside it.
struct Row {
    name: String,
    m: f64,
    traced: Traced,
    gap: f64,
    scan: (f64, usize),
}

/// The header of the tables.
const HEADER: &str = "| pattern | m | points | folds | end of the branch | peak omega / omega_r | \
    peak tip amplitude | peak found | amplification factor | fixed-frequency check | sweep (s) \
    | scan peak (failed solves) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";

impl Row {
    /// The row's markdown line, frequencies in units of `resonance`.
    fn line(&self, tuned: f64, resonance: f64) -> String {
        let t = &self.traced;
        let (scan, failed) = self.scan;
        format!(
            "| {} | {} | {} | {} | {} | {:.6} | {:.6} | {} | {:.4} | {:.1e} | {:.2} | \
             {scan:.6} ({failed}) |\n",
            self.name,
            self.m,
            t.response.points.len(),
            t.response.folds.len(),
            end(t, resonance),
            t.omega / resonance,
            t.amplitude,
            location_name(&t.location),
            t.amplitude / tuned,
            self.gap,
            t.seconds,
        )
    }
}

/// Seed of the random pattern.
const SEED: u64 = 1;

/// Uniform numbers in `[0, 1)` from the xorshift64 generator seeded `seed` (no dependency:
/// the pattern is the same on every machine).
fn uniform(seed: u64, count: usize) -> Vec<f64> {
    let mut x = seed.max(1);
    (0..count)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// The mistuning patterns of amplitude `m` over `blades` blades, with their names.
fn patterns(m: f64, blades: usize) -> Vec<(&'static str, Vec<f64>)> {
    let sine = (0..blades).map(|j| m * (2.3 * j as f64).sin()).collect();
    let random = uniform(SEED, blades)
        .iter()
        .map(|u| m * (2.0 * u - 1.0))
        .collect();
    let alternate = (0..blades)
        .map(|j| if j % 2 == 0 { m } else { -m })
        .collect();
    let rogue = (0..blades).map(|j| if j == 0 { -m } else { 0.0 }).collect();
    vec![
        ("builder's m sin(2.3 j)", sine),
        ("random, seed 1", random),
        ("alternate", alternate),
        ("one rogue blade", rogue),
    ]
}

/// The full disk of `pattern` under `loading` and the engine-order load.
fn mistuned_disk(loading: &DiskLoading, pattern: &[f64]) -> Structure {
    let disk = BladedDisk::tuned(pattern.len());
    let mut full = (disk.structure_with_mistuning(loading, pattern)).expect("the disk");
    full.model.load = (full.model.load.clone())
        .delayed_by_sector(&disk.sector_dofs(), ENGINE_ORDER)
        .expect("the disk's sectors");
    full
}

/// The row of the full disk of `pattern` (amplitude `m`): its branch, its peak checked
/// at fixed frequency, the scan beside it.
fn mistuned_row(
    loading: &DiskLoading,
    (name, m): (&str, f64),
    pattern: &[f64],
    resonance: f64,
) -> Row {
    let full = mistuned_disk(loading, pattern);
    let tips: Vec<usize> = (0..BLADES).map(BladedDisk::tip).collect();
    let mut row = Row {
        name: name.to_string(),
        m,
        traced: trace(&full, resonance, &tips),
        gap: f64::NAN,
        scan: scan_peak(&full, (WINDOW.0 * resonance, WINDOW.1 * resonance), &tips),
    };
    let peak = &row.traced;
    let observed = Structure {
        observed_dof: peak.tip,
        ..full
    };
    row.gap = fixed_frequency_gap(&observed, peak, &peak.nearest, &tips);
    row
}

/// The tuned sector's row (the reference peak): its peak checked on the full tuned disk
/// solved at the peak's frequency from the state recovered from the sector's.
fn tuned_row(loading: &DiskLoading, sector: &CyclicSector, resonance: f64) -> Row {
    let structure = sector.structure(1).expect("blade 0's tip");
    // The sector's blade 0 tip is its reduced dof 1 (one sector: every blade is it, delayed).
    let mut row = Row {
        name: "tuned (sector)".into(),
        m: 0.0,
        traced: trace(&structure, resonance, &[structure.observed_dof]),
        gap: f64::NAN,
        scan: scan_peak(
            &structure,
            (WINDOW.0 * resonance, WINDOW.1 * resonance),
            &[structure.observed_dof],
        ),
    };
    let peak = &row.traced;
    let recovered = BladedDisk::tuned(BLADES).recover_state(sector, &peak.nearest, HARMONICS);
    let full = mistuned_disk(loading, &[0.0; BLADES]);
    let tips: Vec<usize> = (0..BLADES).map(BladedDisk::tip).collect();
    row.gap = fixed_frequency_gap(&full, peak, &recovered, &tips);
    row
}

/// The markdown page of the tables (`tuned` the reference row, `amplitudes` the builder's
/// pattern at several amplitudes, `others` the patterns).
fn page(tuned: &Row, amplitudes: &[Row], others: &[Row], resonance: f64) -> String {
    let reference = tuned.traced.amplitude;
    let mut page = String::from(
        "# Mistuning patterns under engine order 3\n\n\
         Written by `cargo run --release --example mistuned_engine_order -- --write` (do not \
         edit). The 24-blade disk with a casing contact on every blade (gap 1, three times the \
         shipped load), engine order 3, 5 harmonics, 72 samples; blade `j`'s stiffness is \
         `k_b (1 + delta_j)`. Each disk is swept by pseudo-arclength continuation \
         (`sweep::frequency_response`, default steps, no stability) \
         upward from 0.92 to 1.30 times nodal diameter 3's resonance `omega_r`, the mistuned \
         ones whole, the tuned one by one cyclic sector. The tuned sector's peak is an interior \
         maximum of its branch, below the window's upper end (the example stops with an error \
         otherwise). The peak is the largest blade-tip \
         amplitude over the blades and the branch, located along the branch on the blade that \
         has it (`sweep::peak`: between branch points, at a fold, or at the branch's end); the \
         amplification factor is it against the tuned sector's peak. The fixed-frequency \
         check is the relative difference of the peak amplitude against the disk solved at \
         the peak's frequency from the nearest branch point's state moved by 1e-3 (the tuned \
         sector's on the full tuned disk, from the recovered state). The last column is the \
         former upward scan (161 frequencies, warm \
         starts): its largest amplitude and its failed solves.\n\n",
    );
    page.push_str(&format!(
        "Tuned peak (sector): {reference:.6} at {:.6} omega_r.",
        tuned.traced.omega / resonance
    ));
    let (scan, _) = tuned.scan;
    if scan > reference * (1.0 + 1e-9) {
        page.push_str(&format!(
            " The tuned scan reaches {scan:.6}, above it: the tuned branch turned back at a \
             corner below the tuned resonance's peak, and the amplification factors are \
             against the branch's peak, not the resonance's."
        ));
    }
    page.push_str("\n\n## The builder's pattern\n\n");
    page.push_str(HEADER);
    for row in std::iter::once(tuned).chain(amplitudes) {
        page.push_str(&row.line(reference, resonance));
    }
    page.push_str("\n## Patterns\n\n");
    page.push_str(HEADER);
    for row in others {
        page.push_str(&row.line(reference, resonance));
    }
    page
}

/// `Ok` when the peak of `traced` is an interior maximum of its branch: not at the
/// branch's end and below the window's upper end (units of `resonance`).
fn interior_peak(traced: &Traced, resonance: f64) -> Result<(), String> {
    let at = traced.omega / resonance;
    if matches!(traced.location, PeakLocation::AtEdge) || at >= WINDOW.1 - 1e-9 {
        return Err(format!(
            "the tuned peak {:.6} at {at:.6} omega_r is at the end of its branch or of the \
             window (upper end {}): widen the window",
            traced.amplitude, WINDOW.1
        ));
    }
    Ok(())
}

fn main() {
    let loading = DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped((0..BLADES).collect())
    };
    let (sector, _) = BladedDisk::tuned(BLADES)
        .cyclic_sector(&loading, ENGINE_ORDER)
        .expect("a sector");
    let nd = sector.nodal_diameter(1);
    let resonance = natural_frequencies(&sector.nodal_diameter_model(nd), 1).expect("modes")[0];
    let tuned = tuned_row(&loading, &sector, resonance);
    if let Err(reason) = interior_peak(&tuned.traced, resonance) {
        eprintln!("error: {reason}");
        std::process::exit(1);
    }
    let reference = tuned.traced.amplitude;
    print!("{HEADER}{}", tuned.line(reference, resonance));
    let mut amplitudes = Vec::new();
    for m in [0.0, 0.005, 0.01, 0.02, 0.05] {
        let pattern = BladedDisk {
            blades: BLADES,
            mistuning: m,
        }
        .deterministic_mistuning();
        let name = if m == 0.0 {
            "tuned (full)"
        } else {
            "builder's m sin(2.3 j)"
        };
        let row = mistuned_row(&loading, (name, m), &pattern, resonance);
        print!("{}", row.line(reference, resonance));
        amplitudes.push(row);
    }
    let mut others = Vec::new();
    for m in [0.01, 0.05] {
        for (name, pattern) in patterns(m, BLADES) {
            let row = mistuned_row(&loading, (name, m), &pattern, resonance);
            print!("{}", row.line(reference, resonance));
            others.push(row);
        }
    }
    if std::env::args().any(|a| a == "--write") {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/mistuning_patterns.md");
        let text = page(&tuned, &amplitudes, &others, resonance);
        std::fs::write(path, text).expect("docs/ is writable");
        println!("wrote {path}");
    }
}
