//! Cost of exact 3-D Coulomb contacts in SSN-HB against 1-D (normal only) contacts at the
//! same count: one solve from zero and one sweep, on a patch of `P` contact nodes.
//!
//! The patch is a chain of `P` unit-mass nodes with three dofs each (`x`, `y` in the plane,
//! `z` normal): ground springs `(1, 1, 10)`, springs 0.5 between neighbours in every
//! direction, mass-proportional damping 0.05. Each node is pressed on a flat at the gap
//! 0.05 by a static load 1 and loaded by `0.3 cos w t` along `z` and a travelling in-plane
//! load `(0.25 cos(w t - phi_j), 0.15 sin(w t - phi_j))`, `phi_j = 2 pi j / P`. With 3-D
//! contacts each node has the Coulomb disk `mu = 0.4` on `(x, y)` under the normal law on
//! `z` (three rows of `G`); with 1-D contacts only the normal law (one row). H = 20.
//!
//! The disk: 100 blades in a ring, each a disk node and a blade tip node of unit mass with
//! three dofs (`x`, `y` in the plane of the platform, `z` normal to it). Per direction: the
//! disk node on a ground spring `(1, 1, 10)`, springs 1 between neighbouring disk nodes
//! (cyclic), the blade `1 + delta_j` between disk node and tip (`delta_j = 0.02 sin(2.3 j)`,
//! the shipped mistuning), damping `0.05 M`. Each tip is pressed on its platform as a patch
//! node (static load 1, gap 0.05, `0.3 cos w t` along `z`) and loaded in the plane by an
//! engine-order-3 travelling load `(0.25 cos(w t - phi_j), 0.15 sin(w t - phi_j))`,
//! `phi_j = 2 pi 3 j / 100`: a 3-D contact (`mu = 0.4`) or a 1-D one on every blade, one
//! solve at `0.6 omega_1` with H = 10.
//!
//! `cargo run --release -p semismooth-contact --example disk_patch_timing -- [--write]
//! [--no-disk | --disk-only] [COUNTS...]` (default counts `4 16 100`) prints the markdown page; `--write`
//! writes it to `docs/frictional-contact-timing.md`. With `--penalty` it prints instead the
//! time of penalty HB's residual and Jacobian on the 3-D patch per count (the regularised
//! disk law's cost).

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::time::Instant;

use semismooth::{GeneralizedJacobian, Residual};
use semismooth_contact::builder::sparse_matrix;
use semismooth_contact::hb::{PenaltyHb, PenaltyHbOptions};
use semismooth_contact::model::{
    ContactPoint, ContactRow, FrictionalContact, HarmonicLoad, StructuralModel, Structure,
};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::sweep::frequency_response;

/// Harmonics of every patch run.
const HARMONICS: usize = 20;
/// Harmonics of the disk's solve.
const DISK_HARMONICS: usize = 10;
/// Blades of the disk.
const BLADES: usize = 100;
/// Repeats of each solve up to [`REPEATED_UP_TO`] contacts (the median is reported); larger
/// runs are solved once.
const REPEATS: usize = 3;
const REPEATED_UP_TO: usize = 16;

/// The in-plane travelling load `(0.25 cos(w t - phi), 0.15 sin(w t - phi))` and the normal
/// load `1 + 0.3 cos w t` on the node whose dofs start at `first`: `(statics, cosine, sine)`.
fn add_node_load(
    (statics, cosine, sine): (&mut [f64], &mut [f64], &mut [f64]),
    first: usize,
    phi: f64,
) {
    let (s, c) = phi.sin_cos();
    statics[first + 2] = 1.0;
    // 0.25 cos(w t - phi) = 0.25 (cos phi cos w t + sin phi sin w t); 0.15 sin(w t - phi)
    // = 0.15 (cos phi sin w t - sin phi cos w t).
    cosine[first] = 0.25 * c;
    sine[first] = 0.25 * s;
    cosine[first + 1] = -0.15 * s;
    sine[first + 1] = 0.15 * c;
    cosine[first + 2] = 0.3;
}

/// The node whose dofs start at `first` pressed on its flat: a 3-D contact (`mu = 0.4`) or
/// the normal law alone.
fn with_node_contact(model: StructuralModel, first: usize, three_d: bool) -> StructuralModel {
    let (x, y, z) = (first, first + 1, first + 2);
    if three_d {
        let tangents = [ContactRow::unit(x, 1.0), ContactRow::unit(y, 1.0)];
        let contact = FrictionalContact::unilateral(ContactRow::unit(z, 1.0), 0.05, tangents, 0.4);
        model.with_frictional_contact(contact)
    } else {
        model.with_contact(ContactPoint::new(z, 0.05))
    }
}

/// The model with mass `mass` (diagonal), stiffness triplets `k`, damping `0.05 M` and the
/// load `(statics, cosine, sine)` on harmonics 0 and 1.
fn loaded_model(
    mass: &[f64],
    k: &[(usize, usize, f64)],
    (statics, cosine, sine): (Vec<f64>, Vec<f64>, Vec<f64>),
) -> StructuralModel {
    let n = mass.len();
    let diagonal = |scale: f64| {
        let entries: Vec<_> = mass
            .iter()
            .enumerate()
            .map(|(i, v)| (i, i, scale * v))
            .collect();
        sparse_matrix(n, &entries).expect("diagonal")
    };
    let mut load = HarmonicLoad::zero(n);
    load.add_harmonic(0, &statics, &vec![0.0; n])
        .expect("the load's length");
    load.add_harmonic(1, &cosine, &sine)
        .expect("the load's length");
    StructuralModel::new(
        diagonal(1.0),
        sparse_matrix(n, k).expect("within the dofs"),
        vec![0.0; n],
    )
    .with_load(load)
    .with_damping(diagonal(0.05))
}

/// `k` gains the spring `s` from dof `i` to dof `j` (to the ground without `j`).
fn spring(k: &mut Vec<(usize, usize, f64)>, i: usize, j: Option<usize>, s: f64) {
    k.push((i, i, s));
    if let Some(j) = j {
        k.extend([(j, j, s), (i, j, -s), (j, i, -s)]);
    }
}

/// The disk of [`BLADES`] blades (module documentation), with 3-D contacts or 1-D ones.
fn disk(three_d: bool) -> Structure {
    let n = 6 * BLADES;
    let mut k = Vec::new();
    let (mut statics, mut cosine, mut sine) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for j in 0..BLADES {
        let (hub, tip, next) = (6 * j, 6 * j + 3, 6 * ((j + 1) % BLADES));
        let blade = 1.0 + 0.02 * (2.3 * j as f64).sin();
        for (axis, ground) in [1.0, 1.0, 10.0].into_iter().enumerate() {
            spring(&mut k, hub + axis, None, ground);
            spring(&mut k, hub + axis, Some(next + axis), 1.0);
            spring(&mut k, hub + axis, Some(tip + axis), blade);
        }
        let phi = 2.0 * PI * 3.0 * j as f64 / BLADES as f64;
        add_node_load((&mut statics, &mut cosine, &mut sine), tip, phi);
    }
    let mut model = loaded_model(&vec![1.0; n], &k, (statics, cosine, sine));
    for j in 0..BLADES {
        model = with_node_contact(model, 6 * j + 3, three_d);
    }
    Structure::new(model, 3).expect("a valid disk")
}

/// The patch of `count` nodes (module documentation), with 3-D contacts or 1-D ones.
fn patch(count: usize, three_d: bool) -> Structure {
    let n = 3 * count;
    let mut k = Vec::new();
    for j in 0..count {
        for (axis, ground) in [1.0, 1.0, 10.0].into_iter().enumerate() {
            let i = 3 * j + axis;
            k.push((i, i, ground));
            if j + 1 < count {
                spring(&mut k, i, Some(i + 3), 0.5);
            }
        }
    }
    let (mut statics, mut cosine, mut sine) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for j in 0..count {
        let phi = 2.0 * PI * j as f64 / count as f64;
        add_node_load((&mut statics, &mut cosine, &mut sine), 3 * j, phi);
    }
    let mut model = loaded_model(&vec![1.0; n], &k, (statics, cosine, sine));
    for j in 0..count {
        model = with_node_contact(model, 3 * j, three_d);
    }
    Structure::new(model, 0).expect("a valid patch")
}

/// Median seconds of `repeats` solves from zero at `0.6 omega_1`, and the Newton
/// iterations and GMRES iterations of one; `Err` with the reason when a solve fails.
fn solve_seconds(
    structure: &Structure,
    settings: &SolverSettings,
    repeats: usize,
) -> Result<(f64, usize, u64), String> {
    let omega = 0.6 * structure.omega_1;
    let mut seconds = Vec::with_capacity(repeats);
    let (mut iterations, mut gmres) = (0, 0);
    for _ in 0..repeats {
        let start = Instant::now();
        let solution = solve(structure, omega, settings, None).map_err(|e| e.to_string())?;
        seconds.push(start.elapsed().as_secs_f64());
        if !solution.converged() {
            return Err(format!(
                "not converged after {:.0} s, {} iterations: {:?}",
                start.elapsed().as_secs_f64(),
                solution.iterations,
                solution.termination
            ));
        }
        iterations = solution.iterations;
        gmres = solution.counters.krylov_iterations;
    }
    seconds.sort_by(f64::total_cmp);
    Ok((seconds[repeats / 2], iterations, gmres))
}

/// Seconds and points of one sweep over `omega / omega_1` in `[0.5, 0.7]` without stability.
fn sweep_seconds(structure: &Structure, settings: &SolverSettings) -> (f64, usize) {
    let sweep = SweepSettings {
        stability: false,
        ..SweepSettings::new(0.5, 0.7)
    };
    let start = Instant::now();
    let response = frequency_response(structure, settings, &sweep, None).expect("a sweep");
    let seconds = start.elapsed().as_secs_f64();
    assert!(response.converged(), "{:?}", response.termination);
    (seconds, response.points.len())
}

/// The machine: CPU model, cores and the load average when the run started.
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            let line = t.lines().find(|l| l.starts_with("model name"))?;
            Some(line.split(':').nth(1)?.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg")
        .map(|t| t.split_whitespace().next().unwrap_or("?").to_string())
        .unwrap_or_else(|_| "?".into());
    format!("{cpu}, {cores} cores, load average {load} at the start")
}

/// The table rows of the patch of `count` nodes: 1-D and 3-D, solve and sweep, the ratios
/// 3-D over 1-D.
fn patch_rows(count: usize, settings: &SolverSettings) -> String {
    let repeats = if count <= REPEATED_UP_TO { REPEATS } else { 1 };
    let mut rows = Vec::new();
    for three_d in [false, true] {
        let structure = patch(count, three_d);
        let (solve, iterations, gmres) =
            solve_seconds(&structure, settings, repeats).expect("the patch converges");
        let (sweep, points) = sweep_seconds(&structure, settings);
        rows.push((
            three_d,
            structure.model.dofs(),
            solve,
            (iterations, gmres),
            sweep / points as f64,
            points,
        ));
    }
    let (one, three) = (rows[0], rows[1]);
    let mut page = String::new();
    for (three_d, dofs, solve, (iterations, gmres), per_point, points) in rows {
        let kind = if three_d { "3-D" } else { "1-D" };
        let ratios = if three_d {
            format!("{:.2} | {:.2}", three.2 / one.2, three.4 / one.4)
        } else {
            "1 | 1".into()
        };
        let _ = writeln!(
            page,
            "| {count} | {kind} | {dofs} | {solve:.4} | {iterations} | {gmres} | {points} | {per_point:.4} | {ratios} |"
        );
    }
    page
}

/// The table rows of the disk: one solve with a 1-D and with a 3-D contact on every blade.
fn disk_rows() -> String {
    let settings = SolverSettings::with_harmonics(DISK_HARMONICS);
    let mut page = String::new();
    let mut first = f64::NAN;
    for three_d in [false, true] {
        let structure = disk(three_d);
        let kind = if three_d { "3-D" } else { "1-D" };
        let (solve, iterations, gmres) = match solve_seconds(&structure, &settings, 1) {
            Ok(run) => run,
            Err(why) => {
                let _ = writeln!(
                    page,
                    "| {BLADES} | {kind} | {} | {why} |",
                    structure.model.dofs()
                );
                continue;
            }
        };
        if !three_d {
            first = solve;
        }
        let _ = writeln!(
            page,
            "| {BLADES} | {kind} | {} | {solve:.2} | {iterations} | {gmres} | {:.2} |",
            structure.model.dofs(),
            solve / first
        );
    }
    page
}

/// Residual and Jacobian evaluations per count timed in penalty mode.
const PENALTY_EVALUATIONS: usize = 200;

/// The table of penalty HB's residual-and-Jacobian evaluation on the 3-D patch per count in
/// `counts` (seconds per evaluation over [`PENALTY_EVALUATIONS`], at `0.6 omega_1`, H =
/// [`HARMONICS`], at a state that closes and slides part of the period), the regularised
/// disk law's sampling and blocks being most of it.
fn penalty_rows(counts: &[usize]) -> String {
    let mut page = String::from("| P | dofs | s per residual and Jacobian |\n|---|---|---|\n");
    for &count in counts {
        let structure = patch(count, true);
        let model = &structure.model;
        let mut options = PenaltyHbOptions::for_model(model);
        options.harmonics = HARMONICS;
        let mut problem = PenaltyHb::new(model, 0.6 * structure.omega_1, &options)
            .expect("a valid penalty problem");
        // A smooth state: every dof's harmonics 0, 1 and 2 nonzero (0.1 sin(1.7 i)).
        let u: Vec<f64> = (0..problem.dim())
            .map(|i| {
                if i < 5 * model.dofs() {
                    0.1 * (1.7 * i as f64).sin()
                } else {
                    0.0
                }
            })
            .collect();
        let (mut out, mut jac) = (vec![0.0; u.len()], problem.new_jacobian());
        let start = Instant::now();
        for _ in 0..PENALTY_EVALUATIONS {
            problem.residual(&u, &mut out).expect("a finite residual");
            problem.jacobian(&u, &mut jac).expect("a finite Jacobian");
        }
        let seconds = start.elapsed().as_secs_f64() / PENALTY_EVALUATIONS as f64;
        let _ = writeln!(page, "| {count} | {} | {seconds:.5} |", model.dofs());
    }
    page
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let write = args.iter().any(|a| a == "--write");
    let with_disk = !args.iter().any(|a| a == "--no-disk");
    let counts: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    let counts = if args.iter().any(|a| a == "--disk-only") {
        Vec::new()
    } else if counts.is_empty() {
        vec![4, 16, 100]
    } else {
        counts
    };
    if args.iter().any(|a| a == "--penalty") {
        print!("{}", penalty_rows(&counts));
        return;
    }
    let settings = SolverSettings::with_harmonics(HARMONICS);
    let mut page = String::new();
    let _ = writeln!(
        page,
        "# Cost of exact 3-D frictional contacts\n\n\
         Written by `cargo run --release -p semismooth-contact --example disk_patch_timing -- \
         --write` (the models are described there): a patch of P contact nodes, each either a \
         3-D contact (normal law and Coulomb disk, three rows of G) or a 1-D contact (normal \
         law only, one row), SSN-HB at H = {HARMONICS} through the library's `solve` (median of \
         {REPEATS} up to P = {REPEATED_UP_TO}, one solve above) and `frequency_response` (omega / \
         omega_1 from 0.5 to 0.7, no stability), the solve at 0.6 from zero. Ratios are 3-D over \
         1-D, measured in the same run. GMRES iterations are those of the matrix-free condensed \
         solve, which the structured solver takes above {} condensed unknowns (0: dense LU), \
         each Newton step's GMRES stopped by the inexact-Newton forcing term \
         (Eisenstat-Walker, never below a tenth of the Newton tolerance).\n\n\
         Machine: {}.\n\n\
         | P | contacts | dofs | solve s | Newton iterations | GMRES iterations | sweep points | s per sweep point | solve ratio | per-point ratio |\n\
         |---|---|---|---|---|---|---|---|---|---|",
        semismooth_contact::hb::KRYLOV_THRESHOLD,
        machine()
    );
    for &count in &counts {
        page += &patch_rows(count, &settings);
    }
    if with_disk {
        let _ = writeln!(
            page,
            "\nThe {BLADES}-blade disk (module documentation of the example) with a contact on \
             every blade's tip, one SSN-HB solve from zero at 0.6 omega_1 with H = \
             {DISK_HARMONICS}; the ratio is 3-D over 1-D.\n\n\
             | blades | contacts | dofs | solve s | Newton iterations | GMRES iterations | solve ratio |\n\
             |---|---|---|---|---|---|---|"
        );
        page += &disk_rows();
    }
    let _ = writeln!(
        page,
        "\nThe 1-D patch stays closed over the period at these loads (its normal force \
         0.5 + 0.3 cos w t), so its contact law is linear there and Newton takes 2 \
         iterations; the 3-D patch sticks and slips with a turning direction and takes tens \
         of iterations from zero. Up to 2000 condensed unknowns each iteration factors the \
         dense condensed system of 3P(2H + 1) unknowns (1968 at P = 16); at P = 100 \
         (12,300 unknowns, a dense LU of 1.2 GB and 1.2e12 flops per iteration) the \
         condensed system is solved matrix-free by GMRES, preconditioned by one block per \
         contact node that keeps the disk's 2 x 2 coupling and its column on the normal force. \
         On the disk (6300 condensed unknowns) most tips stick at the solution, where the \
         blocks miss the coupling through the ring: GMRES there falls back on the dense \
         condensed matrix of a recent iterate as its preconditioner, refactored when it needs \
         more than 30 iterations, and that factorization is most of the disk's time."
    );
    print!("{page}");
    if write {
        std::fs::write("docs/frictional-contact-timing.md", &page).expect("docs/ is writable");
        println!("wrote docs/frictional-contact-timing.md");
    }
}
