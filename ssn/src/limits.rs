//! Up-front memory estimates of a run, so that a scene too large for the machine is refused
//! before anything is allocated (exit code 2, naming the keys, the need and the limit)
//! instead of aborting on an allocation failure or being killed half-way.
//!
//! The estimates are upper bounds fitted to peak resident sizes measured on the rod
//! (`/usr/bin/time -f %M`, release build), with `N` elements, `m` contacts, `S = 2H + 1`
//! harmonic functions and `Nt` time samples:
//!
//! | method | estimate (bytes) | measured |
//! |---|---|---|
//! | HB, structured solver, dense condensed system | `300 N S + 8 (2 S Nt + 3 m S^2 + 2 (m S)^2) + 16 (H + 1) N m` | 86 MB at N = 10^4, H = 20; 289 MB at H = 80 |
//! | SSN-HB, structured solver, matrix-free condensed system (more than `KRYLOV_THRESHOLD` condensed unknowns `m S`, or `condensed-krylov`) | `600 N S + 8 (2 S Nt + 3 m S^2) + 3300 m S` (GMRES basis of up to 201 vectors), plus `8 (m S)^2 + 16 (H + 1) m^2` up to `DENSE_PRECONDITIONER_LIMIT` condensed unknowns (the dense preconditioner GMRES may fall back on) | see `examples/contact_scaling.rs` |
//! | HB, dense solver | `10 n^2` more, `n = (N + m) S` (SSN-HB) or `N S` (penalty) | 156 MB at N = 100, H = 20 (n = 4141); 570 MB at N = 200 (n = 8241) |
//! | periodic LCP | `24 (m Nt)^2 + 1000 N` | 71 MB (Lemke), 48 MB (Newton) at Nt = 2048, m = 1 |
//! | time marching | `1000 N` | 12 MB at N = 10^4 |
//!
//! plus `400 N` for the rod itself (`N` the dofs of an imported `[model]`, whose size is
//! known once its files are read: [`structure_memory`]). The limit is the memory available to new processes
//! (`MemAvailable` of `/proc/meminfo`), or the number of bytes in the environment variable
//! `SSN_MEMORY_LIMIT` when it is set (anything but a number > 0 is refused), and never
//! more than the address space the process may still map (`RLIMIT_AS`, `ulimit -v`); where
//! none is known nothing is refused.
//!
//! A run that fits in memory can still take hours: [`run_work`] estimates the operations of
//! one solve (its factorizations, the matrix-free path's GMRES, the error estimate's second
//! solve), refused above `SSN_WORK_LIMIT` (default [`DEFAULT_WORK_LIMIT`]).

use crate::scene::{default_hb_time_samples, LinearSolverChoice, Method, Scene, SolverSettings};
use semismooth_contact::model::Structure;
use semismooth_contact::solve::DiscretisationKind;

/// The dense condensed matrix (and full receptance) the matrix-free path may factor as
/// GMRES's preconditioner: `8 (m S)^2 + 16 (H + 1) m^2` bytes up to
/// [`DENSE_PRECONDITIONER_LIMIT`](semismooth_contact::hb::DENSE_PRECONDITIONER_LIMIT) condensed unknowns,
/// none above.
fn dense_preconditioner_bytes(m: f64, s: f64) -> f64 {
    if m * s <= semismooth_contact::hb::DENSE_PRECONDITIONER_LIMIT as f64 {
        8.0 * (m * s).powi(2) + 8.0 * (s + 1.0) * m * m
    } else {
        0.0
    }
}

/// What a run needs, in words and bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryEstimate {
    /// Estimated peak memory in bytes (a float: hostile settings overflow any integer).
    pub bytes: f64,
    /// The dominant storage, in words.
    pub what: String,
    /// The scene keys that drive it (what to reduce).
    pub keys: &'static str,
}

/// Bytes of the rod model itself (sparse K, M, D, load vectors) per element.
const ROD_BYTES_PER_ELEMENT: f64 = 400.0;

/// Estimated peak memory of one run of `settings` on a rod of `elements` elements with
/// `contacts` contact points.
pub fn run_memory(elements: usize, contacts: usize, settings: &SolverSettings) -> MemoryEstimate {
    let n = elements as f64;
    let m = contacts as f64;
    let rod = ROD_BYTES_PER_ELEMENT * n;
    match settings.method.discretisation() {
        DiscretisationKind::Harmonics => {
            let h = settings.harmonics as f64;
            let s = 2.0 * h + 1.0;
            let nt = settings.time_samples as f64;
            let aft = 8.0 * (2.0 * s * nt + 3.0 * m * s * s + 2.0 * (m * s).powi(2));
            let structured = 300.0 * n * s + aft + 16.0 * (h + 1.0) * n * m;
            let condensed = settings.linear_solver.condensed();
            let krylov = condensed.is_some_and(|c| {
                c.uses_krylov(
                    contacts,
                    settings.harmonics,
                    settings.method.carries_contact_forces(),
                )
            });
            match settings.linear_solver {
                _ if krylov => MemoryEstimate {
                    bytes: rod
                        + 600.0 * n * s
                        + 8.0 * (2.0 * s * nt + 3.0 * m * s * s)
                        + 3300.0 * m * s
                        + dense_preconditioner_bytes(m, s)
                        // The static compliance between contacts behind the default `c`.
                        + 8.0 * m * m,
                    what: format!(
                        "per-harmonic factorizations of {elements} dofs x {} harmonic functions \
                         (matrix-free condensed system of {:.0} unknowns)",
                        2 * settings.harmonics as u128 + 1,
                        m * s
                    ),
                    keys: "rod.elements or the model's size, solver.harmonics",
                },
                LinearSolverChoice::Structured
                | LinearSolverChoice::CondensedDense
                | LinearSolverChoice::CondensedKrylov => MemoryEstimate {
                    bytes: rod + structured,
                    what: format!(
                        "per-harmonic factorizations of {elements} dofs x {} harmonic functions",
                        2 * settings.harmonics as u128 + 1
                    ),
                    keys: "rod.elements, solver.harmonics (and the number of contacts)",
                },
                LinearSolverChoice::Dense => {
                    let unknowns = if settings.method.carries_contact_forces() {
                        (n + m) * s
                    } else {
                        n * s
                    };
                    MemoryEstimate {
                        bytes: rod + structured + 10.0 * unknowns * unknowns,
                        what: format!(
                            "a dense Jacobian and its LU on {unknowns:.0} unknowns \
                             (solver.linear_solver = \"dense\"; \"structured\" needs about {})",
                            human(rod + structured)
                        ),
                        keys: "solver.linear_solver, solver.harmonics, rod.elements",
                    }
                }
            }
        }
        DiscretisationKind::TimeSamples => {
            let dim = m * settings.time_samples as f64;
            MemoryEstimate {
                bytes: rod + 24.0 * dim * dim + 1000.0 * n,
                what: format!(
                    "the dense periodic LCP matrix of {dim:.0} = contacts x time samples unknowns"
                ),
                keys: "solver.time_samples (and the number of contacts)",
            }
        }
        DiscretisationKind::StepsPerPeriod => MemoryEstimate {
            bytes: rod + 1000.0 * n,
            what: format!("time-stepping matrices of {elements} dofs"),
            keys: "rod.elements",
        },
    }
}

/// Estimated peak memory of `ssn compare` on the scene: the largest of its runs (SSN-HB up
/// to the reference's 320 harmonics, penalty HB up to 80, the LCP up to Nt = 1024, time
/// marching), each with the scene's other settings.
pub fn compare_memory(elements: usize, contacts: usize, base: &SolverSettings) -> MemoryEstimate {
    let hb = |method, harmonics: usize| SolverSettings {
        method,
        harmonics,
        time_samples: default_hb_time_samples(harmonics),
        ..base.clone()
    };
    let runs = [
        hb(Method::SsnHb, crate::accuracy_cost::REFERENCE_HARMONICS),
        hb(Method::PenaltyHb, 80),
        SolverSettings {
            method: Method::LcpSsn,
            time_samples: 1024,
            ..base.clone()
        },
        SolverSettings {
            method: Method::March,
            ..base.clone()
        },
    ];
    runs.iter()
        .map(|s| run_memory(elements, contacts, s))
        .fold(None::<MemoryEstimate>, |best, e| match best {
            Some(b) if b.bytes >= e.bytes => Some(b),
            _ => Some(e),
        })
        .expect("four runs")
}

/// A limit given in the environment variable `name`: `Ok(None)` when unset, `Err` naming
/// the variable and its value unless it is a finite number > 0.
fn limit_from_env(name: &str, unit: &str) -> Result<Option<f64>, String> {
    match std::env::var(name) {
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(v)) => Err(format!(
            "invalid {name} = {v:?}: allowed a finite number of {unit} > 0"
        )),
        Ok(v) => match v.trim().parse::<f64>() {
            Ok(b) if b.is_finite() && b > 0.0 => Ok(Some(b)),
            _ => Err(format!(
                "invalid {name} = {:?}: allowed a finite number of {unit} > 0 (e.g. 8e9)",
                crate::io::printable(&v)
            )),
        },
    }
}

/// The memory a run may use: `SSN_MEMORY_LIMIT` (bytes) when set, else `MemAvailable`;
/// in both cases at most the address space the process may still map (`RLIMIT_AS`, as
/// set by `ulimit -v`, less what is mapped already). `Err` for a `SSN_MEMORY_LIMIT` that
/// is not a number > 0.
pub fn memory_limit() -> Result<Option<f64>, String> {
    let limit = match limit_from_env("SSN_MEMORY_LIMIT", "bytes")? {
        Some(b) => Some(b),
        None => meminfo_available(),
    };
    Ok(match (limit, address_space_left()) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    })
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn meminfo_available() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    proc_kilobytes(&info, "MemAvailable:")
}

/// The value of the `/proc` field `key` given in kB, in bytes.
fn proc_kilobytes(text: &str, key: &str) -> Option<f64> {
    let kb: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix(key))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024.0)
}

/// Address space mapped beyond the resident peak the estimates bound: the allocator's
/// per-thread arenas (64 MB of address space each) and the threads' stacks.
const ADDRESS_SPACE_RESERVE: f64 = 256e6;

/// Address space the process may still map: the soft `RLIMIT_AS` (`/proc/self/limits`)
/// less the current `VmSize` and [`ADDRESS_SPACE_RESERVE`]; `None` when unlimited or
/// unknown.
fn address_space_left() -> Option<f64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let soft: f64 = limits
        .lines()
        .find_map(|l| l.strip_prefix("Max address space"))?
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let mapped = proc_kilobytes(&status, "VmSize:").unwrap_or(0.0);
    Some((soft - mapped - ADDRESS_SPACE_RESERVE).max(0.0))
}

/// Refuses `need` when it exceeds `limit`: the message names the keys, the need and the
/// limit.
pub fn check(need: &MemoryEstimate, limit: Option<f64>) -> Result<(), String> {
    match limit {
        Some(limit) if need.bytes.is_nan() || need.bytes > limit => Err(format!(
            "these settings need about {} of memory ({}), more than the {} available \
             (MemAvailable, or SSN_MEMORY_LIMIT when set, within the address-space limit of \
             ulimit -v): allowed are settings whose estimate \
             fits; reduce {}",
            human(need.bytes),
            need.what,
            human(limit),
            need.keys
        )),
        _ => Ok(()),
    }
}

/// The estimate of the command run on the rod of a `[rod]` scene (`compare` runs several
/// settings), before the rod is built. `None` for a `[model]` scene, whose size is known
/// only from its files: estimate it with [`structure_memory`] once imported.
pub fn rod_scene_memory(scene: &Scene, compare: bool) -> Option<MemoryEstimate> {
    if scene.model.is_some() {
        return None;
    }
    let (n, m) = (scene.rod.elements, scene.rod.contacts.len());
    Some(size_memory(n, m, &scene.solver, compare))
}

/// Bytes per dof of a command that solves nothing (`scene-check`, `export-model`): the
/// model ([`ROD_BYTES_PER_ELEMENT`]) and the 18 vectors of the natural frequencies'
/// subspace iteration with their sparse solves.
const MODEL_ONLY_BYTES_PER_DOF: f64 = ROD_BYTES_PER_ELEMENT + 8.0 * 18.0 * 4.0;

/// The estimate of a command that builds the structure of `dofs` dofs and solves nothing.
pub fn model_only_memory(dofs: usize) -> MemoryEstimate {
    MemoryEstimate {
        bytes: MODEL_ONLY_BYTES_PER_DOF * dofs as f64,
        what: format!("the model of {dofs} dofs"),
        keys: "rod.elements",
    }
}

/// The estimate of the command run with `settings` on a built structure (its dofs and
/// contacts; `compare` runs several settings).
pub fn structure_memory(
    structure: &Structure,
    settings: &SolverSettings,
    compare: bool,
) -> MemoryEstimate {
    let (n, m) = (structure.model.dofs(), structure.model.contacts.len());
    size_memory(n, m, settings, compare)
}

fn size_memory(
    dofs: usize,
    contacts: usize,
    settings: &SolverSettings,
    compare: bool,
) -> MemoryEstimate {
    if compare {
        compare_memory(dofs, contacts, settings)
    } else {
        run_memory(dofs, contacts, settings)
    }
}

/// Bytes in words: `1.5 GB`.
pub fn human(bytes: f64) -> String {
    const UNITS: [&str; 7] = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = bytes;
    let mut unit = 0;
    while v >= 1000.0 && unit + 1 < UNITS.len() {
        v /= 1000.0;
        unit += 1;
    }
    if v.is_finite() {
        format!("{v:.1} {}", UNITS[unit])
    } else {
        "more than can be counted".into()
    }
}

// Work (floating-point operations), next to memory: a run that fits in memory can still
// run for hours (a dense LU is cubic in its size).

/// What a run costs in floating-point operations, in words and numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkEstimate {
    /// Estimated floating-point operations (a float: hostile settings overflow integers).
    pub flops: f64,
    /// The dominant work, in words.
    pub what: String,
    /// The scene keys that drive it (what to reduce).
    pub keys: &'static str,
}

/// Operations of one penalty-HB iteration beyond the condensed system's dense LU (its sparse
/// Jacobian's factorization, residual and FFTs), per dof and cubed harmonic function count
/// `N S^3`: measured on the rod of 1,000 elements, 157 factorizations in 37.8 s at H = 200
/// (0.085 operations per `N S^3` at 2.3e10 per second) and more than 400 s at H = 400 (a
/// growth of more than 10 for 2 in H; `S^3` alone gives 8), on 2 loaded cores (load 11-13).
pub const PENALTY_JACOBIAN_FLOPS: f64 = 0.09;

/// Newton iterations counted for a solve from zero with one contact (an estimate: the shipped
/// scenes take 7 to 13, one factorization each).
const NEWTON_FACTORIZATIONS: f64 = 10.0;

/// Newton iterations counted for a solve from zero with two contacts or more, and on the
/// matrix-free path: `scenes/two_contacts.toml` took 43, the rod of 1,000 elements with 5,
/// 10, 20 and 40 evenly spaced stops (gap 0.5, H = 20) 48, 48, 47 and 52 (Newton stalls and
/// the smoothing strategy takes over), with 50 and 200 stops (matrix-free) 49 and 38.
pub const SEVERAL_CONTACTS_NEWTON_ITERATIONS: f64 = 50.0;

/// Newton iterations counted for the error estimate's second solve, started from the first
/// solve's state at the comparison's discretisation: measured 1 to 9 on the shipped scenes
/// and the rod with 5 to 50 stops (102 with 40 stops, an outlier the count leaves out).
pub const ERROR_ESTIMATE_NEWTON_ITERATIONS: f64 = 10.0;

/// Operations of one iteration of the structured solver beyond the condensed LU, per unit
/// of `N (H + 1) (m + 4)`: the receptance's `m` columns in each harmonic and about four
/// sweeps of the per-harmonic solves (residual, step, outputs). Measured on the rod of
/// 1,000 elements at H = 20 (CPU time, a load of 6 on 2 cores, 2.3e10 operations per
/// second): 5, 10 and 20 stops took 2.1e8, 3.2e8 and 8.1e8 operations an iteration, of
/// which the condensed LU 5.7e6, 4.6e7 and 3.7e8: 900 per unit fits all three within 25 %.
pub const STRUCTURED_ITERATION_FLOPS: f64 = 900.0;

/// GMRES iterations per Newton iteration and contact on the matrix-free path, between
/// [`KRYLOV_ITERATIONS_PER_NEWTON_MIN`] and [`KRYLOV_ITERATIONS_PER_NEWTON_MAX`] (the contact
/// blocks leave out the coupling between contacts, so the iterations grow with their
/// number). Measured with the `krylov_iterations` counter on rods with evenly spaced stops
/// (gap 0.5, H = 20), per Newton iteration: 48 with 10 stops on 100 elements
/// (`condensed-krylov`), 48 with 50 on 100, 200 and 1,000 elements, 244 with 200 and 295
/// with 1,000 on 1,000 elements.
pub const KRYLOV_ITERATIONS_PER_CONTACT: f64 = 1.25;

/// GMRES iterations of one Newton iteration with two contacts or more, at least (48
/// measured with 10 stops); one contact's block is the whole system and its solves take
/// one iteration each (two solves a Newton iteration are counted).
pub const KRYLOV_ITERATIONS_PER_NEWTON_MIN: f64 = 50.0;

/// GMRES iterations of one Newton iteration with many contacts (295 measured with 1,000
/// stops: restarted cycles of 200 converge in about one and a half).
pub const KRYLOV_ITERATIONS_PER_NEWTON_MAX: f64 = 300.0;

/// Operations of one GMRES iteration of the matrix-free path per unit of
/// `N (H + 1) + m S^2 + m S b` (the `H + 1` sparse solves of a product, `Q` and the contact
/// blocks, the Gram-Schmidt on the `2b` Krylov vectors of the current cycle). On the rod
/// above (CPU time, a load of 5 on 2 cores, at 2.3e10 operations per second): 200 stops
/// (no dense preconditioner: `m S = 8200` above its limit) took 30.2 s for 9,264 GMRES iterations, 63 per
/// unit; 1,000 stops 194 s for 10,617, 72 per unit.
pub const KRYLOV_PRODUCT_FLOPS: f64 = 70.0;

/// Dense factorizations of the condensed system per Newton iteration counted where the
/// matrix-free path may fall back on the dense preconditioner (two or more contacts, at
/// most `DENSE_PRECONDITIONER_LIMIT` condensed unknowns): it is refactored when GMRES
/// needs more than 30 iterations with an earlier one, and how often varies. 50 stops (2,050
/// condensed unknowns, 5.7e9 operations a factorization, 49 or 50 Newton iterations) took
/// 13.3 s of CPU on 1,000 elements with gap 0.5 (3 counted: 2.8 times that), 102 s with
/// gap 0.1 and 92 s on 100 elements (2.7 and 2.4 times the count).
pub const DENSE_PRECONDITIONER_FACTORIZATIONS_PER_ITERATION: f64 = 3.0;

/// The work of one Newton iteration of the matrix-free path, and its parts.
struct MatrixFreeIteration {
    /// All of it.
    flops: f64,
    /// GMRES iterations.
    krylov: f64,
    /// Operations of one GMRES iteration.
    product: f64,
    /// Operations of the dense preconditioner's factorizations.
    dense: f64,
}

/// One Newton iteration of the matrix-free path on `n` dofs, `m` contacts and `harmonics`
/// harmonics (`S = 2H + 1`): `k` GMRES (2 for one contact, else
/// [`KRYLOV_ITERATIONS_PER_CONTACT`] `m` within its bounds)
/// iterations of [`KRYLOV_PRODUCT_FLOPS`] `(N (H + 1) + m S^2 + m S min(k, 200) / 2)`,
/// the contact blocks' LU `(2/3) m S^3`, and
/// [`DENSE_PRECONDITIONER_FACTORIZATIONS_PER_ITERATION`] dense LUs `(2/3) (m S)^3` where
/// GMRES may fall back on them (when `preconditioner_factorizations`).
fn matrix_free_iteration(
    n: f64,
    m: f64,
    harmonics: usize,
    preconditioner_factorizations: bool,
) -> MatrixFreeIteration {
    let h = harmonics as f64;
    let s = 2.0 * h + 1.0;
    let krylov = if m < 2.0 {
        2.0
    } else {
        (KRYLOV_ITERATIONS_PER_CONTACT * m).clamp(
            KRYLOV_ITERATIONS_PER_NEWTON_MIN,
            KRYLOV_ITERATIONS_PER_NEWTON_MAX,
        )
    };
    let basis = krylov.min(200.0) / 2.0;
    let product = KRYLOV_PRODUCT_FLOPS * (n * (h + 1.0) + m * s * s + m * s * basis);
    let unknowns = m * s;
    let dense = if preconditioner_factorizations
        && m >= 2.0
        && unknowns <= semismooth_contact::hb::DENSE_PRECONDITIONER_LIMIT as f64
    {
        DENSE_PRECONDITIONER_FACTORIZATIONS_PER_ITERATION * 2.0 / 3.0 * unknowns.powi(3)
    } else {
        0.0
    };
    let blocks = 2.0 / 3.0 * m * s.powi(3);
    MatrixFreeIteration {
        flops: krylov * product + blocks + dense,
        krylov,
        product,
        dense,
    }
}

/// Whether the SSN-HB condensed system of `contacts` contacts is solved matrix-free with
/// `settings` (more than `KRYLOV_THRESHOLD` condensed unknowns, or on request).
fn matrix_free(contacts: usize, settings: &SolverSettings) -> bool {
    settings.method.carries_contact_forces()
        && settings
            .linear_solver
            .condensed()
            .is_some_and(|c| c.uses_krylov(contacts, settings.harmonics, true))
}

/// GMRES iterations [`run_work`] counts for one SSN-HB solve of `dofs` dofs and `contacts`
/// contacts with `settings` (0 off the matrix-free path).
pub fn estimated_krylov_iterations(dofs: usize, contacts: usize, settings: &SolverSettings) -> f64 {
    if matrix_free(contacts, settings) {
        SEVERAL_CONTACTS_NEWTON_ITERATIONS
            * matrix_free_iteration(dofs as f64, contacts as f64, settings.harmonics, true).krylov
    } else {
        0.0
    }
}

/// Newton iterations [`size_work`] counts for one solve with `settings` (the divisor that
/// gives the work of one iteration).
pub(crate) fn counted_newton_iterations(contacts: usize, settings: &SolverSettings) -> f64 {
    let method = settings.method;
    if method.penalises_contact()
        && settings.linear_solver != LinearSolverChoice::Dense
        && contacts > 0
    {
        settings.max_iterations as f64
    } else if matrix_free(contacts, settings) {
        SEVERAL_CONTACTS_NEWTON_ITERATIONS
    } else if method.carries_contact_forces() {
        newton_iterations(contacts)
    } else {
        NEWTON_FACTORIZATIONS
    }
}

/// Newton iterations counted for an SSN-HB solve from zero off the matrix-free path:
/// [`NEWTON_FACTORIZATIONS`] with one contact, [`SEVERAL_CONTACTS_NEWTON_ITERATIONS`] with
/// more.
fn newton_iterations(contacts: usize) -> f64 {
    if contacts >= 2 {
        SEVERAL_CONTACTS_NEWTON_ITERATIONS
    } else {
        NEWTON_FACTORIZATIONS
    }
}

/// One iteration of the structured solver with the condensed system factored dense on `n`
/// dofs and `m` contacts: its LU `(2/3) (m S)^3` and [`STRUCTURED_ITERATION_FLOPS`]
/// `N (H + 1) (m + 4)`.
fn dense_condensed_iteration(n: f64, m: f64, harmonics: usize) -> f64 {
    let h = harmonics as f64;
    2.0 / 3.0 * (m * (2.0 * h + 1.0)).powi(3)
        + STRUCTURED_ITERATION_FLOPS * n * (h + 1.0) * (m + 4.0)
}

/// Operations per second the estimates are counted in: faer's dense LU on a 2-core machine
/// (a factorization of 8241 unknowns, 3.7e11 operations, in 16 s).
pub const OPERATIONS_PER_SECOND: f64 = 2.3e10;

/// Default limit of [`work_limit`]: 1e12 operations, about 43 s at
/// [`OPERATIONS_PER_SECOND`]. The lowest round value that leaves a factor 3 for the
/// estimates' error above every shipped scene's `solve`, `sweep`, `solutions`, `compare`
/// and `scene-check` (2.5e11 at most: `compare` on the beams), the documentation's runs and
/// the tests', and refuses the natural frequencies of a rod of 1e6 elements (2.6e12,
/// measured 88 s) and the branches that take a quarter of an hour or more.
pub const DEFAULT_WORK_LIMIT: f64 = 1e12;

/// Estimated work of one run (`solve_work` on a rod of `elements` elements).
pub fn run_work(elements: usize, contacts: usize, settings: &SolverSettings) -> WorkEstimate {
    solve_work(
        elements,
        contacts,
        settings,
        "solver.linear_solver, solver.harmonics, rod.elements",
    )
}

/// Estimated work of one solve with its error estimate: [`size_work`] and
/// [`error_estimate_work`].
pub(crate) fn solve_work(
    dofs: usize,
    contacts: usize,
    settings: &SolverSettings,
    dense_keys: &'static str,
) -> WorkEstimate {
    let mut work = size_work(dofs, contacts, settings, dense_keys);
    if let Some((harmonics, flops)) = error_estimate_work(dofs, contacts, settings) {
        work.flops += flops;
        work.what += &format!(", and the error estimate's solve at H = {harmonics} ({flops:.1e})");
    }
    work
}

/// The error estimate's second solve of an SSN-HB run on the structured solver: at `2H`
/// (at `H / 2` beyond the search's `MAX_SEARCH_UNKNOWNS` unknowns, none below `H = 2`),
/// [`ERROR_ESTIMATE_NEWTON_ITERATIONS`] iterations of its path (the matrix-free path
/// without the dense preconditioner's factorizations: the first solve's state leaves GMRES
/// few iterations). Its harmonics and operations; `None` where no such solve runs.
fn error_estimate_work(
    dofs: usize,
    contacts: usize,
    settings: &SolverSettings,
) -> Option<(usize, f64)> {
    let runs = settings.method.carries_contact_forces()
        && settings.linear_solver != LinearSolverChoice::Dense
        && settings.estimate_error
        && settings.accuracy.is_none()
        && contacts > 0;
    if !runs {
        return None;
    }
    let h = settings.harmonics;
    let width = dofs.saturating_add(contacts);
    let finer = width.saturating_mul(4 * h + 1)
        <= semismooth_contact::accuracy::search::MAX_SEARCH_UNKNOWNS;
    let harmonics = match (finer, h) {
        (true, _) => 2 * h,
        (false, h) if h >= 2 => h / 2,
        _ => return None,
    };
    let other = SolverSettings {
        harmonics,
        ..settings.clone()
    };
    let (n, m) = (dofs as f64, contacts as f64);
    let iteration = if matrix_free(contacts, &other) {
        matrix_free_iteration(n, m, harmonics, false).flops
    } else {
        dense_condensed_iteration(n, m, harmonics)
    };
    Some((harmonics, ERROR_ESTIMATE_NEWTON_ITERATIONS * iteration))
}

/// [`run_work`] for a model of `dofs` dofs and `contacts` contacts; `dense_keys`: the keys a
/// refusal of the dense solver names.
pub(crate) fn size_work(
    dofs: usize,
    contacts: usize,
    settings: &SolverSettings,
    dense_keys: &'static str,
) -> WorkEstimate {
    let (n, m) = (dofs as f64, contacts as f64);
    let s = 2.0 * settings.harmonics as f64 + 1.0;
    let method = settings.method;
    match settings.linear_solver {
        LinearSolverChoice::Dense if method.is_harmonic_balance() => {
            let (unknowns, count) = if method.carries_contact_forces() {
                ((n + m) * s, newton_iterations(contacts))
            } else {
                (n * s, NEWTON_FACTORIZATIONS)
            };
            WorkEstimate {
                flops: count * 2.0 / 3.0 * unknowns.powi(3),
                what: format!(
                    "{count} LU factorizations of a dense Jacobian on \
                     {unknowns:.0} unknowns (solver.linear_solver = \"dense\"; \"structured\" \
                     factors per harmonic)"
                ),
                keys: dense_keys,
            }
        }
        // Above the threshold (or on request) the condensed system is solved matrix-free.
        _ if matrix_free(contacts, settings) => {
            let iteration = matrix_free_iteration(n, m, settings.harmonics, true);
            WorkEstimate {
                flops: SEVERAL_CONTACTS_NEWTON_ITERATIONS * iteration.flops,
                what: format!(
                    "{SEVERAL_CONTACTS_NEWTON_ITERATIONS} Newton iterations of a matrix-free solve of \
                     the condensed contact system on {:.0} unknowns, each {:.1e} operations: \
                     {:.0} GMRES iterations of {:.1e}, the contact blocks' factorizations{}",
                    m * s,
                    iteration.flops,
                    iteration.krylov,
                    iteration.product,
                    if iteration.dense > 0.0 {
                        " and the dense preconditioner's"
                    } else {
                        ""
                    }
                ),
                keys: "solver.harmonics and the number of contacts",
            }
        }
        _ if method.penalises_contact() && contacts > 0 => {
            // Penalty HB factors the condensed system at every iteration and stiff
            // penalties take hundreds of them: counted at solver.max_iterations.
            let unknowns = m * s;
            let count = settings.max_iterations as f64;
            let per_iteration =
                2.0 / 3.0 * unknowns.powi(3) + PENALTY_JACOBIAN_FLOPS * n * s.powi(3);
            WorkEstimate {
                flops: count * per_iteration,
                what: format!(
                    "up to {count} iterations (solver.max_iterations) of {per_iteration:.1e} \
                     operations: the sparse Jacobian on {:.0} unknowns and the condensed \
                     penalty system on {unknowns:.0}",
                    n * s
                ),
                keys: "solver.harmonics, solver.max_iterations and the structure's size",
            }
        }
        LinearSolverChoice::Structured
        | LinearSolverChoice::CondensedDense
        | LinearSolverChoice::CondensedKrylov
            if method.carries_contact_forces() =>
        {
            let iterations = newton_iterations(contacts);
            WorkEstimate {
                flops: iterations * dense_condensed_iteration(n, m, settings.harmonics),
                what: format!(
                    "{iterations} Newton iterations, each an LU factorization of the condensed \
                     contact system on {:.0} unknowns and the per-harmonic solves of {dofs} dofs",
                    m * s
                ),
                keys: "solver.harmonics and the number of contacts",
            }
        }
        _ => WorkEstimate {
            flops: 0.0,
            what: "no dense factorization".into(),
            keys: "",
        },
    }
}

/// The operations a run may take: `SSN_WORK_LIMIT` when set, else [`DEFAULT_WORK_LIMIT`];
/// `Err` for a value that is not a number > 0.
pub fn work_limit() -> Result<f64, String> {
    Ok(
        limit_from_env("SSN_WORK_LIMIT", "floating-point operations")?
            .unwrap_or(DEFAULT_WORK_LIMIT),
    )
}

/// Refuses `need` when it exceeds `limit`: the message names the keys, the need and the
/// limit, and how to lift it.
pub fn check_work(need: &WorkEstimate, limit: f64) -> Result<(), String> {
    if need.flops.is_nan() || need.flops > limit {
        Err(format!(
            "these settings need about {:.1e} floating-point operations ({}; {} on a 2-core \
             machine at {OPERATIONS_PER_SECOND:.1e} operations per second), more than the \
             limit of {limit:.1e} (SSN_WORK_LIMIT, default {DEFAULT_WORK_LIMIT:.0e}: {}): \
             allowed are settings whose estimate is within the limit; reduce {}{}",
            need.flops,
            need.what,
            duration_words(need.flops / OPERATIONS_PER_SECOND),
            duration_words(DEFAULT_WORK_LIMIT / OPERATIONS_PER_SECOND),
            need.keys,
            match round_up(need.flops) {
                Some(limit) =>
                    format!(", or raise the limit for this run: SSN_WORK_LIMIT={limit} ssn ..."),
                None => String::new(),
            },
        ))
    } else {
        Ok(())
    }
}

/// A duration in seconds in words: `about 45 s`, `about 13 minutes`, `about 2.5 hours`,
/// `about 3 days`; `longer than can be counted` beyond any of them.
fn duration_words(seconds: f64) -> String {
    match seconds {
        s if !s.is_finite() || s > 1e6 * 86400.0 => "longer than can be counted".into(),
        s if s < 1.0 => "under a second".into(),
        s if s < 120.0 => format!("about {s:.0} s"),
        s if s < 7200.0 => format!("about {:.0} minutes", s / 60.0),
        s if s < 2.0 * 86400.0 => format!("about {:.1} hours", s / 3600.0),
        s => format!("about {:.0} days", s / 86400.0),
    }
}

/// `x > 0` rounded up to one significant digit, as `2e13` (a limit that lets `x` run);
/// `None` for a need no limit lets run (not finite, or beyond the largest float).
fn round_up(x: f64) -> Option<String> {
    let exponent = x.log10().floor();
    let digit = (x / 10f64.powf(exponent)).ceil();
    let (digit, exponent) = if digit >= 10.0 {
        (1.0, exponent + 1.0)
    } else {
        (digit, exponent)
    };
    (digit * 10f64.powf(exponent))
        .is_finite()
        .then(|| format!("{digit}e{exponent}"))
}

/// `settings`, or those of the comparison's SSN-HB reference run when `compare`.
pub(crate) fn compared(settings: &SolverSettings, compare: bool) -> SolverSettings {
    let mut settings = settings.clone();
    if compare {
        settings.method = Method::SsnHb;
        settings.harmonics = crate::accuracy_cost::REFERENCE_HARMONICS;
    }
    settings
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(method: Method, h: usize, dense: bool) -> SolverSettings {
        let mut s = crate::scene::Scene::from_toml(
            "[rod]\nelements = 20\n[forcing]\namplitude = 0.1\n[contact]\ngap = 0.5\n",
            "t.toml",
        )
        .unwrap()
        .solver;
        s.method = method;
        s.harmonics = h;
        s.time_samples = default_hb_time_samples(h);
        if dense {
            s.linear_solver = LinearSolverChoice::Dense;
        }
        s
    }

    #[test]
    fn estimates_bound_the_measured_peaks_within_a_factor_three() {
        // Peak resident sizes measured with /usr/bin/time (see the module table).
        for (elements, method, h, dense, measured) in [
            (10_000, Method::SsnHb, 20, false, 86e6),
            (10_000, Method::SsnHb, 80, false, 289e6),
            (10_000, Method::PenaltyHb, 20, false, 90e6),
            (100, Method::SsnHb, 20, true, 156e6),
            (200, Method::SsnHb, 20, true, 570e6),
        ] {
            let e = run_memory(elements, 1, &settings(method, h, dense)).bytes;
            assert!(
                e >= measured && e <= 3.0 * measured,
                "{elements} {method:?} H={h}: estimate {e:e} against {measured:e}"
            );
        }
        // The matrix-free condensed path (SSN-HB, 1,000 contacts on the 10,002-dof disk of
        // examples/contact_scaling.rs, H = 20): VmHWM 200 MB.
        let krylov = run_memory(10_002, 1000, &settings(Method::SsnHb, 20, false)).bytes;
        assert!((200e6..3.0 * 200e6).contains(&krylov), "{krylov:e}");
        let mut lcp = settings(Method::LcpLemke, 5, false);
        lcp.time_samples = 2048;
        let e = run_memory(20, 1, &lcp).bytes;
        assert!((71e6..3.0 * 71e6).contains(&e), "{e:e}");
    }

    #[test]
    fn a_refusal_names_the_keys_the_need_and_the_limit() {
        let dense = run_memory(400, 1, &settings(Method::SsnHb, 2000, true));
        let e = check(&dense, Some(16e9)).unwrap_err();
        for word in [
            "solver.linear_solver",
            "TB",
            "16.0 GB",
            "\"structured\" needs",
        ] {
            assert!(e.contains(word), "{word}: {e}");
        }
        let structured = run_memory(400, 1, &settings(Method::SsnHb, 20, false));
        assert!(check(&structured, Some(16e9)).is_ok());
        assert!(
            check(&dense, None).is_ok(),
            "no limit known: nothing refused"
        );
        // Hostile sizes give a large estimate (the matrix-free path: about 1e24 bytes), never
        // an overflowed small one.
        let huge = run_memory(usize::MAX, usize::MAX, &settings(Method::SsnHb, 20, false));
        assert!(check(&huge, Some(1e20)).is_err());
    }

    #[test]
    fn the_dense_solver_on_400_elements_at_h_40_is_refused_for_its_work() {
        // n = 401 x 81 = 32481 unknowns: (2/3) n^3 = 2.28e13 operations per factorization.
        let dense = run_work(400, 1, &settings(Method::SsnHb, 40, true));
        let n = 401.0 * 81.0;
        assert!((dense.flops - 10.0 * 2.0 / 3.0 * n * n * n).abs() <= 1e-12 * dense.flops);
        let e = check_work(&dense, DEFAULT_WORK_LIMIT).unwrap_err();
        for word in [
            "solver.linear_solver",
            "2.3e14",
            "1.0e12",
            "SSN_WORK_LIMIT=3e14",
            "about 2.8 hours",
            "32481",
        ] {
            assert!(e.contains(word), "{word}: {e}");
        }
        // The dense solver at 100 elements, H = 20 (4.7e11) stays allowed, as does the
        // structured one at 10,000 elements with one contact.
        assert!(check_work(
            &run_work(100, 1, &settings(Method::SsnHb, 20, true)),
            DEFAULT_WORK_LIMIT
        )
        .is_ok());
        let long = run_work(10_000, 1, &settings(Method::SsnHb, 20, false));
        assert!(check_work(&long, DEFAULT_WORK_LIMIT).is_ok(), "{long:?}");
        assert!(
            check_work(&dense, 1e15).is_ok(),
            "a raised limit lets it run"
        );
    }

    #[test]
    fn penalty_hb_is_estimated_by_its_measured_iterations_and_refused_at_h_2000() {
        // Measured on 1,000 elements at H = 200: 37.8 s for 157 iterations (8.7e11
        // operations at 2.3e10 per second); the estimate counts solver.max_iterations = 200
        // and stays within a factor 3 of it.
        let near = run_work(1000, 1, &settings(Method::PenaltyHb, 200, false));
        let measured = 37.8 * 2.3e10;
        assert!((measured..3.0 * measured).contains(&near.flops), "{near:?}");
        assert!(check_work(&near, 3.0 * measured).is_ok());
        // H = 2000: about 1000 times H = 200 (more than 10 times from 200 to 400 measured).
        let big = run_work(1000, 1, &settings(Method::PenaltyHb, 2000, false));
        let e = check_work(&big, DEFAULT_WORK_LIMIT).unwrap_err();
        assert!(
            e.contains("solver.harmonics") && e.contains("1.2e15"),
            "{e}"
        );
    }

    #[test]
    fn imported_models_are_estimated_by_their_size_and_the_matrix_free_path_by_its_gmres() {
        // A model of 32,481 dofs with the dense solver at H = 1: (32481 + 1) x 3 unknowns,
        // 10 x (2/3) n^3 = 6.2e14 operations, refused, naming the model's size.
        let dense = size_work(
            32_481,
            1,
            &settings(Method::SsnHb, 1, true),
            "the model's size",
        );
        let e = check_work(&dense, DEFAULT_WORK_LIMIT).unwrap_err();
        assert!(e.contains("the model's size"), "{e}");
        // 1,000 contacts at H = 20 on the 10,002-dof disk of examples/contact_scaling.rs:
        // 41,000 condensed unknowns, solved matrix-free (a dense estimate would be 4.6e14
        // and refuse a run that takes seconds); the GMRES iterations of the rod's stops,
        // which couple far more, are counted, and the run is allowed.
        let many = size_work(10_002, 1000, &settings(Method::SsnHb, 20, false), "");
        assert!((1e12..1e14).contains(&many.flops), "{many:?}");
        assert!(many.what.contains("GMRES iterations"), "{many:?}");
        // At the threshold the condensed system is still factored dense, at every one of
        // the 50 Newton iterations counted with several contacts.
        let dense_condensed = size_work(10_002, 40, &settings(Method::SsnHb, 20, false), "");
        let n: f64 = 40.0 * 41.0;
        assert!(dense_condensed.flops >= 50.0 * 2.0 / 3.0 * n.powi(3));
        assert!(
            dense_condensed.what.contains("on 1640 unknowns"),
            "{dense_condensed:?}"
        );
    }

    #[test]
    fn the_dense_condensed_path_is_estimated_within_a_factor_three_of_its_measured_runs() {
        // The rod of 1,000 elements with m evenly spaced stops (gap 0.5, H = 20), from zero,
        // with its error estimate: CPU seconds of `ssn solve` (a load of 6 on 2 cores) at
        // 2.3e10 operations per second. The solves took 48, 48 and 47 Newton iterations (50
        // counted), their error estimates' solves at H = 40 4, 3 and 9 (10 counted).
        for (m, seconds) in [(5, 0.52), (10, 0.81), (20, 3.04), (20, 1.58)] {
            let settings = settings(Method::SsnHb, 20, false);
            let work = run_work(1000, m, &settings);
            let measured = seconds * 2.3e10;
            assert!(
                (measured / 3.0..3.0 * measured).contains(&work.flops),
                "{m} contacts: {work:?} against {measured:e}"
            );
            assert!(
                work.what.contains("error estimate's solve at H = 40"),
                "{work:?}"
            );
        }
        // Without an error estimate only the solve is counted.
        let mut alone = settings(Method::SsnHb, 20, false);
        alone.estimate_error = false;
        let with = run_work(1000, 20, &settings(Method::SsnHb, 20, false)).flops;
        let without = run_work(1000, 20, &alone).flops;
        assert!(without < 0.6 * with, "{without:e} {with:e}");
    }

    #[test]
    fn the_matrix_free_path_is_estimated_within_a_factor_three_of_its_measured_runs() {
        // The rod of 1,000 elements with m evenly spaced stops (gap 0.5, H = 20), from
        // zero: GMRES iterations (the `krylov_iterations` counter) and CPU seconds
        // (a load of 5 on 2 cores) measured, converted at 2.3e10 operations per second. 50
        // stops took 13.3 s and 19.5 s (a load of 6) in two runs: their mean.
        for (m, krylov, seconds) in [
            (50, 2370.0, 16.4),
            (200, 9264.0, 30.2),
            (1000, 10617.0, 194.0),
        ] {
            let settings = settings(Method::SsnHb, 20, false);
            let counted = estimated_krylov_iterations(1001, m, &settings);
            assert!(
                (krylov / 3.0..3.0 * krylov).contains(&counted),
                "{m} contacts: {counted} GMRES iterations counted, {krylov} measured"
            );
            let work = run_work(1000, m, &settings).flops;
            let measured = seconds * 2.3e10;
            assert!(
                (measured / 3.0..3.0 * measured).contains(&work),
                "{m} contacts: {work:e} against {measured:e}"
            );
        }
        // The default limit lets 50 stops run (13 to 20 s) and refuses 200 (30 s, estimated
        // 1.6e12) and 1,000 (194 s).
        let default = |m| {
            check_work(
                &run_work(1000, m, &settings(Method::SsnHb, 20, false)),
                DEFAULT_WORK_LIMIT,
            )
        };
        assert!(default(50).is_ok() && default(200).is_err() && default(1000).is_err());
        // Below the threshold nothing is counted for GMRES; `condensed-krylov` asks for it.
        let mut small = settings(Method::SsnHb, 20, false);
        assert_eq!(estimated_krylov_iterations(1001, 20, &small), 0.0);
        small.linear_solver = LinearSolverChoice::CondensedKrylov;
        assert!(estimated_krylov_iterations(1001, 20, &small) > 0.0);
    }
}
