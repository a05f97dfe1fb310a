//! Solving from zero over the public grid of the 20-element rod (damping ratio 0.01,
//! distributed load `p0` in {0.1, 0.4}, tip gaps {0.25, 0.5, 0.75}, omega from 0.8 to 1.6
//! omega_1 by 0.04, consistent and modified mass, H = 20 and 40), with the default settings
//! (the polyalgorithm: full steps, then the Newton homotopy, then the line search).
//!
//! Independent check: every point that converges from zero lies on the frequency response
//! followed by pseudo-arclength continuation from the linear regime (0.7 omega_1, no contact):
//! its tip maximum matches the branch, linearly interpolated at that frequency, at one of the
//! branch's crossings of it. The branch is sampled with steps of at most 0.01, so the
//! interpolation error of the tip maximum (a function of omega with bounded curvature away
//! from corners) is far below the 1e-2 allowed; a solution on another branch (or garbage)
//! differs by far more (the gaps are 0.25 to 0.75).
//!
//! The number of points that converge is a measured bound, asserted both ways (a regression
//! and an improvement are both noticed). `cargo run --release --example from_zero` prints the
//! whole table with the hard cases.

mod common;

use semismooth_problems::figures::default_settings;
use semismooth_problems::from_zero::{grid_frequency_ratios, grid_rod, GRID_GAPS};
use semismooth_problems::rod::{build_rod, MassModel};
use semismooth_problems::runner::solve_rod;
use semismooth_problems::scene::{Method, SweepSettings};
use semismooth_problems::sweep::frequency_response;

/// The tip maxima of a branch at `omega`, at each crossing (linear interpolation).
fn branch_tip_max_at(omega: &[f64], tip_max: &[f64], at: f64) -> Vec<f64> {
    omega
        .windows(2)
        .zip(tip_max.windows(2))
        .filter(|(w, _)| (w[0] - at) * (w[1] - at) <= 0.0 && w[0] != w[1])
        .map(|(w, a)| a[0] + (a[1] - a[0]) * (at - w[0]) / (w[1] - w[0]))
        .collect()
}

/// Points (of 126 per group) measured to converge from zero, and the most iterations a
/// converged point took, per mass model and `H`.
const MEASURED: [(MassModel, usize, usize, usize); 4] = [
    (MassModel::Consistent, 20, 126, 82),
    (MassModel::Consistent, 40, 126, 92),
    (MassModel::Modified, 20, 126, 68),
    (MassModel::Modified, 40, 126, 76),
];

#[test]
fn the_public_grid_converges_from_zero_on_the_measured_points_and_on_the_branch() {
    let ratios = grid_frequency_ratios();
    let mut failures = Vec::new();
    for (mass, harmonics, measured, measured_worst) in MEASURED {
        let settings = default_settings(harmonics);
        let sweep_settings = common::sweep_solver(Method::SsnHb, harmonics);
        let mut converged: usize = 0;
        let mut worst = 0;
        for p0 in [0.1, 0.4] {
            for gap in GRID_GAPS {
                let base = build_rod(&grid_rod(mass, p0, gap, 1.0)).unwrap();
                let sweep = SweepSettings {
                    step: 0.01,
                    max_step: 0.01,
                    ..SweepSettings::new(0.7, 1.7)
                };
                let branch = frequency_response(&base, &sweep_settings, &sweep, None).unwrap();
                assert!(
                    branch.converged,
                    "{mass:?} H={harmonics} p0={p0} gap={gap}: sweep {}",
                    branch.termination
                );
                let branch_ratio: Vec<f64> =
                    branch.omega.iter().map(|w| w / base.omega_1).collect();
                for &ratio in &ratios {
                    let rod = build_rod(&grid_rod(mass, p0, gap, ratio)).unwrap();
                    let sol = solve_rod(&rod, &settings, None).unwrap();
                    if !sol.converged {
                        failures.push(format!(
                            "{mass:?} H={harmonics} p0={p0} gap={gap} omega={ratio:.2}: {}",
                            sol.termination
                        ));
                        continue;
                    }
                    converged += 1;
                    worst = worst.max(sol.iterations);
                    let on_branch = branch_tip_max_at(&branch_ratio, &branch.tip_max, ratio);
                    let distance = on_branch
                        .iter()
                        .map(|a| (a - sol.stats.max).abs())
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        distance < 1e-2,
                        "{mass:?} H={harmonics} p0={p0} gap={gap} omega={ratio:.2}: tip max {} \
                         ({}) is not on the branch (crossings {on_branch:?})",
                        sol.stats.max,
                        sol.strategy.unwrap_or("-"),
                    );
                }
            }
        }
        println!(
            "{mass:?} mass, H = {harmonics}: {converged} of 126 converged from zero, worst {worst} iterations"
        );
        assert_eq!(
            converged, measured,
            "{mass:?} H = {harmonics}: {converged} of 126 points converged, measured {measured}"
        );
        // The worst count, measured, within 10 % both ways: a regression and an
        // improvement are both noticed.
        assert!(
            worst.abs_diff(measured_worst) * 10 <= measured_worst,
            "{mass:?} H = {harmonics}: worst {worst} iterations, measured {measured_worst}"
        );
    }
    for f in &failures {
        println!("not converged: {f}");
    }
}
