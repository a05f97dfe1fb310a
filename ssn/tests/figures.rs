//! The default run's figures as a user would publish them: Fig. 2's branches are drawn
//! finely (each plotted step at most 1.5 % of the axis ranges), each curve's CSV columns
//! have equal length, and with the modified mass the branch is dashed exactly where it is
//! unstable, between its folds.

use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::SolverSettings;
use semismooth_contact::solve::solve;
use ssn::figures::{fig2_rod, figure_2_branch, figure_2_curves, FIG2_PLOTTED_STEP};
use ssn::output::{longest_plotted_step, longest_plotted_step_on, stability_series, LineStyle};

/// The paper's Fig. 2 (consistent mass, H = 5): fine steps, equal CSV columns per curve,
/// no contact branch dotted (every point decided, the contact node having mass).
#[test]
fn paper_fig2_is_drawn_finely_with_equal_csv_columns() {
    let fig = figure_2_curves(5, MassModel::Consistent).unwrap();
    let step = longest_plotted_step(&fig.series);
    println!(
        "consistent mass H = 5: longest plotted step {:.4} of the axis ranges",
        step
    );
    assert!(step <= FIG2_PLOTTED_STEP, "{step}");
    assert_eq!(fig.columns.len(), 12);
    for curve in fig.columns.chunks(3) {
        let len = curve[0].1.len();
        assert!(len > 100, "{}", curve[0].0);
        assert!(curve.iter().all(|(_, c)| c.len() == len), "{}", curve[0].0);
    }
    for s in &fig.series {
        assert_ne!(s.style, LineStyle::Dotted, "{}", s.label);
    }
    assert!(fig.curves.iter().all(|c| c.converged && c.undecided == 0));
}

/// The paper's Fig. 2 branch with gap 0.5 (consistent mass, H = 5): stable before its
/// first reversal of the frequency and after its last, unstable points between them only
/// (the boundaries of its unstable parts are its folds and the corners where it turns).
#[test]
fn paper_fig2_branch_is_unstable_only_between_its_folds() {
    let (rod, r) = figure_2_branch(Some(0.5), 5, MassModel::Consistent).unwrap();
    assert!(r.converged());
    let mut reversals: Vec<usize> = r
        .fold_indices
        .iter()
        .chain(&r.corner_fold_indices)
        .copied()
        .collect();
    reversals.sort_unstable();
    println!(
        "folds {:?}, corner folds {}",
        r.folds.iter().map(|w| w / rod.omega_1).collect::<Vec<_>>(),
        r.corner_fold_indices.len()
    );
    let (first, last) = (reversals[0], reversals[reversals.len() - 1]);
    let st = &r.stability;
    let unstable: Vec<usize> = (0..r.points())
        .filter(|&i| st.stable[i] == Some(false))
        .collect();
    println!(
        "{} unstable points, between indices {first} and {last} of {}",
        unstable.len(),
        r.points()
    );
    assert!(!unstable.is_empty());
    assert!(
        unstable.iter().all(|&i| first <= i && i <= last),
        "{unstable:?} outside {first}..={last}"
    );
    assert!(st.stable.iter().all(|s| s.is_some()));
}

/// The modified-mass branch with gap 0.25 at H = 20 (its contact loss is the sharpest bend
/// of Fig. 2): on the axes of the figure each plotted step is at most 1.5 % (0.7 %
/// measured); its dashed pieces lie between its two folds and its solid
/// ones outside.
#[test]
fn modified_mass_branch_is_fine_and_dashed_between_its_folds() {
    let (rod, r) = figure_2_branch(Some(0.25), 20, MassModel::Modified).unwrap();
    assert!(r.converged());
    let ratio = r.omega_ratio();
    let series = stability_series("gap 0.25", 0, &ratio, &r.amplitude, &r.stability.stable);
    // The axes of Fig. 2: omega/omega_1 over [0.5, 2], the amplitude from about 0.007
    // (at 2 omega_1) up to the linear resonance; 0.98 times the linear rod's amplitude at
    // exactly omega_1 (one linear solve, at most the peak) is below the figure's range.
    let linear_rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..fig2_rod(None)
    })
    .unwrap();
    let linear = solve(
        &linear_rod,
        linear_rod.omega(),
        &SolverSettings::with_harmonics(20),
        None,
    )
    .unwrap();
    assert!(linear.converged());
    let y_range = 0.98 * linear.stats.max.abs().max(linear.stats.min.abs());
    let step = longest_plotted_step_on(&series, 1.5, y_range);
    println!(
        "modified mass H = 20, gap 0.25: {} points, folds {:?}, longest plotted step {step:.4}",
        r.points(),
        r.folds.iter().map(|w| w / rod.omega_1).collect::<Vec<_>>()
    );
    assert!(step <= FIG2_PLOTTED_STEP, "{step}");
    assert_eq!(r.folds.len(), 2);
    let (hi, lo) = (r.folds[0] / rod.omega_1, r.folds[1] / rod.omega_1);
    let dashed: Vec<_> = series
        .iter()
        .filter(|s| s.style == LineStyle::Dashed)
        .collect();
    assert!(!dashed.is_empty());
    // The pieces share their end points with the neighbouring ones: a dashed piece may
    // reach one point past a fold (the branch steps are at most 0.005 omega_1 here).
    for s in &dashed {
        assert!(
            s.x.iter().all(|x| lo - 5e-3 <= *x && *x <= hi + 5e-3),
            "dashed piece {:?} outside the folds {lo}..{hi}",
            (s.x.first(), s.x.last())
        );
    }
    // Far from the overhang everything is solid (stable).
    for s in &series {
        if s.x.iter().any(|x| *x < 0.9 || *x > 1.2) {
            assert_eq!(s.style, LineStyle::Solid, "{}", s.label);
        }
    }
}
