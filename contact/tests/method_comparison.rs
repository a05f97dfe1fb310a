//! Every method on the same scene (SSN-HB, penalty HB, the periodic LCP by Lemke and by
//! semismooth Newton, and time marching) agrees on the canonical modified-mass rod, with
//! differences that shrink as each discretisation is refined.

mod common;

use common::{relative, solve_converged as solve};

use semismooth_contact::rod::{build_rod, MassModel, RodModel};
use semismooth_contact::settings::{default_hb_time_samples, Method, SolverSettings};
use semismooth_contact::solve::Solution;

fn rod() -> RodModel {
    build_rod(&common::canonical(MassModel::Modified)).unwrap()
}

/// The time-marching reference: 4000 steps per period, marched to a period-to-period
/// change below 1e-10.
fn reference(rod: &RodModel) -> Solution {
    solve(rod, &common::march(4000, 1e-10))
}

fn hb(method: Method, h: usize) -> SolverSettings {
    SolverSettings {
        method,
        ..SolverSettings::with_harmonics(h)
    }
}

fn lcp(method: Method, nt: usize) -> SolverSettings {
    SolverSettings {
        method,
        time_samples: nt,
        ..SolverSettings::with_harmonics(20)
    }
}

#[test]
fn all_methods_agree_on_the_tip_minimum_at_their_finest_settings() {
    let rod = rod();
    let reference = reference(&rod);
    let scale = rod.model.contact_stiffness_scale();
    // With the relative difference of each to the reference, measured (release build).
    let finest = [
        ("ssn-hb H=40", 6.10e-5, solve(&rod, &hb(Method::SsnHb, 40))),
        (
            "penalty-hb H=40 kp=1e5 scale",
            1.15e-4,
            solve(
                &rod,
                &SolverSettings {
                    penalty_stiffness: Some(1e5 * scale),
                    ..hb(Method::PenaltyHb, 40)
                },
            ),
        ),
        (
            "lcp-lemke Nt=1024",
            6.08e-6,
            solve(&rod, &lcp(Method::LcpLemke, 1024)),
        ),
        (
            "lcp-ssn Nt=1024",
            6.08e-6,
            solve(&rod, &lcp(Method::LcpSsn, 1024)),
        ),
    ];
    // Each within twice its measured difference: HB's truncation at H = 40, the penalty's
    // limit at fixed H, the LCP's time step; all within 2e-3 a priori.
    let tolerance = |measured: f64| 2.0 * measured;
    for (name, measured, s) in &finest {
        let d = relative(s.stats.min, reference.stats.min);
        println!(
            "{name:<30} tip min {:.8} (vs march {:.2e}), penetration {:.2e}, mean force {:.6e}",
            s.stats.min, d, s.stats.max_penetration, s.stats.mean_contact_force
        );
        assert!(
            d < tolerance(*measured),
            "{name}: {d:e}, measured {measured:e}"
        );
        assert!(s.stats.mean_contact_force < 0.0);
    }
    for (a, ma, sa) in &finest {
        for (b, mb, sb) in &finest {
            let d = relative(sa.stats.min, sb.stats.min);
            assert!(d < tolerance(*ma) + tolerance(*mb), "{a} vs {b}: {d:e}");
        }
    }
    // Lemke and Newton solve the same LCP: same answer to round-off (measured 8.5e-16, a
    // few ulps of the tip); allowed 3e-15 (3.5 times that).
    let same = relative(finest[2].2.stats.min, finest[3].2.stats.min);
    println!("lcp-lemke vs lcp-ssn at Nt = 1024: {same:e}");
    assert!(same < 3e-15, "{same:e}");
}

#[test]
fn differences_to_the_reference_shrink_with_refinement() {
    let rod = rod();
    let reference = reference(&rod);
    let error = |s: &Solution| relative(s.stats.min, reference.stats.min);
    // LCP over Nt: the bilinear-map error is second order in the step.
    let lcp_errors: Vec<f64> = [128, 256, 512, 1024]
        .iter()
        .map(|&nt| error(&solve(&rod, &lcp(Method::LcpLemke, nt))))
        .collect();
    println!("lcp-lemke errors over Nt = 128..1024: {lcp_errors:?}");
    assert!(lcp_errors.windows(2).all(|w| w[1] < w[0]), "{lcp_errors:?}");
    // SSN-HB over H: the truncation error oscillates with H at the 1e-5 level once H >= 20
    // (a Gibbs-like effect of the kink in the contact force), so the claim is on the
    // envelope: every refinement beats H = 10 and H = 80 is within 2e-5.
    let hb_errors: Vec<f64> = [10, 20, 40, 80]
        .iter()
        .map(|&h| error(&solve(&rod, &hb(Method::SsnHb, h))))
        .collect();
    println!("ssn-hb errors over H = 10, 20, 40, 80: {hb_errors:?}");
    assert!(
        hb_errors[1..].iter().all(|e| *e < hb_errors[0]),
        "{hb_errors:?}"
    );
    assert!(hb_errors[3] < 2e-5, "{hb_errors:?}");
    // Penalty HB over k_p (H = 40): penetration ~ 1/k_p until the truncation in H
    // dominates (the penalty's limit at fixed H differs from the reference by ~1e-4).
    let scale = rod.model.contact_stiffness_scale();
    let penalty: Vec<Solution> = [1e1, 1e2, 1e3]
        .iter()
        .map(|&k| {
            solve(
                &rod,
                &SolverSettings {
                    penalty_stiffness: Some(k * scale),
                    time_samples: default_hb_time_samples(40),
                    ..hb(Method::PenaltyHb, 40)
                },
            )
        })
        .collect();
    let pen_errors: Vec<f64> = penalty.iter().map(error).collect();
    let penetrations: Vec<f64> = penalty.iter().map(|s| s.stats.max_penetration).collect();
    println!("penalty-hb errors over k_p = 1e1..1e3 scale: {pen_errors:?}, penetrations {penetrations:?}");
    assert!(pen_errors.windows(2).all(|w| w[1] < w[0]), "{pen_errors:?}");
    assert!(
        penetrations.windows(2).all(|w| w[1] < 0.5 * w[0]),
        "{penetrations:?}"
    );
}
