//! The paper's figures and the default run of `ssn` (no subcommand), as library functions
//! so that examples and tests can call them.
//!
//! - Fig. 1: the tip displacement of the canonical rod (20 elements, gap 0.5, forced at
//!   `omega = omega_1`) over one period, SSN-HB from zero at `H = 10, 15, 20` against the
//!   time-marching reference (trapezoidal steps with a massless contact node, Moreau–Jean with
//!   restitution 0 otherwise). With the modified mass the harmonic-balance answers converge
//!   to the reference; with the consistent mass the reference depends on its impact law.
//! - Fig. 2: the frequency response `max |u_tip|` against `omega / omega_1` on `[0.5, 2]` for
//!   the gaps 0.25, 0.5, 0.75 and the rod without contact, by pseudo-arclength continuation of
//!   SSN-HB; folds are where the branch turns (the jump frequencies of a slow sweep).
//!
//! Each figure is written as `<stem>.svg` and `<stem>.csv` into the output directory.

use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;

use crate::exit::CliError;
use crate::output::{
    csv_table, prepare_directory, stability_key, stability_series, write_atomically,
    write_line_plot, LineStyle, PlotSpec, Series, BLACK_INDEX,
};
use crate::progress::progress_bar;
use crate::scene::{Method, SolverSettings, SweepSettings};
use semismooth_contact::model::Structure;
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::solve::{solve, Solution};

fn bad_input(e: impl std::fmt::Display) -> CliError {
    CliError::BadInput(e.to_string())
}

/// One row of the default run's Fig. 1 table.
#[derive(Debug, Clone)]
pub struct Fig1Row {
    /// Mass model.
    pub mass: MassModel,
    /// Harmonics (None for the reference).
    pub harmonics: Option<usize>,
    /// Newton iterations (periods for the reference).
    pub iterations: usize,
    /// Wall time of the solve.
    pub seconds: f64,
    /// Tip minimum over the period.
    pub tip_min: f64,
    /// Tip maximum over the period.
    pub tip_max: f64,
    /// Relative difference of the tip minimum to the reference.
    pub difference: f64,
    /// The solve's own error estimate (relative, on the reported quantities), when it has
    /// one.
    pub estimate: Option<f64>,
}

/// Writes `<stem>.svg` (the series) and `<stem>.csv` (the named columns) into `out`.
fn write_figure(
    out: &Path,
    stem: &str,
    plot: &PlotSpec,
    series: &[Series],
    columns: &[(String, Vec<f64>)],
) -> Result<(), CliError> {
    write_line_plot(&out.join(format!("{stem}.svg")), plot, series)?;
    let headers: Vec<&str> = columns.iter().map(|(h, _)| h.as_str()).collect();
    let data: Vec<&[f64]> = columns.iter().map(|(_, c)| c.as_slice()).collect();
    write_atomically(
        &out.join(format!("{stem}.csv")),
        csv_table(&headers, &data).as_bytes(),
    )?;
    Ok(())
}

/// Fig. 1 of the paper for one mass model: SSN-HB at H = 10, 15, 20 against the time-marching
/// reference; writes `fig1_<mass>.svg` and `.csv` into `out`.
pub fn figure_1(out: &Path, mass: MassModel) -> Result<Vec<Fig1Row>, CliError> {
    let spec = RodSpec {
        mass,
        ..RodSpec::canonical()
    };
    let rod = build_rod(&spec).map_err(bad_input)?;
    let name = mass_name(mass);
    let bar = progress_bar(4, &format!("Fig. 1 ({name} mass)"));
    // Reference: energy-conserving trapezoidal steps with a massless contact node; the
    // Moreau–Jean scheme (restitution 0) otherwise, with finer steps (first order).
    let reference_settings = SolverSettings {
        method: Method::March,
        steps_per_period: if mass == MassModel::Modified {
            4000
        } else {
            8000
        },
        march_tolerance: if mass == MassModel::Modified {
            1e-9
        } else {
            1e-6
        },
        ..SolverSettings::with_harmonics(20)
    };
    let reference = solve(&rod, rod.omega(), &reference_settings, None).map_err(bad_input)?;
    bar.inc(1);
    let period = 2.0 * std::f64::consts::PI / reference.omega;
    let mut series = Vec::new();
    let mut csv_columns: Vec<(String, Vec<f64>)> = Vec::new();
    let mut rows = Vec::new();
    let mut finest = None;
    for h in [10usize, 15, 20] {
        let settings = SolverSettings::with_harmonics(h);
        let s = solve(&rod, rod.omega(), &settings, None).map_err(bad_input)?;
        bar.inc(1);
        let phase: Vec<f64> = s.times.iter().map(|t| t / period).collect();
        series.push(Series::new(
            format!("SSN-HB H = {h}"),
            phase.clone(),
            s.observed.clone(),
        ));
        csv_columns.push((format!("t_over_T_H{h}"), phase));
        csv_columns.push((format!("u_tip_H{h}"), s.observed.clone()));
        rows.push(Fig1Row {
            mass,
            harmonics: Some(h),
            iterations: s.iterations,
            seconds: s.solve_seconds,
            tip_min: s.stats.min,
            tip_max: s.stats.max,
            difference: (s.stats.min - reference.stats.min).abs() / reference.stats.min.abs(),
            estimate: s.error_estimate.as_ref().ok().map(|e| e.relative),
        });
        finest = Some(s);
    }
    let phase: Vec<f64> = reference.times.iter().map(|t| t / period).collect();
    series.push(Series::dashed(
        "reference (time marching)",
        phase.clone(),
        reference.observed.clone(),
    ));
    csv_columns.push(("t_over_T_reference".into(), phase));
    csv_columns.push(("u_tip_reference".into(), reference.observed.clone()));
    rows.push(Fig1Row {
        mass,
        harmonics: None,
        iterations: reference.iterations,
        seconds: reference.solve_seconds,
        tip_min: reference.stats.min,
        tip_max: reference.stats.max,
        difference: 0.0,
        estimate: reference.error_estimate.as_ref().ok().map(|e| e.relative),
    });
    bar.finish_and_clear();
    series.extend(obstacle_lines(&rod, 0.0, 1.0));
    write_figure(
        out,
        &format!("fig1_{name}_mass"),
        &PlotSpec {
            title: format!(
                "Fig. 1: rod tip over one period, gap 0.5, omega = omega_1 ({name} mass)"
            ),
            x_label: "time t / T (T: forcing period)".into(),
            y_label: "tip displacement u_tip".into(),
            log_log: false,
        },
        &series,
        &csv_columns,
    )?;
    if let Some(hb) = finest {
        let stem = format!("fig1_{name}_mass");
        period_figures(
            out,
            &stem,
            &rod,
            &[(&hb, "SSN-HB H = 20"), (&reference, "reference")],
        )?;
    }
    Ok(rows)
}

/// `series` in palette colour `color`, solid for the first solution (`index` 0) and dashed
/// for the others (the references).
fn styled(series: Series, color: usize, index: usize) -> Series {
    let style = if index == 0 {
        LineStyle::Solid
    } else {
        LineStyle::Dashed
    };
    Series {
        style,
        ..series.with_color(color)
    }
}

/// The contact force of every contact over one period (`<stem>_contact_force.svg`) and the
/// orbit of the observed dof, displacement against velocity (`<stem>_orbit.svg`, the
/// velocity by central differences of the periodic samples), of each solution.
fn period_figures(
    out: &Path,
    stem: &str,
    rod: &Structure,
    solutions: &[(&Solution, &str)],
) -> Result<(), CliError> {
    let mut forces = Vec::new();
    let mut orbits = Vec::new();
    // A time-marching contact force is an impulse divided by one step at an impact, far
    // beyond the harmonic-balance force it is drawn with: where it reaches four times the
    // largest harmonic-balance compression it is clipped at twice that, and its label says
    // so.
    let hb_compression = solutions
        .iter()
        .filter(|(s, _)| s.method.is_harmonic_balance())
        .flat_map(|(s, _)| s.contact_forces.iter().flatten())
        .fold(0.0f64, |a, f| a.max(-f));
    let floor = -2.0 * hb_compression;
    for (color, (s, label)) in solutions.iter().enumerate() {
        let period = 2.0 * std::f64::consts::PI / s.omega;
        let phase: Vec<f64> = s.times.iter().map(|t| t / period).collect();
        for (k, f) in s.contact_forces.iter().enumerate() {
            let mut curve = if s.contact_forces.len() > 1 {
                format!("{label}, contact {k}")
            } else {
                label.to_string()
            };
            let deepest = f.iter().fold(0.0f64, |a, &v| a.min(v));
            let values = if hb_compression > 0.0 && deepest < 2.0 * floor {
                curve = format!("{curve} (impacts clipped at {floor:.2}; deepest {deepest:.2})");
                f.iter().map(|&v| v.max(floor)).collect()
            } else {
                f.clone()
            };
            forces.push(styled(
                Series::new(curve, phase.clone(), values),
                color + k,
                color,
            ));
        }
        let u = &s.observed;
        let m = u.len();
        let dt = period / m as f64;
        let v: Vec<f64> = (0..m)
            .map(|i| (u[(i + 1) % m] - u[(i + m - 1) % m]) / (2.0 * dt * s.omega))
            .collect();
        let mut closed_u = u.clone();
        let mut closed_v = v;
        if m > 0 {
            closed_u.push(u[0]);
            closed_v.push(closed_v[0]);
        }
        orbits.push(styled(
            Series::new(*label, closed_u, closed_v),
            color,
            color,
        ));
    }
    write_line_plot(
        &out.join(format!("{stem}_contact_force.svg")),
        &PlotSpec {
            title: "contact force over one period (compressive < 0)".into(),
            x_label: "time t / T".into(),
            y_label: "contact force lambda".into(),
            log_log: false,
        },
        &forces,
    )?;
    let gaps = rod
        .model
        .contacts
        .iter()
        .filter(|c| c.dof() == rod.observed_dof)
        .map(|c| c.gap);
    let (v_lo, v_hi) = orbits
        .iter()
        .flat_map(|s| s.y.iter().copied())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    for gap in gaps {
        orbits.push(Series {
            x: vec![gap, gap],
            y: vec![v_lo, v_hi],
            ..Series::horizontal("obstacle", 0.0, 0.0, 0.0)
        });
    }
    write_line_plot(
        &out.join(format!("{stem}_orbit.svg")),
        &PlotSpec {
            title: "orbit of the observed dof over one period".into(),
            x_label: "displacement u".into(),
            y_label: "velocity du/dt / omega".into(),
            log_log: false,
        },
        &orbits,
    )
    .map_err(CliError::from)
}

/// Dashed black lines at the obstacles of the contacts on the observed dof, over
/// `[x0, x1]` (plots of the observed displacement against time).
pub fn obstacle_lines(structure: &Structure, x0: f64, x1: f64) -> Vec<Series> {
    structure
        .model
        .contacts
        .iter()
        .filter_map(|c| match c.row.single() {
            Some((dof, sign)) if dof == structure.observed_dof => Some(Series::horizontal(
                format!("obstacle (gap {})", c.gap),
                sign * c.gap,
                x0,
                x1,
            )),
            _ => None,
        })
        .collect()
}

/// The Fig. 1 table: mass, method, iterations, time, tip extremes, difference to the reference.
pub fn fig1_table(rows: &[Fig1Row]) -> String {
    let mut out = String::from(
        "Fig. 1: rod tip over one period (20 elements, gap 0.5, omega = omega_1, zeta = 0.01)\n",
    );
    out.push_str(&format!(
        "{:<11} {:<10} {:>6} {:>9} {:>11} {:>11} {:>11} {:>10}\n",
        "mass", "method", "iter", "ms", "tip min", "tip max", "diff (min)", "estimate"
    ));
    for r in rows {
        out.push_str(&format!(
            "{:<11} {:<10} {:>6} {:>9.2} {:>11.6} {:>11.6} {:>11.2e} {:>10}\n",
            format!("{:?}", r.mass).to_lowercase(),
            r.harmonics
                .map(|h| format!("H = {h}"))
                .unwrap_or_else(|| "reference".into()),
            r.iterations,
            1e3 * r.seconds,
            r.tip_min,
            r.tip_max,
            r.difference,
            r.estimate
                .map_or_else(|| "none".to_string(), |e| format!("{e:.2e}"))
        ));
    }
    out
}

/// One curve of the default run's Fig. 2.
#[derive(Debug, Clone)]
pub struct Fig2Curve {
    /// Gap (None: no contact, the linear rod).
    pub gap: Option<f64>,
    /// Points on the branch.
    pub points: usize,
    /// Fold frequencies, in units of omega_1.
    pub folds: Vec<f64>,
    /// Peak amplitude and its frequency (units of omega_1).
    pub peak: (f64, f64),
    /// Wall time of the sweep.
    pub seconds: f64,
    /// Whether the branch reached the end of the interval.
    pub converged: bool,
    /// Points found unstable.
    pub unstable: usize,
    /// Points whose stability is undecided.
    pub undecided: usize,
}

/// The gaps of Fig. 2 (`None`: the rod without contact).
pub const FIG2_GAPS: [Option<f64>; 4] = [Some(0.25), Some(0.5), Some(0.75), None];

/// The rod of Fig. 2: the canonical rod with its tip contact at `gap`, or without contact.
pub fn fig2_rod(gap: Option<f64>) -> RodSpec {
    RodSpec::canonical().with_tip_gap(gap)
}

/// The name of a Fig. 2 curve: `gap <g>`, or `linear` without contact.
fn curve_label(gap: Option<f64>) -> String {
    gap.map(|g| format!("gap {g}"))
        .unwrap_or_else(|| "linear".into())
}

/// The sweep of the default run's Fig. 2: `omega/omega_1` in `[0.5, 2]`, steps of at most
/// [`FIG2_MAX_STEP`] so that each plotted step is at most [`FIG2_PLOTTED_STEP`] of the axis
/// ranges, up to 5000 points.
pub fn figure_2_sweep() -> SweepSettings {
    SweepSettings {
        step: FIG2_MAX_STEP,
        max_step: FIG2_MAX_STEP,
        max_points: 5000,
        ..SweepSettings::new(0.5, 2.0)
    }
}

/// Largest arclength step of the Fig. 2 sweeps (the sweep's own unit, module `sweep`).
/// (0.0075 leaves one step of 2.2 % where the gap-0.25 branch loses contact at H = 20,
/// measured; 0.005 gives at most 0.7 %.)
pub const FIG2_MAX_STEP: f64 = 0.005;

/// Largest plotted step of a Fig. 2 curve, as a fraction of the axis ranges.
pub const FIG2_PLOTTED_STEP: f64 = 0.015;

/// The mass model's name in file names and titles.
fn mass_name(mass: MassModel) -> &'static str {
    match mass {
        MassModel::Consistent => "consistent",
        MassModel::Lumped => "lumped",
        MassModel::Modified => "modified",
    }
}

/// The curves of Fig. 2 and their CSV columns, as drawn.
#[derive(Debug, Clone)]
pub struct Fig2 {
    /// One per gap.
    pub curves: Vec<Fig2Curve>,
    /// The plotted series (the pieces of each branch by stability, the obstacle-free key).
    pub series: Vec<Series>,
    /// The CSV columns: per curve `omega_ratio_<curve>`, `amplitude_<curve>`,
    /// `stable_<curve>` (1 stable, 0 unstable, empty undecided), of equal length.
    pub columns: Vec<(String, Vec<f64>)>,
    /// The file stem (`fig2_H<h>` for the consistent mass, the paper's rod;
    /// `fig2_H<h>_<mass>_mass` else).
    pub stem: String,
}

/// Fig. 2 of the paper: `max |u_tip|` against omega/omega_1 on [0.5, 2] for gaps 0.25, 0.5,
/// 0.75 and the linear rod, SSN-HB with `harmonics` harmonics and the `mass` model, by
/// pseudo-arclength continuation, each branch drawn by stability
/// ([`crate::output::STABILITY_KEY`]); writes `<stem>.svg` and `.csv` into `out`.
/// Folds are marked by circles. `<stem>_resonance.svg` is the same figure around the
/// resonance ([`resonance_window`]), where the folds and the unstable parts lie.
///
/// With the consistent mass the contact node has mass: the verdict is that of the
/// harmonic-balance orbit under the impact law it follows (module
/// `semismooth_contact::stability`).
pub fn figure_2(out: &Path, harmonics: usize, mass: MassModel) -> Result<Vec<Fig2Curve>, CliError> {
    let fig = figure_2_curves(harmonics, mass)?;
    let spec = PlotSpec {
        title: format!(
            "Fig. 2: frequency response of the rod tip, H = {harmonics}, {} mass",
            mass_name(mass),
        ),
        x_label: "forcing frequency omega / omega_1".into(),
        y_label: "tip amplitude max_t |u_tip(t)|".into(),
        log_log: false,
    };
    write_figure(out, &fig.stem, &spec, &fig.series, &fig.columns)?;
    if let Some((lo, hi)) = resonance_window(&fig.curves) {
        let zoomed: Vec<Series> = fig.series.iter().map(|s| clipped(s, lo, hi)).collect();
        let spec = PlotSpec {
            title: format!("{} (resonance)", spec.title),
            ..spec
        };
        write_line_plot(
            &out.join(format!("{}_resonance.svg", fig.stem)),
            &spec,
            &zoomed,
        )?;
    }
    Ok(fig.curves)
}

/// The frequencies (units of omega_1) around the contact branches' peaks and folds: from
/// the smallest to the largest of them, widened by half their spread and at least 0.02 on
/// each side; `None` without a contact branch.
pub fn resonance_window(curves: &[Fig2Curve]) -> Option<(f64, f64)> {
    let marks: Vec<f64> = curves
        .iter()
        .filter(|c| c.gap.is_some())
        .flat_map(|c| c.folds.iter().copied().chain([c.peak.1]))
        .filter(|v| v.is_finite())
        .collect();
    let lo = marks.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = marks.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo <= hi).then(|| {
        let margin = (0.5 * (hi - lo)).max(0.02);
        (lo - margin, hi + margin)
    })
}

/// The points of `series` with `lo <= x <= hi` (a legend entry without points stays).
fn clipped(series: &Series, lo: f64, hi: f64) -> Series {
    let (x, y) = series
        .x
        .iter()
        .zip(&series.y)
        .filter(|(x, _)| (lo..=hi).contains(*x))
        .map(|(x, y)| (*x, *y))
        .unzip();
    Series {
        x,
        y,
        ..series.clone()
    }
}

/// One branch of Fig. 2: the rod with `gap` (`None`: without contact) and `mass`, swept by
/// SSN-HB with `harmonics` harmonics over [`figure_2_sweep`], with its stability.
pub fn figure_2_branch(
    gap: Option<f64>,
    harmonics: usize,
    mass: MassModel,
) -> Result<
    (
        semismooth_contact::rod::RodModel,
        semismooth_contact::sweep::FrequencyResponse,
    ),
    CliError,
> {
    let spec = RodSpec {
        mass,
        ..fig2_rod(gap)
    };
    let rod = build_rod(&spec).map_err(bad_input)?;
    let r = semismooth_contact::sweep::frequency_response(
        &rod,
        &SolverSettings::with_harmonics(harmonics),
        &figure_2_sweep(),
        None,
    )
    .map_err(bad_input)?;
    Ok((rod, r))
}

/// The sweeps and series of [`figure_2`], without writing them.
pub fn figure_2_curves(harmonics: usize, mass: MassModel) -> Result<Fig2, CliError> {
    let bar = progress_bar(4, &format!("Fig. 2 (H = {harmonics})"));
    let mut curves = Vec::new();
    let mut series = Vec::new();
    let mut columns: Vec<(String, Vec<f64>)> = Vec::new();
    let mut verdicts = Vec::new();
    let mut folds_marked = false;
    // The branches are independent: followed side by side on the machine's cores.
    let branches = FIG2_GAPS
        .par_iter()
        .map(|&gap| {
            let branch = figure_2_branch(gap, harmonics, mass);
            bar.inc(1);
            branch
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    for (k, (gap, (rod, r))) in FIG2_GAPS.into_iter().zip(branches).enumerate() {
        let ratio = r.omega_ratio();
        let label = curve_label(gap);
        let peak = r
            .peak()
            .map(|(i, a)| (a, ratio[i]))
            .unwrap_or((f64::NAN, f64::NAN));
        let stable = &r.stable();
        let amplitude = r.amplitudes();
        curves.push(Fig2Curve {
            gap,
            points: r.points.len(),
            folds: r.folds.iter().map(|w| w / rod.omega_1).collect(),
            peak,
            seconds: r.solve_seconds + r.stability_seconds,
            converged: r.converged(),
            unstable: stable.iter().filter(|s| **s == Some(false)).count(),
            undecided: stable.iter().filter(|s| s.is_none()).count(),
        });
        let key = label.replace(' ', "_");
        columns.push((format!("omega_ratio_{key}"), ratio.clone()));
        columns.push((format!("amplitude_{key}"), amplitude.clone()));
        columns.push((
            format!("stable_{key}"),
            stable
                .iter()
                .map(|s| s.map_or(f64::NAN, |b| f64::from(u8::from(b))))
                .collect(),
        ));
        let mut pieces = stability_series(&label, k, &ratio, &amplitude, stable);
        if !r.fold_indices.is_empty() {
            let (x, y) = r
                .fold_indices
                .iter()
                .map(|&i| (ratio[i], amplitude[i]))
                .unzip();
            pieces.push(Series::markers("", x, y).with_color(k));
            folds_marked = true;
        }
        if gap.is_none() {
            // The linear rod underneath: off contact the contact branches coincide with it.
            series.splice(0..0, pieces);
        } else {
            series.extend(pieces);
        }
        verdicts.extend_from_slice(stable);
    }
    series.extend(stability_key(&verdicts));
    if folds_marked {
        series.push(Series::markers("fold", Vec::new(), Vec::new()).with_color(BLACK_INDEX));
    }
    bar.finish_and_clear();
    let stem = match mass {
        MassModel::Consistent => format!("fig2_H{harmonics}"),
        other => format!("fig2_H{harmonics}_{}_mass", mass_name(other)),
    };
    Ok(Fig2 {
        curves,
        series,
        columns,
        stem,
    })
}

/// The default run (`ssn` without a subcommand): the paper's figures into `out`.
pub fn default_run(out: &Path) -> Result<(), CliError> {
    prepare_directory(out)?;
    let start = Instant::now();
    // The four figures are independent: computed side by side on the machine's cores
    // (their files join the one output set, written all or nothing).
    let ((modified, consistent), (paper, massless)) = rayon::join(
        || {
            rayon::join(
                || figure_1(out, MassModel::Modified),
                || figure_1(out, MassModel::Consistent),
            )
        },
        || {
            rayon::join(
                || figure_2(out, 5, MassModel::Consistent),
                || figure_2(out, 20, MassModel::Modified),
            )
        },
    );
    let mut rows = modified?;
    rows.extend(consistent?);
    crate::io::write_text(&fig1_table(&rows))?;
    crate::outln!(
        "With the modified mass (massless contact node) harmonic balance converges to the \
         time-marching reference; with the consistent mass the reference depends on the impact \
         law (here restitution 0) and the two need not agree. The estimate is each solve's own \
         (relative, against a solve at 2H or with half the time steps; none where that \
         coarser march does not settle)."
    )?;
    crate::outln!()?;
    for ((harmonics, mass, setting), curves) in [
        (5, MassModel::Consistent, "the paper's setting, fig2_H5.svg"),
        (
            20,
            MassModel::Modified,
            "massless contact node, fig2_H20_modified_mass.svg",
        ),
    ]
    .into_iter()
    .zip([paper?, massless?])
    {
        crate::outln!(
            "Fig. 2 ({} mass, H = {harmonics}): frequency response max|u_tip| on \
             omega/omega_1 in [0.5, 2] ({setting})",
            mass_name(mass)
        )?;
        crate::outln!(
            "{:<8} {:>7} {:>11} {:>10} {:>22} {:>9} {:>9} {:>9}",
            "curve",
            "points",
            "peak",
            "at omega",
            "folds (omega/omega_1)",
            "unstable",
            "undecided",
            "ms"
        )?;
        for c in &curves {
            let folds: Vec<String> = c.folds.iter().map(|f| format!("{f:.4}")).collect();
            crate::outln!(
                "{:<8} {:>7} {:>11.6} {:>10.4} {:>22} {:>9} {:>9} {:>9.2}{}",
                curve_label(c.gap),
                c.points,
                c.peak.0,
                c.peak.1,
                if folds.is_empty() {
                    "none".to_string()
                } else {
                    folds.join(", ")
                },
                c.unstable,
                c.undecided,
                1e3 * c.seconds,
                if c.converged { "" } else { "  (stopped early)" }
            )?;
        }
    }
    crate::outln!(
        "Contact stiffens the rod: the peak moves to higher frequency and is bounded by the gap; \
         the branches fold over (the jump frequencies are the folds) and are unstable between \
         their folds. Stability: solid stable, dashed unstable, dotted undecided. With the \
         consistent mass (the paper's rod, fig2_H5.svg) the contact node has mass: the \
         verdict is that of the harmonic-balance orbit under the impact law it follows: a \
         perfectly inelastic impact (restitution 0) where it stays on the stop, its own \
         restitution where it rebounds or grazes the stop (just above the first contact, \
         where the impacting orbits are unstable). At H = 5 the branches turn several times near their peaks: the contact \
         holds only in the Galerkin sense (ssn/examples/strange_loops.rs)."
    )?;
    crate::outln!(
        "\nWrote {} in {:.1} s.",
        out.display(),
        start.elapsed().as_secs_f64()
    )?;
    Ok(())
}
