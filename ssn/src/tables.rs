//! The measured tables of the documentation (`docs/`), each computed by one function of
//! this module. `cargo run --release -p ssn --example docs_tables [-- SECTION ...]` prints
//! them as markdown, and with `--write` replaces each section's generated block in its
//! docs file ([`SECTIONS`], [`replace_block`]).
//!
//! A [`Table`] knows which of its columns are wall times (they vary from machine to
//! machine and run to run); every other cell is deterministic (iteration counts, points,
//! folds, errors rounded as printed), and `tests/docs_tables.rs` recomputes the cheap
//! tables and asserts that the docs files hold exactly those cells, so a documented number
//! cannot drift from the code unnoticed.

use std::time::Instant;

use crate::accuracy_cost::{AccuracyCost, Entry};
use crate::scene::{GlobalizationChoice, Method, SolverSettings, SweepSettings};
use semismooth_contact::from_zero::GridCase;
use semismooth_contact::rod::{build_rod, MassModel, ModelError, RodModel, RodSpec};
use semismooth_contact::solve::{solve, RunError, Solution};
use semismooth_contact::sweep::frequency_response;

/// A section of the generated tables: its name (the argument of the `docs_tables`
/// example) and the docs file, relative to the workspace root, that holds its block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Section {
    /// The section's name (`methods`, `sweeps`, ...).
    pub name: &'static str,
    /// The docs file holding the section's generated block.
    pub file: &'static str,
}

/// Every section, in the order the example computes them: the method comparison, the
/// cheapest setting per accuracy, the discretisation chosen for an accuracy target, the
/// frequency sweeps, the public grid from zero, what the
/// examples time, the hard cases from zero (minutes), and the friction tables.
pub const SECTIONS: [Section; 9] = [
    Section {
        name: "methods",
        file: "docs/method-comparison.md",
    },
    Section {
        name: "accuracy",
        file: "docs/accuracy-cost.md",
    },
    Section {
        name: "accuracy-targets",
        file: "docs/accuracy-cost.md",
    },
    Section {
        name: "sweeps",
        file: "docs/sweeps.md",
    },
    Section {
        name: "adaptive-sweeps",
        file: "docs/sweeps.md",
    },
    Section {
        name: "from-zero",
        file: "docs/solving-from-zero.md",
    },
    Section {
        name: "performance",
        file: "docs/performance.md",
    },
    Section {
        name: "hard",
        file: "docs/solving-from-zero.md",
    },
    Section {
        name: "friction",
        file: "docs/friction.md",
    },
];

/// The section called `name`.
pub fn section(name: &str) -> Option<Section> {
    SECTIONS.iter().copied().find(|s| s.name == name)
}

/// The line that opens the generated block of `section` in its docs file.
pub fn block_start(section: &str) -> String {
    format!("<!-- docs_tables {section}: generated, do not edit -->")
}

/// The line that closes the generated block of `section`.
pub fn block_end(section: &str) -> String {
    format!("<!-- docs_tables {section}: end -->")
}

/// `text` with the generated block of `section` (the lines between [`block_start`] and
/// [`block_end`]) replaced by `content`; `None` when `text` has no such block.
pub fn replace_block(text: &str, section: &str, content: &str) -> Option<String> {
    let (start, end) = (block_start(section), block_end(section));
    let open = text.find(&start)? + start.len();
    let close = open + text[open..].find(&end)?;
    let mut out = String::with_capacity(text.len() + content.len());
    out.push_str(&text[..open]);
    out.push_str("\n\n");
    out.push_str(content.trim());
    out.push_str("\n\n");
    out.push_str(&text[close..]);
    Some(out)
}

/// The machine the wall times of a generated block were measured on: the processor
/// model, the cores and the load average when the tables were computed (Linux; `unknown`
/// where the system does not say).
pub fn machine_note() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown processor".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|t| t.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into());
    format!("{cpu}, {cores} cores, load average {load}")
}

/// A markdown table: a header, rows of cells, and the columns that hold wall times.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Column names.
    pub header: Vec<String>,
    /// Cells, one row per line; the first cell names the row.
    pub rows: Vec<Vec<String>>,
    /// Indices of the columns whose cells are (or contain) wall times.
    pub timing: Vec<usize>,
}

impl Table {
    pub(crate) fn new(header: &[&str], timing: &[usize]) -> Self {
        Self {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
            timing: timing.to_vec(),
        }
    }

    /// The table as markdown: `| a | b |`, the `|---|` line, one line per row.
    pub fn markdown(&self) -> String {
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        let mut out = line(&self.header);
        out.push_str(&format!("|{}\n", "---|".repeat(self.header.len())));
        for row in &self.rows {
            out.push_str(&line(row));
        }
        out
    }

    /// The rows of the markdown table in `text` whose header line is this table's, cells
    /// trimmed (`None` when `text` has no such table).
    pub fn rows_in(&self, text: &str) -> Option<Vec<Vec<String>>> {
        let header = self.markdown().lines().next()?.to_string();
        let mut lines = text.lines().skip_while(|l| l.trim_end() != header);
        lines.next()?;
        lines.next()?;
        Some(
            lines
                .take_while(|l| l.starts_with('|'))
                .map(|l| {
                    l.trim()
                        .trim_start_matches('|')
                        .trim_end_matches('|')
                        .split(" | ")
                        .map(|c| c.trim().to_string())
                        .collect()
                })
                .collect(),
        )
    }

    /// Where `text` differs from this table in a deterministic cell: one message per row
    /// that `text` lacks (rows are matched by their first cell) and per differing cell.
    /// Timing columns are not compared; rows of `text` that this table lacks are allowed
    /// (tables recomputed in part).
    pub fn differences_in(&self, text: &str) -> Vec<String> {
        let Some(rows) = self.rows_in(text) else {
            return vec![format!("no table with header {:?}", self.header)];
        };
        let mut out = Vec::new();
        for row in &self.rows {
            let Some(found) = rows.iter().find(|r| r.first() == row.first()) else {
                out.push(format!("row {:?} missing", row[0]));
                continue;
            };
            for (i, cell) in row.iter().enumerate() {
                if self.timing.contains(&i) {
                    continue;
                }
                let have = found.get(i).map_or("", String::as_str);
                if have != cell {
                    out.push(format!(
                        "row {:?}, column {:?}: the docs have {have:?}, the code gives {cell:?}",
                        row[0], self.header[i]
                    ));
                }
            }
        }
        out
    }
}

/// Why a table could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// A rod did not build.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A run could not start.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A figure's sweeps could not run.
    #[error("{0}")]
    Figure(String),
}

/// One method of the method comparison and what it gave.
#[derive(Debug, Clone)]
pub struct ComparisonRow {
    /// The method and its discretisation (`ssn-hb H=20`).
    pub label: String,
    /// The solution, or why the run could not start.
    pub result: Result<Solution, String>,
}

/// The settings of the method comparison on `rod`: the time-marching reference first
/// (4000 trapezoidal steps per period with a massless contact node, 8000 Moreau–Jean
/// steps otherwise), then SSN-HB at H = 10, 20, 40, penalty HB at H = 40 with `k_p` = 1e2,
/// 1e3, 1e5 times the contact stiffness scale, and the periodic LCP by Lemke and by
/// semismooth Newton at Nt = 256 and 1024.
pub fn comparison_settings(rod: &RodModel, mass: MassModel) -> Vec<(String, SolverSettings)> {
    let scale = rod.model.contact_stiffness_scale();
    let base = SolverSettings::with_harmonics(20);
    let (steps, tolerance) = if mass == MassModel::Modified {
        (4000, 1e-10)
    } else {
        (8000, 1e-6)
    };
    let mut cases = vec![(
        format!("march {steps} steps/period"),
        SolverSettings {
            method: Method::March,
            steps_per_period: steps,
            march_tolerance: tolerance,
            ..base.clone()
        },
    )];
    for h in [10, 20, 40] {
        cases.push((format!("ssn-hb H={h}"), SolverSettings::with_harmonics(h)));
    }
    for k in [1e2, 1e3, 1e5] {
        cases.push((
            format!("penalty-hb H=40 kp={k:.0e}x{scale}"),
            SolverSettings {
                method: Method::PenaltyHb,
                penalty_stiffness: Some(k * scale),
                ..SolverSettings::with_harmonics(40)
            },
        ));
    }
    for nt in [256, 1024] {
        for method in [Method::LcpLemke, Method::LcpSsn] {
            cases.push((
                format!("{} Nt={nt}", method.name()),
                SolverSettings {
                    method,
                    time_samples: nt,
                    ..base.clone()
                },
            ));
        }
    }
    cases
}

/// The method comparison on the canonical rod with the given mass model: every method of
/// [`comparison_settings`] solved once from zero, and the table of them (`ms`, the
/// wall time of one cold solve, is the timing column; `diff. tip min` is relative to the
/// reference, the first row).
pub fn method_comparison(mass: MassModel) -> Result<(Table, Vec<ComparisonRow>), TableError> {
    let rod = build_rod(&RodSpec {
        mass,
        ..RodSpec::canonical()
    })?;
    let rows: Vec<ComparisonRow> = comparison_settings(&rod, mass)
        .into_iter()
        .map(|(label, settings)| ComparisonRow {
            label,
            result: solve(&rod, rod.omega(), &settings, None).map_err(|e| e.to_string()),
        })
        .collect();
    let reference_min = rows[0].result.as_ref().ok().map(|r| r.stats.min);
    let first = format!("method ({} mass)", format!("{mass:?}").to_lowercase());
    let mut table = Table::new(
        &[
            &first,
            "iterations",
            "ms",
            "tip min",
            "max penetration",
            "mean force",
            "diff. tip min",
        ],
        &[2],
    );
    for row in &rows {
        table.rows.push(match &row.result {
            Ok(s) => {
                let diff = reference_min.map_or(f64::NAN, |r| (s.stats.min - r).abs() / r.abs());
                let label = if s.converged() {
                    row.label.clone()
                } else {
                    format!(
                        "{} (not converged: {})",
                        row.label,
                        crate::words::termination(&s.termination)
                    )
                };
                vec![
                    label,
                    s.iterations.to_string(),
                    format!("{:.2}", 1e3 * s.solve_seconds),
                    format!("{:.6}", s.stats.min),
                    format!("{:.1e}", s.stats.max_penetration),
                    format!("{:.4e}", s.stats.mean_contact_force),
                    format!("{diff:.1e}"),
                ]
            }
            Err(e) => {
                let mut cells = vec![row.label.clone(), format!("error: {e}")];
                cells.resize(7, String::new());
                cells
            }
        });
    }
    Ok((table, rows))
}

/// The cheapest setting of each method of an accuracy-cost study for a relative error of
/// 1e-3 and 1e-4 on the tip minimum: `setting, time` per cell (the time makes the whole
/// cell a timing column: which setting is cheapest depends on the times where two are
/// close).
pub fn cheapest_settings(study: &AccuracyCost) -> Table {
    let mut table = Table::new(&["method", "for 1e-3", "for 1e-4"], &[1, 2]);
    let cell = |e: &Option<Entry>| match e {
        Some(e) => format!("{}, {:.2} ms", e.setting, 1e3 * e.seconds),
        None => "not reached".to_string(),
    };
    for ((method, a), (_, b)) in study.cheapest(1e-3).iter().zip(&study.cheapest(1e-4)) {
        table
            .rows
            .push(vec![method.name().to_string(), cell(a), cell(b)]);
    }
    table
}

/// One frequency sweep of the sweep table.
#[derive(Debug, Clone)]
pub struct SweepCase {
    /// The row's name.
    pub label: String,
    /// Mass model of the canonical rod (gap 0.5 at the tip, load 0.04).
    pub mass: MassModel,
    /// The solver.
    pub settings: SolverSettings,
    /// The sweep.
    pub sweep: SweepSettings,
    /// Whether it takes seconds rather than a fraction of a second (then only the example
    /// computes it).
    pub slow: bool,
}

/// The sweeps of the sweep table over `[0.5, 2] omega_1` on the canonical rod (gap 0.5, load
/// 0.04): SSN-HB at H = 20 and 40 and the periodic LCP by semismooth Newton at Nt = 128,
/// 256, 512 with the modified mass (scene defaults, up to 5000 points), and penalty HB at
/// the default penalty at H = 5 and 20 with the consistent mass (at most 100 Newton
/// iterations per point, non-monotone line search).
pub fn sweep_cases() -> Vec<SweepCase> {
    let long = SweepSettings {
        max_points: 5000,
        ..SweepSettings::new(0.5, 2.0)
    };
    let mut cases = Vec::new();
    for h in [20, 40] {
        cases.push(SweepCase {
            label: format!("ssn-hb H={h}, modified mass"),
            mass: MassModel::Modified,
            settings: SolverSettings::with_harmonics(h),
            sweep: long.clone(),
            slow: false,
        });
    }
    for nt in [128, 256, 512] {
        cases.push(SweepCase {
            label: format!("lcp-ssn Nt={nt}, modified mass"),
            mass: MassModel::Modified,
            settings: SolverSettings {
                method: Method::LcpSsn,
                time_samples: nt,
                ..SolverSettings::with_harmonics(20)
            },
            sweep: long.clone(),
            slow: nt > 256,
        });
    }
    for h in [5, 20] {
        cases.push(SweepCase {
            label: format!("penalty-hb H={h}, consistent mass"),
            mass: MassModel::Consistent,
            settings: SolverSettings {
                method: Method::PenaltyHb,
                max_iterations: 100,
                globalization: GlobalizationChoice::Nonmonotone,
                ..SolverSettings::with_harmonics(h)
            },
            sweep: SweepSettings::new(0.5, 2.0),
            slow: false,
        });
    }
    cases
}

/// The sweep table for `cases`: points, corrector iterations, corners crossed
/// exactly, folds (turning points), reversals at corners, the highest fold and the peak
/// amplitude with its frequency, and the wall time of the sweep (the timing column).
pub fn sweeps(cases: &[SweepCase]) -> Result<Table, TableError> {
    let mut table = Table::new(
        &[
            "sweep",
            "points",
            "corrector iterations",
            "corners",
            "folds",
            "corner reversals",
            "highest fold",
            "peak (at omega_1)",
            "seconds",
        ],
        &[8],
    );
    for case in cases {
        let rod = build_rod(&RodSpec {
            mass: case.mass,
            ..RodSpec::canonical()
        })?;
        let r = frequency_response(&rod, &case.settings, &case.sweep, None)?;
        let (ip, peak) = r.peak().unwrap_or((0, f64::NAN));
        let highest = r.folds.iter().copied().fold(f64::NAN, f64::max) / rod.omega_1;
        let label = if r.converged() {
            case.label.clone()
        } else {
            format!(
                "{} (not converged: {})",
                case.label,
                crate::words::sweep_termination(&r)
            )
        };
        table.rows.push(vec![
            label,
            r.points.len().to_string(),
            r.continuation.corrector_iterations.to_string(),
            r.corners.to_string(),
            r.folds.len().to_string(),
            r.corner_folds.len().to_string(),
            format!("{highest:.5}"),
            format!("{peak:.5} ({:.4})", r.points[ip].omega / rod.omega_1),
            format!("{:.3}", r.solve_seconds),
        ]);
    }
    Ok(table)
}

/// What solving one group of cases from zero gave.
#[derive(Debug, Clone)]
pub struct GroupSummary {
    /// The group's name.
    pub name: String,
    /// Cases in the group.
    pub points: usize,
    /// Cases that converged.
    pub converged: usize,
    /// Largest iteration count of the converged cases (0 when none).
    pub worst: usize,
    /// Largest iteration count of all cases, converged or not.
    pub largest: usize,
    /// Median iteration count of the converged cases.
    pub median: usize,
    /// Line-search backtracks over the group.
    pub backtracks: u64,
    /// The strategy that converged (`failed` when none did) and how many cases it took.
    pub strategies: Vec<(String, usize)>,
    /// `label (termination)` or `label: error` of each case that did not converge.
    pub failures: Vec<String>,
    /// The distinct terminations (or errors) of the cases that did not converge.
    pub terminations: Vec<String>,
    /// Cases that did not converge or took more than 60 iterations: the label, the
    /// iterations and per attempt its strategy, iterations and outcome.
    pub details: Vec<String>,
    /// Wall time of the group, seconds.
    pub seconds: f64,
}

impl GroupSummary {
    /// `newton 158, smoothing 31`: the strategies that converged, with their counts.
    pub fn strategies_text(&self) -> String {
        let parts: Vec<String> = self
            .strategies
            .iter()
            .map(|(s, n)| format!("{s} {n}"))
            .collect();
        parts.join(", ")
    }
}

/// Solves every case of a group from zero with `globalization` in place of its own.
pub fn solve_group(
    name: &str,
    cases: &[GridCase],
    globalization: GlobalizationChoice,
) -> GroupSummary {
    let start = Instant::now();
    let mut g = GroupSummary {
        name: name.to_string(),
        points: cases.len(),
        converged: 0,
        worst: 0,
        largest: 0,
        median: 0,
        backtracks: 0,
        strategies: Vec::new(),
        failures: Vec::new(),
        terminations: Vec::new(),
        details: Vec::new(),
        seconds: 0.0,
    };
    let mut iterations = Vec::new();
    for case in cases {
        let mut settings = case.solver_settings();
        settings.globalization = globalization;
        // Whether each case converges from zero, and at what cost: no error estimate.
        settings.estimate_error = false;
        let sol = match solve(&case.rod, case.rod.omega(), &settings, None) {
            Ok(sol) => sol,
            Err(e) => {
                g.failures.push(format!("{}: {e}", case.label));
                if !g.terminations.contains(&e.to_string()) {
                    g.terminations.push(e.to_string());
                }
                continue;
            }
        };
        g.backtracks += sol.counters.line_search_backtracks;
        g.largest = g.largest.max(sol.iterations);
        if !sol.converged() || sol.iterations > 60 {
            let mut d = format!("{} ({} iterations):", case.label, sol.iterations);
            for a in &sol.attempts {
                d.push_str(&format!(
                    "\n    {} {} {}",
                    a.strategy.name(),
                    a.iterations,
                    a.outcome
                ));
            }
            g.details.push(d);
        }
        let strategy = if sol.converged() {
            g.converged += 1;
            iterations.push(sol.iterations);
            sol.strategy.map_or("-", |s| s.name()).to_string()
        } else {
            let termination = crate::words::termination(&sol.termination);
            g.failures.push(format!("{} ({termination})", case.label));
            if !g.terminations.contains(&termination) {
                g.terminations.push(termination);
            }
            "failed".to_string()
        };
        match g.strategies.iter_mut().find(|(k, _)| *k == strategy) {
            Some((_, n)) => *n += 1,
            None => g.strategies.push((strategy, 1)),
        }
    }
    iterations.sort_unstable();
    g.worst = iterations.last().copied().unwrap_or(0);
    g.median = iterations.get(iterations.len() / 2).copied().unwrap_or(0);
    g.seconds = start.elapsed().as_secs_f64();
    g
}

/// The table of the public grid solved from zero: per group converged points / worst
/// iteration count and the strategies that converged, with the default `auto`, and
/// converged / worst with `hybrid` (full steps, then the non-monotone line search); `auto` and
/// `hybrid` are the two groups' summaries, in the same order.
pub fn from_zero_grid(auto: &[GroupSummary], hybrid: &[GroupSummary]) -> Table {
    let mut table = Table::new(
        &[
            "group",
            "`auto`: converged / worst",
            "`auto`: strategies that converged",
            "`auto`: backtracks",
            "`hybrid`: converged / worst",
            "`hybrid`: backtracks",
        ],
        &[],
    );
    for (a, h) in auto.iter().zip(hybrid) {
        table.rows.push(vec![
            a.name.clone(),
            format!("{} / {}", a.converged, a.worst),
            a.strategies_text(),
            a.backtracks.to_string(),
            format!("{} / {}", h.converged, h.worst),
            h.backtracks.to_string(),
        ]);
    }
    table
}

/// The table of the hard cases solved from zero (`auto`): per case (a group of
/// cases for the LCP) the cases that converged, the largest iteration count (converged or
/// not), the strategies that converged or the terminations of those that did not, and the
/// wall time (the timing column).
pub fn from_zero_hard(groups: &[GroupSummary]) -> Table {
    let mut table = Table::new(
        &["case", "converged", "iterations", "outcome", "seconds"],
        &[4],
    );
    for g in groups {
        let outcome = if g.terminations.is_empty() {
            g.strategies_text()
        } else {
            format!("not converged: {}", g.terminations.join("; "))
        };
        table.rows.push(vec![
            g.name.clone(),
            format!("{} of {}", g.converged, g.points),
            g.largest.to_string(),
            outcome,
            format!("{:.1}", g.seconds),
        ]);
    }
    table
}

/// The table of what the examples time (criterion's medians are in a table of their
/// own): one cold solve of the canonical rod from zero with SSN-HB at H = 20 (the
/// Newton iterations, including the first Jacobian and factorization, not the assembly of
/// the rod), the four Fig. 2 sweeps at H = 5 and one at H = 20 (continuation from the
/// first point to the last; the consistent mass, so no stability), time marching from rest
/// to steady state, and Lemke on the periodic LCP at Nt = 2048 (the pivots, the LCP
/// already built). `counts` are deterministic, `seconds` is the timing column.
pub fn performance() -> Result<Table, TableError> {
    let mut table = Table::new(&["what", "counts", "seconds"], &[2]);
    let figure = |e: crate::exit::CliError| {
        TableError::Figure(match e {
            crate::exit::CliError::BadInput(m)
            | crate::exit::CliError::TooLarge(m)
            | crate::exit::CliError::Output(m) => m,
            crate::exit::CliError::NotConverged => "not converged".into(),
        })
    };
    for mass in [MassModel::Modified, MassModel::Consistent] {
        let rod = build_rod(&RodSpec {
            mass,
            ..RodSpec::canonical()
        })?;
        let s = solve(&rod, rod.omega(), &SolverSettings::with_harmonics(20), None)?;
        table.rows.push(vec![
            format!(
                "canonical rod, {} mass, H = 20, from zero, one cold solve",
                format!("{mass:?}").to_lowercase()
            ),
            format!("{} iterations", s.iterations),
            format!("{:.5}", s.solve_seconds),
        ]);
    }
    let fig2 = crate::figures::figure_2_curves(5, MassModel::Consistent).map_err(figure)?;
    let points: Vec<String> = fig2.curves.iter().map(|c| c.points.to_string()).collect();
    table.rows.push(vec![
        "Fig. 2, four curves at H = 5 (gaps 0.25, 0.5, 0.75, none)".into(),
        format!("{} points", points.join(" / ")),
        format!("{:.3}", fig2.curves.iter().map(|c| c.seconds).sum::<f64>()),
    ]);
    let (_, r) =
        crate::figures::figure_2_branch(Some(0.5), 20, MassModel::Consistent).map_err(figure)?;
    table.rows.push(vec![
        "Fig. 2, the gap 0.5 curve at H = 20".into(),
        format!("{} points", r.points.len()),
        format!("{:.3}", r.solve_seconds),
    ]);
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })?;
    let march = solve(
        &rod,
        rod.omega(),
        &SolverSettings {
            method: Method::March,
            ..SolverSettings::with_harmonics(20)
        },
        None,
    )?;
    table.rows.push(vec![
        "time marching, modified mass, 2000 steps per period, from rest to a change below 1e-8"
            .into(),
        format!("{} periods", march.iterations),
        format!("{:.3}", march.solve_seconds),
    ]);
    let lemke = solve(
        &rod,
        rod.omega(),
        &SolverSettings {
            method: Method::LcpLemke,
            time_samples: 2048,
            ..SolverSettings::with_harmonics(20)
        },
        None,
    )?;
    table.rows.push(vec![
        "periodic LCP by Lemke, modified mass, Nt = 2048".into(),
        format!("{} pivots", lemke.iterations),
        format!("{:.3}", lemke.solve_seconds),
    ]);
    Ok(table)
}

/// The table of adaptive sweeps against the fixed harmonics reaching the same worst error
/// ([`crate::adaptive_sweeps`]), one row per `(label, comparison)`: points, harmonics used
/// (range and mean), the worst error against the references and the worst estimate, the
/// points meeting the target, the references' harmonics, the largest ratios of error to
/// estimate and of estimate to error, the fixed
/// harmonics, their worst error and points; the wall times and their ratio are the timing
/// columns.
pub fn adaptive_sweeps(rows: &[(String, crate::adaptive_sweeps::AdaptiveComparison)]) -> Table {
    let mut table = Table::new(
        &[
            "rod, target",
            "points",
            "H per point (mean)",
            "worst error",
            "worst estimate",
            "points meeting",
            "reference H",
            "error / estimate at most",
            "estimate / error at most",
            "folds",
            "fixed H",
            "its worst error",
            "its points",
            "its folds",
            "seconds adaptive",
            "seconds fixed",
            "cost ratio",
        ],
        &[14, 15, 16],
    );
    let folds = |f: &[f64]| {
        f.iter()
            .map(|w| format!("{w:.5}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (label, c) in rows {
        let fixed = c.fixed.as_ref();
        table.rows.push(vec![
            format!("{label}, {:.0e}", c.target),
            c.points.to_string(),
            format!(
                "{} to {} ({:.1})",
                c.harmonics.0, c.harmonics.1, c.mean_harmonics
            ),
            format!("{:.1e}", c.worst_error()),
            format!("{:.1e}", c.worst_estimate()),
            match c.errors.iter().filter(|e| e.is_nan()).count() {
                0 => format!("{} of {}", c.met(), c.points),
                n => format!("{} of {} ({n} without a reference)", c.met(), c.points),
            },
            c.reference_harmonics.to_string(),
            format!("{:.2}", c.worst_underestimate()),
            format!("{:.1}", c.worst_overestimate()),
            folds(&c.folds),
            fixed.map_or("none".to_string(), |f| f.harmonics.to_string()),
            fixed.map_or("-".to_string(), |f| format!("{:.1e}", f.worst_error)),
            fixed.map_or("-".to_string(), |f| f.points.to_string()),
            fixed.map_or("-".to_string(), |f| folds(&f.folds)),
            format!("{:.2}", c.seconds),
            fixed.map_or("-".to_string(), |f| format!("{:.2}", f.seconds)),
            c.cost_ratio()
                .map_or("-".to_string(), |r| format!("{r:.2}")),
        ]);
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replace_block_replaces_only_the_named_block() {
        let text = format!(
            "intro\n{}\nold a\n{}\nmiddle\n{}\nold b\n{}\nend\n",
            block_start("a"),
            block_end("a"),
            block_start("b"),
            block_end("b")
        );
        let new = replace_block(&text, "b", "| x |\n|---|\n| 1 |\n").unwrap();
        assert!(new.contains("old a") && !new.contains("old b"), "{new}");
        assert!(new.contains(&format!(
            "{}\n\n| x |\n|---|\n| 1 |\n\n{}",
            block_start("b"),
            block_end("b")
        )));
        assert!(new.ends_with("end\n"));
        assert_eq!(replace_block(&text, "c", "x"), None);
        // Replacing twice gives the same text.
        assert_eq!(
            replace_block(&new, "b", "| x |\n|---|\n| 1 |").unwrap(),
            new
        );
    }

    #[test]
    fn every_section_has_a_file_and_a_distinct_name() {
        for (i, s) in SECTIONS.iter().enumerate() {
            assert!(s.file.starts_with("docs/") && s.file.ends_with(".md"));
            assert_eq!(section(s.name), Some(*s));
            assert!(SECTIONS[..i].iter().all(|t| t.name != s.name));
        }
    }
}
