//! Outputs: CSV tables and SVG line plots (written through [`crate::io`], all or nothing).

use std::path::Path;

pub use crate::io::{prepare_directory, write_atomically, OutputError};

use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;

/// A CSV table from named columns of equal length (shorter columns are padded with empty
/// cells). Numbers are written with full precision; a non-finite value (an undecided
/// stability, a quantity that does not apply) is an empty cell, never `NaN` or `inf`.
pub fn csv_table(headers: &[&str], columns: &[&[f64]]) -> String {
    let rows = columns.iter().map(|c| c.len()).max().unwrap_or(0);
    let mut out = headers.join(",");
    out.push('\n');
    for r in 0..rows {
        let cells: Vec<String> = columns
            .iter()
            .map(|c| {
                c.get(r)
                    .filter(|v| v.is_finite())
                    .map(|v| format!("{v:e}"))
                    .unwrap_or_default()
            })
            .collect();
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// How a curve is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineStyle {
    /// A continuous line (stable branch parts, computed curves).
    Solid,
    /// Dashes of 6 px with gaps of 4 px (unstable branch parts, references).
    Dashed,
    /// Dots of 2 px with gaps of 4 px (branch parts whose stability is undecided).
    Dotted,
    /// A filled circle of radius 4 px at each point, no line (folds, bifurcations, the
    /// measured points of a study).
    Markers,
}

/// One curve of a line plot.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label (empty: no legend entry, e.g. a further piece of a labelled curve).
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// Stroke.
    pub style: LineStyle,
    /// Palette index of the colour (`None`: the series' own index).
    pub color: Option<usize>,
}

impl Series {
    /// A solid curve.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            label: label.into(),
            x,
            y,
            style: LineStyle::Solid,
            color: None,
        }
    }

    /// A dashed curve.
    pub fn dashed(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            style: LineStyle::Dashed,
            ..Series::new(label, x, y)
        }
    }

    /// The curve in palette colour `color`.
    pub fn with_color(self, color: usize) -> Self {
        Series {
            color: Some(color),
            ..self
        }
    }

    /// Filled circles at the points, no line.
    pub fn markers(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            style: LineStyle::Markers,
            ..Series::new(label, x, y)
        }
    }

    /// A horizontal line at `y` over `[x0, x1]` in black, dashed (an obstacle, a bound).
    pub fn horizontal(label: impl Into<String>, y: f64, x0: f64, x1: f64) -> Self {
        Series::dashed(label, vec![x0, x1], vec![y, y]).with_color(BLACK_INDEX)
    }
}

/// The key of the stability styles, for titles: solid stable, dashed unstable, dotted
/// undecided.
pub const STABILITY_KEY: &str = "solid: stable, dashed: unstable, dotted: stability undecided";

/// A branch drawn by stability ([`STABILITY_KEY`]): one series per run of points with the
/// same verdict, all in palette colour `color`, neighbouring runs sharing their boundary
/// point so that the curve is continuous; only the first carries `label`.
pub fn stability_series(
    label: &str,
    color: usize,
    x: &[f64],
    y: &[f64],
    stable: &[Option<bool>],
) -> Vec<Series> {
    let style = |s: Option<bool>| match s {
        Some(true) => LineStyle::Solid,
        Some(false) => LineStyle::Dashed,
        None => LineStyle::Dotted,
    };
    let mut out: Vec<Series> = Vec::new();
    let mut start = 0;
    let n = x.len().min(y.len()).min(stable.len());
    for i in 1..=n {
        if i == n || style(stable[i]) != style(stable[start]) {
            // The run [start, i) plus the first point of the next run.
            let end = (i + 1).min(n);
            out.push(Series {
                label: if out.is_empty() {
                    label.to_string()
                } else {
                    String::new()
                },
                x: x[start..end].to_vec(),
                y: y[start..end].to_vec(),
                style: style(stable[start]),
                color: Some(color),
            });
            start = i;
        }
    }
    out
}

/// A branch's stability as numbers, one per point: `stable` 1 / 0 (NaN when undecided: an
/// empty CSV cell) and the largest Floquet multiplier modulus (NaN when undecided).
pub fn stability_numbers(
    response: &semismooth_contact::sweep::FrequencyResponse,
) -> (Vec<f64>, Vec<f64>) {
    response
        .points
        .iter()
        .map(|p| {
            let s = &p.stability;
            (
                s.stable.map_or(f64::NAN, |b| f64::from(u8::from(b))),
                s.floquet_max_abs.unwrap_or(f64::NAN),
            )
        })
        .unzip()
}

/// Legend entries in black for the stability styles that `stable` uses (no points):
/// `stable` solid, `unstable` dashed, `stability undecided` dotted.
pub fn stability_key(stable: &[Option<bool>]) -> Vec<Series> {
    [
        (Some(true), "stable", LineStyle::Solid),
        (Some(false), "unstable", LineStyle::Dashed),
        (None, "stability undecided", LineStyle::Dotted),
    ]
    .into_iter()
    .filter(|(verdict, _, _)| stable.contains(verdict))
    .map(|(_, label, style)| Series {
        style,
        ..Series::new(label, Vec::new(), Vec::new()).with_color(BLACK_INDEX)
    })
    .collect()
}

/// The longest step between neighbouring points of the series, as a fraction of the axis
/// ranges of all series: `max_i max(|dx_i| / range_x, |dy_i| / range_y)`.
pub fn longest_plotted_step(series: &[Series]) -> f64 {
    let range = |f: &dyn Fn(&Series) -> &Vec<f64>| {
        let (lo, hi) = series
            .iter()
            .flat_map(|s| f(s).iter().copied().filter(|v| v.is_finite()))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        (hi - lo).max(f64::MIN_POSITIVE)
    };
    longest_plotted_step_on(series, range(&|s| &s.x), range(&|s| &s.y))
}

/// [`longest_plotted_step`] on axes of the ranges `rx` and `ry` (markers join nothing).
pub fn longest_plotted_step_on(series: &[Series], rx: f64, ry: f64) -> f64 {
    series
        .iter()
        .filter(|s| s.style != LineStyle::Markers)
        .flat_map(|s| {
            s.x.windows(2)
                .zip(s.y.windows(2))
                .map(|(x, y)| ((x[1] - x[0]).abs() / rx).max((y[1] - y[0]).abs() / ry))
        })
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
}

/// A tick label with as many decimals as the tick spacing of an axis of length `range`
/// needs (about ten ticks), never `-0` (a tick at round-off from zero is `0`).
pub fn tick_label(v: f64, range: f64) -> String {
    let step = range.abs().max(f64::MIN_POSITIVE) / 10.0;
    let mut decimals = (-step.log10().floor()).clamp(0.0, 12.0) as usize;
    // More decimals for a tick between the round values (e.g. a spacing of 0.25).
    while decimals < 12
        && (v - format!("{v:.decimals$}").parse::<f64>().unwrap_or(v)).abs() > 1e-9 * range.abs()
    {
        decimals += 1;
    }
    let text = format!("{v:.decimals$}");
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        text.trim_start_matches('-').to_string()
    } else {
        text
    }
}

/// Axes of a plot.
#[derive(Debug, Clone)]
pub struct PlotSpec {
    /// Title above the plot.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Logarithmic axes for both coordinates (non-positive values are dropped).
    pub log_log: bool,
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(0, 0, 0),
];

/// Palette index of black.
pub const BLACK_INDEX: usize = 7;

/// Size of the SVG documents in CSS pixels.
const SIZE: (u32, u32) = (840, 520);

/// The drawing is made at this multiple of [`SIZE`] and shown at [`SIZE`] (the document's
/// `viewBox`): plotters rounds coordinates to whole units, which are then quarter pixels.
const SUPERSAMPLING: u32 = 4;

/// A length of `px` CSS pixels in drawing units.
const fn px(px: u32) -> u32 {
    px * SUPERSAMPLING
}

/// [`px`] as a signed coordinate.
const fn ipx(v: i32) -> i32 {
    v * SUPERSAMPLING as i32
}

/// Draws the series as an SVG document (840 x 520 px, coordinates to a quarter pixel) and
/// returns it as a string.
pub fn line_plot_svg(spec: &PlotSpec, series: &[Series]) -> Result<String, OutputError> {
    let fail = |reason: String| OutputError::Plot {
        title: spec.title.clone(),
        reason,
    };
    let curves: Vec<(&Series, Vec<(f64, f64)>)> = series
        .iter()
        .map(|s| {
            let pts = s
                .x
                .iter()
                .zip(&s.y)
                .filter(|(x, y)| {
                    x.is_finite() && y.is_finite() && (!spec.log_log || (**x > 0.0 && **y > 0.0))
                })
                .map(|(x, y)| (*x, *y))
                .collect();
            (s, pts)
        })
        .collect();
    let all = curves.iter().flat_map(|(_, p)| p.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return Err(fail("no finite points to plot".into()));
    }
    // Padding and legend room are fractions of the axis, in log10 on log axes.
    let log = spec.log_log;
    let to_axis = |v: f64| if log { v.log10() } else { v };
    let from_axis = |v: f64| if log { 10f64.powf(v) } else { v };
    let pad = |a: f64, b: f64| {
        let (a, b) = (to_axis(a), to_axis(b));
        let d = if b > a {
            0.05 * (b - a)
        } else {
            0.5 * a.abs().max(1.0)
        };
        (a - d, b + d)
    };
    let (x0, x1) = pad(x0, x1);
    let (y0, mut y1) = pad(y0, y1);
    // Room for the legend (upper right: 22 px per entry and 16 px of frame on a plot area
    // of about 400 px high, about 200 px of 750 wide) above the curves that pass under it,
    // so that it hides none and the axis is no taller than that needs.
    let entries = series.iter().filter(|s| !s.label.is_empty()).count();
    if entries > 0 {
        let fraction = ((22 * entries + 16) as f64 / 400.0).min(0.6);
        let legend_left = x1 - 0.3 * (x1 - x0);
        let under_legend = curves
            .iter()
            .flat_map(|(_, p)| p.iter())
            .filter(|(x, _)| to_axis(*x) >= legend_left)
            .map(|(_, y)| to_axis(*y))
            .fold(f64::NEG_INFINITY, f64::max);
        if under_legend.is_finite() {
            // The legend's bottom at `y1 - fraction (y1 - y0)` above the highest of them.
            let needed = (under_legend + 0.02 * (y1 - y0) - fraction * y0) / (1.0 - fraction);
            y1 = y1.max(needed);
        }
    }
    let (x0, x1, y0, y1) = (from_axis(x0), from_axis(x1), from_axis(y0), from_axis(y1));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (px(SIZE.0), px(SIZE.1))).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
        let builder = |root| {
            let mut b = ChartBuilder::on(root);
            b.caption(&spec.title, ("sans-serif", px(18)))
                .margin(px(12))
                .x_label_area_size(px(44))
                .y_label_area_size(px(64));
            b
        };
        let log_tick = |v: &f64| format!("{v:.0e}");
        let (x_range, y_range) = (x1 - x0, y1 - y0);
        let x_tick = move |v: &f64| tick_label(*v, x_range);
        let y_tick = move |v: &f64| tick_label(*v, y_range);
        if spec.log_log {
            let mut chart = builder(&root)
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(|e| fail(e.to_string()))?;
            draw_chart(&mut chart, spec, (&log_tick, &log_tick), curves, entries).map_err(fail)?;
        } else {
            let mut chart = builder(&root)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| fail(e.to_string()))?;
            draw_chart(&mut chart, spec, (&x_tick, &y_tick), curves, entries).map_err(fail)?;
        }
        root.present().map_err(|e| fail(e.to_string()))?;
    }
    // Shown at SIZE: the drawing units become fractions of a pixel.
    let drawn = format!(r#"width="{}" height="{}""#, px(SIZE.0), px(SIZE.1));
    let shown = format!(r#"width="{}" height="{}""#, SIZE.0, SIZE.1);
    Ok(svg.replacen(&drawn, &shown, 1))
}

/// The tick label formatters of the two axes.
type Ticks<'t> = (&'t dyn Fn(&f64) -> String, &'t dyn Fn(&f64) -> String);

/// Draws the axes (labelled by `ticks`) and the curves (with their legend entries,
/// `entries` of them) on `chart`.
fn draw_chart<'a, X, Y>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>,
    spec: &PlotSpec,
    ticks: Ticks<'_>,
    curves: Vec<(&Series, Vec<(f64, f64)>)>,
    entries: usize,
) -> Result<(), String>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let fail = |e: DrawingAreaErrorKind<_>| e.to_string();
    chart
        .configure_mesh()
        .x_desc(spec.x_label.as_str())
        .y_desc(spec.y_label.as_str())
        .x_label_formatter(ticks.0)
        .y_label_formatter(ticks.1)
        .label_style(("sans-serif", px(12)))
        .axis_desc_style(("sans-serif", px(14)))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(fail)?;
    for (i, (s, pts)) in curves.into_iter().enumerate() {
        let color = PALETTE[s.color.unwrap_or(i) % PALETTE.len()];
        let style = ShapeStyle {
            color: color.to_rgba(),
            filled: false,
            stroke_width: px(2),
        };
        let anno = match s.style {
            LineStyle::Solid => chart.draw_series(LineSeries::new(pts, style)),
            LineStyle::Dashed => chart.draw_series(DashedLineSeries::new(pts, px(6), px(4), style)),
            LineStyle::Dotted => chart.draw_series(DashedLineSeries::new(pts, px(2), px(4), style)),
            LineStyle::Markers => chart.draw_series(
                pts.into_iter()
                    .map(|p| Circle::new(p, px(4), color.filled())),
            ),
        }
        .map_err(fail)?;
        if !s.label.is_empty() {
            // The legend's glyph in the curve's stroke: three pieces of a 20 px line, or
            // a marker.
            let pieces: [(i32, i32); 3] = match s.style {
                LineStyle::Solid => [(0, 7), (7, 14), (14, 20)],
                LineStyle::Dashed => [(0, 6), (10, 16), (20, 20)],
                LineStyle::Dotted | LineStyle::Markers => [(0, 2), (6, 8), (12, 14)],
            };
            let markers = s.style == LineStyle::Markers;
            // (The pieces are placed relative to the anchor of the composed element.)
            anno.label(s.label.clone()).legend(move |(x, y)| {
                let piece = |(a, b): (i32, i32)| {
                    let (a, b) = if markers { (0, 0) } else { (ipx(a), ipx(b)) };
                    PathElement::new(vec![(a, 0), (b, 0)], color.stroke_width(px(2)))
                };
                let marker = Circle::new(
                    (ipx(10), 0),
                    if markers { px(4) } else { 0 },
                    color.filled(),
                );
                EmptyElement::at((x, y))
                    + piece(pieces[0])
                    + piece(pieces[1])
                    + piece(pieces[2])
                    + marker
            });
        }
    }
    if entries > 0 {
        chart
            .configure_series_labels()
            .label_font(("sans-serif", px(13)))
            .legend_area_size(px(30))
            .margin(px(10))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(fail)?;
    }
    Ok(())
}

/// Draws and writes an SVG plot atomically.
pub fn write_line_plot(path: &Path, spec: &PlotSpec, series: &[Series]) -> Result<(), OutputError> {
    let svg = line_plot_svg(spec, series)?;
    write_atomically(path, svg.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_leaves_no_temporary_file_and_replaces_content() {
        let dir = std::env::temp_dir().join(format!("ssn-out-test-{}", std::process::id()));
        prepare_directory(&dir).unwrap();
        let path = dir.join("a.csv");
        write_atomically(&path, b"one").unwrap();
        write_atomically(&path, b"two").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "two");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(names.len(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn atomic_write_into_a_missing_directory_fails_with_the_path() {
        let path = Path::new("/nonexistent-dir-ssn/x.csv");
        let err = write_atomically(path, b"x").unwrap_err().to_string();
        assert!(err.contains("/nonexistent-dir-ssn/x.csv"), "{err}");
    }

    #[test]
    fn csv_table_round_trips_numbers_exactly() {
        let a = [0.1, 1.0 / 3.0];
        let b = [2.0];
        let text = csv_table(&["a", "b"], &[&a, &b]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "a,b");
        let v: f64 = lines[2].split(',').next().unwrap().parse().unwrap();
        assert_eq!(v, 1.0 / 3.0);
        assert!(lines[2].ends_with(','));
    }

    #[test]
    fn csv_table_writes_non_finite_values_as_empty_cells() {
        let a = [1.0, f64::NAN, f64::INFINITY, 0.0];
        let text = csv_table(&["stable"], &[&a]);
        assert_eq!(text, "stable\n1e0\n\n\n0e0\n");
    }

    #[test]
    fn svg_plot_contains_every_label() {
        let spec = PlotSpec {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_log: false,
        };
        let svg = line_plot_svg(
            &spec,
            &[
                Series::new("first", vec![0.0, 1.0], vec![0.0, 1.0]),
                Series::dashed("second", vec![0.0, 1.0], vec![1.0, 0.0]),
            ],
        )
        .unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("first") && svg.contains("second"));
    }

    #[test]
    fn tick_labels_have_no_negative_zero() {
        assert_eq!(tick_label(-1e-17, 1.0), "0.0");
        assert_eq!(tick_label(-0.0, 2.0), "0.0");
        assert_eq!(tick_label(-0.3, 1.0), "-0.3");
        assert_eq!(tick_label(0.25, 1.0), "0.25");
        assert_eq!(tick_label(0.05, 0.1), "0.05");
        assert_eq!(tick_label(2.0, 20.0), "2");
        assert_eq!(tick_label(1.5, 20.0), "1.5");
    }

    #[test]
    fn stability_runs_share_their_boundary_points() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let stable = [Some(true), Some(true), Some(false), None, None];
        let s = stability_series("b", 2, &x, &x, &stable);
        let styles: Vec<LineStyle> = s.iter().map(|s| s.style).collect();
        assert_eq!(
            styles,
            [LineStyle::Solid, LineStyle::Dashed, LineStyle::Dotted]
        );
        assert_eq!(s[0].x, [0.0, 1.0, 2.0]);
        assert_eq!(s[1].x, [2.0, 3.0]);
        assert_eq!(s[2].x, [3.0, 4.0]);
        assert_eq!(s[0].label, "b");
        assert!(s[1].label.is_empty() && s[2].label.is_empty());
        assert!(s.iter().all(|s| s.color == Some(2)));
        assert!((longest_plotted_step(&s) - 0.25).abs() < 1e-15);
    }
}
