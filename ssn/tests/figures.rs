//! The default run's figures as a user would publish them: Fig. 2's branches are drawn
//! finely (each plotted step at most 1.5 % of the axis ranges), each curve's CSV columns
//! have equal length, and the branch is dashed exactly where it is unstable: between its
//! folds, and with the consistent mass also where it grazes the stop.

use semismooth_contact::march::{march_to_steady_state, MarchError, MarchOptions, MarchScheme};
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

/// Every contact branch of the paper's Fig. 2 (consistent mass, H = 5): unstable at every
/// point strictly between its two folds (the middle branch of the overhang, however the
/// harmonic balance zigzags near its peak), stable at every point after the lower fold,
/// and before the upper fold stable but within 0.02 omega_1 above the first contact (the
/// grazing band of the test below): the stability boundaries are the folds.
#[test]
fn paper_fig2_branches_change_stability_at_their_folds() {
    for gap in [0.25, 0.5, 0.75] {
        let (rod, r) = figure_2_branch(Some(gap), 5, MassModel::Consistent).unwrap();
        assert!(r.converged());
        let w1 = rod.omega_1;
        let stable = &r.stable();
        assert_eq!(r.fold_indices.len(), 2, "gap {gap}: {:?}", r.folds);
        let (upper, lower) = (r.fold_indices[0], r.fold_indices[1]);
        let contact = (0..r.points.len())
            .find(|&i| r.points[i].observed_max > gap)
            .expect("a contact");
        let unstable_between = (upper + 1..lower)
            .filter(|&i| stable[i] == Some(false))
            .count();
        println!(
            "gap {gap}: folds {:?}, {unstable_between} of {} points between them unstable",
            r.folds.iter().map(|w| w / w1).collect::<Vec<_>>(),
            lower - upper - 1
        );
        assert_eq!(unstable_between, lower - upper - 1, "gap {gap}");
        assert!(
            (lower + 1..r.points.len()).all(|i| stable[i] == Some(true)),
            "gap {gap}"
        );
        for (i, (verdict, omega)) in stable
            .iter()
            .zip(&r.column(|p| p.omega))
            .take(upper)
            .enumerate()
        {
            let grazing = i >= contact && *omega < r.points[contact].omega + 0.02 * w1;
            assert!(
                *verdict == Some(true) || grazing,
                "gap {gap}: unstable at {:.4} before the upper fold",
                omega / w1
            );
        }
    }
}

/// The paper's Fig. 2 branch with gap 0.5 (consistent mass, H = 5): unstable between its
/// first and last reversal of the frequency, and just above its first contact, where its
/// orbit grazes the stop and rebounds (at 0.6 to 1.0 times its approach speed at H = 5)
/// and the impacting orbits near grazing are unstable; stable elsewhere. Moreau–Jean
/// marching (restitution 0) agrees: from rest it settles to a periodic motion below the
/// first contact and at omega_1, and not in the grazing band.
#[test]
fn paper_fig2_branch_is_unstable_between_its_folds_and_where_it_grazes() {
    let (rod, r) = figure_2_branch(Some(0.5), 5, MassModel::Consistent).unwrap();
    assert!(r.converged());
    let w1 = rod.omega_1;
    let mut reversals: Vec<usize> = r
        .fold_indices
        .iter()
        .chain(&r.corner_fold_indices)
        .copied()
        .collect();
    reversals.sort_unstable();
    let (first, last) = (reversals[0], reversals[reversals.len() - 1]);
    let contact = (0..r.points.len())
        .find(|&i| r.points[i].observed_max > 0.5)
        .expect("a contact");
    let stable = r.stable();
    let grazing: Vec<usize> = (0..first).filter(|&i| stable[i] == Some(false)).collect();
    println!(
        "folds {:?}, first contact at {:.4}, unstable below the first reversal at {:?}",
        r.folds.iter().map(|w| w / w1).collect::<Vec<_>>(),
        r.points[contact].omega / w1,
        grazing
            .iter()
            .map(|&i| r.points[i].omega / w1)
            .collect::<Vec<_>>()
    );
    assert!(stable.iter().all(|s| s.is_some()));
    assert!((first..=last).any(|i| stable[i] == Some(false)));
    assert!((last + 1..r.points.len()).all(|i| stable[i] == Some(true)));
    // The grazing band: within 0.02 omega_1 above the first contact (measured 0.982 to
    // 0.994 with the contact at 0.982).
    assert!(!grazing.is_empty());
    assert!(grazing
        .iter()
        .all(|&i| i >= contact && r.points[i].omega < r.points[contact].omega + 0.02 * w1));
    let options = MarchOptions {
        steps_per_period: 1000,
        tolerance: 1e-6,
        max_periods: 1500,
        scheme: MarchScheme::MOREAU_JEAN_DEFAULT,
    };
    let middle = grazing[grazing.len() / 2];
    for (omega, settles) in [
        (0.97 * w1, true),
        (r.points[middle].omega, false),
        (w1, true),
    ] {
        let result = march_to_steady_state(&rod.model, omega, &options, &[rod.tip_dof()]);
        // Measured: settled in 190 and 81 periods at 0.97 and 1; a period-to-period change
        // of 1e-4 to 3e-3 after 1500 periods in the band.
        match result {
            Ok(p) => assert!(
                settles,
                "{:.4}: settled in {} periods",
                omega / w1,
                p.periods
            ),
            Err(MarchError::NotSteady { change, .. }) => {
                assert!(!settles, "{:.4}: change {change:e}", omega / w1)
            }
            Err(e) => panic!("{e}"),
        }
    }
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
    let series = stability_series(
        "gap 0.25",
        0,
        &ratio,
        &r.column(|p| p.amplitude),
        &r.stable(),
    );
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
        r.points.len(),
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
