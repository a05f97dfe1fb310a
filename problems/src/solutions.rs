//! Every periodic response at one forcing frequency, with its stability.
//!
//! Inside an overhang of a frequency response a forced structure with contact has several
//! periodic responses at the same frequency `w*`; which one a machine settles on depends on
//! its history. The branch of the scene's harmonic-balance problem holds all of them that
//! are connected to the linear response: [`find_solutions`] follows it in frequency with
//! the core's continuation over a window around `w*` (the scene's `[sweep]` range, or
//! `[0.5, 2] w*` without one), takes every pair of neighbouring branch points on either
//! side of `w*`, corrects the interpolated state by Newton at exactly `w*` (the runner's
//! solve with that warm start), merges corrections that land on the same solution
//! (relative distance of the unknowns below [`SAME_SOLUTION`]) and computes the stability
//! of each ([`crate::stability::hb_stability`]).
//!
//! Isolated branches (not connected to the linear response) are not found; nor are
//! solutions outside the window.

use std::time::Instant;

use crate::branch::Reconstruction;
use crate::model::Structure;
use crate::runner::{solve_rod, RunError, Solution};
use crate::scene::{Method, SolverSettings, SweepSettings};
use crate::stability::{hb_stability, Stability, StabilityOptions};
use crate::state::{HbState, StateShape};
use crate::sweep::follow_branch;

/// Relative distance of the unknowns below which two corrected solutions are the same.
pub const SAME_SOLUTION: f64 = 1e-6;

/// One contact's diagnostics over a period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSummary {
    /// The contact dof.
    pub dof: usize,
    /// Its gap.
    pub gap: f64,
    /// Mean contact force over a period (`<= 0`).
    pub contact_force_mean: f64,
    /// Largest `max(0, u - g)` over the period.
    pub max_penetration: f64,
}

/// One periodic solution at the frequency.
#[derive(Debug, Clone)]
pub struct PeriodicSolution {
    /// The corrected solve at exactly the frequency (tip series, statistics, unknowns).
    pub solution: Solution,
    /// Per contact.
    pub contacts: Vec<ContactSummary>,
    /// Floquet multipliers and the verdict.
    pub stability: Stability,
    /// Index of the branch point after the crossing it was corrected from.
    pub branch_index: usize,
}

/// The answer of [`find_solutions`].
#[derive(Debug, Clone)]
pub struct SolutionSet {
    /// The forcing frequency `w*`.
    pub omega: f64,
    /// First natural frequency.
    pub omega_1: f64,
    /// The shape of every solution's unknowns (method, harmonics, dofs, contacts).
    pub shape: StateShape,
    /// The distinct solutions, in branch order.
    pub solutions: Vec<PeriodicSolution>,
    /// The window searched, in units of `omega_1`.
    pub window: (f64, f64),
    /// Branch points followed.
    pub branch_points: usize,
    /// Whether the branch crossed the whole window.
    pub branch_converged: bool,
    /// The continuation's termination in words.
    pub branch_termination: String,
    /// Crossings of `w*` found on the branch.
    pub crossings: usize,
    /// Crossings whose correction did not converge (listed as their termination).
    pub failed_corrections: Vec<String>,
    /// Wall time.
    pub seconds: f64,
}

/// All periodic solutions at the model's forcing frequency (module documentation).
/// `sweep`: the window and continuation settings (`None`: `[0.5, 2] w* / omega_1` with the
/// scene defaults).
pub fn find_solutions(
    rod: &Structure,
    settings: &SolverSettings,
    sweep: Option<&SweepSettings>,
) -> Result<SolutionSet, RunError> {
    let started = Instant::now();
    if !matches!(settings.method, Method::SsnHb | Method::PenaltyHb) {
        return Err(RunError::Unsupported {
            method: settings.method.name(),
            what: "a harmonic-balance method (ssn-hb or penalty-hb) to follow the branch \
                   through the frequency and correct each crossing",
        });
    }
    let omega = rod.model.forcing.omega;
    let ratio = omega / rod.omega_1;
    let window = match sweep {
        Some(s) => s.clone(),
        None => SweepSettings::new(0.5 * ratio, 2.0 * ratio),
    };
    let (lo, hi) = (
        window.omega_ratio_from.min(window.omega_ratio_to),
        window.omega_ratio_from.max(window.omega_ratio_to),
    );
    if !(lo <= ratio && ratio <= hi) {
        return Err(RunError::InvalidSetting {
            name: "forcing.omega_ratio",
            value: ratio,
            allowed: "a frequency inside the [sweep] range searched for solutions",
        });
    }
    let branch = follow_branch(rod, settings, &window, None)?;
    let mut at_omega = rod.clone();
    at_omega.model.forcing.omega = omega;
    let reconstruction = Reconstruction::new(&rod.model, settings)?;
    let len = rod.model.dofs() * (2 * settings.harmonics + 1);
    let mut set = SolutionSet {
        omega,
        omega_1: rod.omega_1,
        shape: StateShape {
            method: settings.method,
            harmonics: settings.harmonics,
            dofs: rod.model.dofs(),
            contacts: rod.model.contacts.len(),
        },
        solutions: Vec::new(),
        window: (window.omega_ratio_from, window.omega_ratio_to),
        branch_points: branch.points(),
        branch_converged: branch.converged,
        branch_termination: branch.termination.clone(),
        crossings: 0,
        failed_corrections: Vec::new(),
        seconds: 0.0,
    };
    for i in 1..branch.points() {
        let (w0, w1) = (branch.omega[i - 1], branch.omega[i]);
        // Each crossing once: the left point strictly on one side (or exactly at w*).
        let crosses = (w0 - omega) * (w1 - omega) < 0.0 || w1 == omega;
        if !crosses {
            continue;
        }
        set.crossings += 1;
        let t = if w1 != w0 {
            (omega - w0) / (w1 - w0)
        } else {
            1.0
        };
        let start: Vec<f64> = branch.states[i - 1]
            .iter()
            .zip(&branch.states[i])
            .map(|(a, b)| a + t * (b - a))
            .collect();
        let solution = solve_rod(&at_omega, settings, Some(&start))?;
        if !solution.converged {
            set.failed_corrections.push(format!(
                "crossing between points {} and {i}: {} (|F| = {:e})",
                i - 1,
                solution.termination,
                solution.residual_norm
            ));
            continue;
        }
        let x = &solution.state;
        let scale = x.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-300);
        let duplicate = set.solutions.iter().any(|s| {
            let d = s
                .solution
                .state
                .iter()
                .zip(x)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            d <= SAME_SOLUTION * scale
        });
        if duplicate {
            continue;
        }
        let stability = hb_stability(
            &rod.model,
            settings.harmonics,
            omega,
            &x[..len],
            &StabilityOptions::default(),
        )
        .unwrap_or_else(|e| Stability::undecided(format!("stability not computed: {e}"), 0));
        let contacts = reconstruction.contacts(&rod.model, x)?;
        set.solutions.push(PeriodicSolution {
            solution,
            contacts,
            stability,
            branch_index: i,
        });
    }
    set.seconds = started.elapsed().as_secs_f64();
    Ok(set)
}

impl SolutionSet {
    /// The JSON of `ssn solutions --json`: `omega`, `omega_ratio`, `window`,
    /// `branch_points`, `branch_converged`, `crossings`, `failed_corrections`, `seconds` and
    /// `solutions`, each {`tip_min`, `tip_max`, `contact_force_mean`, `max_penetration`,
    /// `contacts` [{`dof`, `gap`, `contact_force_mean`, `max_penetration`}], `stable`
    /// (true / false / null), `floquet_max_abs`, `stability_note`, `iterations`,
    /// `residual_norm`, `state` (the harmonic coefficients, [`crate::state`]: start
    /// `ssn solve` from it with `--start FILE --entry K`)}.
    pub fn to_json(&self) -> serde_json::Value {
        let solutions: Vec<serde_json::Value> = self
            .solutions
            .iter()
            .map(|s| {
                let contacts: Vec<serde_json::Value> = s
                    .contacts
                    .iter()
                    .map(|c| {
                        serde_json::json!({
                            "dof": c.dof,
                            "gap": c.gap,
                            "contact_force_mean": c.contact_force_mean,
                            "max_penetration": c.max_penetration,
                        })
                    })
                    .collect();
                serde_json::json!({
                    "tip_min": s.solution.stats.min,
                    "tip_max": s.solution.stats.max,
                    "contact_force_mean": s.solution.stats.mean_contact_force,
                    "max_penetration": s.solution.stats.max_penetration,
                    "contacts": contacts,
                    "stable": s.stability.stable,
                    "floquet_max_abs": s.stability.floquet_max_abs,
                    "stability_note": s.stability.reason,
                    "iterations": s.solution.iterations,
                    "residual_norm": s.solution.residual_norm,
                    "state": HbState::from_unknowns(
                        self.shape,
                        self.omega,
                        self.omega_1,
                        &s.solution.state
                    )
                    .to_json(),
                })
            })
            .collect();
        serde_json::json!({
            "omega": self.omega,
            "omega_ratio": self.omega / self.omega_1,
            "window": [self.window.0, self.window.1],
            "branch_points": self.branch_points,
            "branch_converged": self.branch_converged,
            "crossings": self.crossings,
            "failed_corrections": self.failed_corrections,
            "seconds": self.seconds,
            "solutions": solutions,
        })
    }
}

/// `ssn solutions SCENE`: every periodic solution at the scene's frequency (module
/// documentation); text or JSON on stdout, a CSV row per solution, an SVG of the tip over
/// one period (stable solid, unstable dashed, undecided dotted).
pub fn command(args: &crate::cli::RunArgs) -> Result<(), crate::cli::CliError> {
    use crate::cli::CliError;
    use crate::output::{csv_table, line_plot_svg, LineStyle, PlotSpec, Series};
    let (scene, rod) = crate::cli::load(&args.scene)?;
    let mut outputs = args.plan()?;
    let bad = |e: RunError| CliError::BadInput(format!("{}: {e}", args.scene.display()));
    let set = find_solutions(&rod, &scene.solver, scene.sweep.as_ref()).map_err(bad)?;
    let column = |f: &dyn Fn(&PeriodicSolution) -> f64| -> Vec<f64> {
        set.solutions.iter().map(f).collect()
    };
    if let Some(csv) = &args.csv {
        let columns = [
            column(&|s| s.solution.stats.min),
            column(&|s| s.solution.stats.max),
            column(&|s| s.solution.stats.mean_contact_force),
            column(&|s| s.solution.stats.max_penetration),
            column(&|s| {
                s.stability
                    .stable
                    .map_or(f64::NAN, |b| f64::from(u8::from(b)))
            }),
            column(&|s| s.stability.floquet_max_abs.unwrap_or(f64::NAN)),
        ];
        let refs: Vec<&[f64]> = columns.iter().map(|c| c.as_slice()).collect();
        let headers = [
            "tip_min",
            "tip_max",
            "contact_force_mean",
            "max_penetration",
            "stable",
            "floquet_max_abs",
        ];
        outputs.add(csv, csv_table(&headers, &refs).into_bytes());
    }
    if let Some(svg) = &args.svg {
        let mut series: Vec<Series> = set
            .solutions
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let t: Vec<f64> = s
                    .solution
                    .times
                    .iter()
                    .map(|t| t * set.omega / (2.0 * std::f64::consts::PI))
                    .collect();
                let label = match s.stability.stable {
                    Some(true) => format!("solution {} (stable)", k + 1),
                    Some(false) => format!("solution {} (unstable)", k + 1),
                    None => format!("solution {} (stability undecided)", k + 1),
                };
                // The stability styles of the sweeps: solid, dashed, dotted.
                let style = match s.stability.stable {
                    Some(true) => LineStyle::Solid,
                    Some(false) => LineStyle::Dashed,
                    None => LineStyle::Dotted,
                };
                Series {
                    style,
                    ..Series::new(label, t, s.solution.tip.clone())
                }
            })
            .collect();
        series.extend(crate::figures::obstacle_lines(&rod, 0.0, 1.0));
        let spec = PlotSpec {
            title: format!(
                "periodic solutions at omega/omega_1 = {:.4}",
                set.omega / set.omega_1
            ),
            x_label: "time t / T (T: forcing period)".into(),
            y_label: "tip displacement u_tip".into(),
            log_log: false,
        };
        outputs.add(svg, line_plot_svg(&spec, &series)?.into_bytes());
    }
    let text = || {
        let mut t = format!(
            "omega/omega_1     {:.6}: {} solution(s) from {} crossing(s) of a {}-point branch \
             over [{}, {}]\n",
            set.omega / set.omega_1,
            set.solutions.len(),
            set.crossings,
            set.branch_points,
            set.window.0,
            set.window.1
        );
        for (k, s) in set.solutions.iter().enumerate() {
            t += &format!(
                "  {}: tip min {:.6} max {:.6}, mean contact force {:.4e}, {} (max |mu| {})\n",
                k + 1,
                s.solution.stats.min,
                s.solution.stats.max,
                s.solution.stats.mean_contact_force,
                match s.stability.stable {
                    Some(true) => "stable".to_string(),
                    Some(false) => "unstable".to_string(),
                    None => format!(
                        "undecided: {}",
                        s.stability.reason.clone().unwrap_or_default()
                    ),
                },
                s.stability
                    .floquet_max_abs
                    .map_or("-".to_string(), |m| format!("{m:.4}"))
            );
        }
        for f in &set.failed_corrections {
            t += &format!("  not corrected: {f}\n");
        }
        if !set.solutions.is_empty() {
            t += "  (--json carries each solution's state: ssn solve SCENE --start FILE --entry K \
                  starts from solution K)\n";
        }
        t
    };
    args.finish(outputs, || set.to_json(), text, true)
}
