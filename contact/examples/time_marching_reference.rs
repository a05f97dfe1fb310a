//! The time-marching reference on the canonical rod, in three tables (nothing asserted; the
//! tests of `contact/tests/time_marching.rs` check the claims):
//! 1. the modified-mass steady period at 1000 ... 8000 steps per period and two steady-state
//!    tolerances (tip extremes, parabola-refined minimum, mean contact force, cost);
//! 2. SSN-HB (H = 10, 20, 40, from zero) against that reference at 8000 steps per period;
//! 3. the consistent mass: SSN-HB (H = 20, 40) against Moreau–Jean (restitution 0 and 0.5,
//!    1000 and 4000 steps per period; the last period when the march does not lock onto the
//!    forcing period).
//!
//! `cargo run --release -p semismooth-contact --example time_marching_reference` (a few
//! minutes).

#[path = "../tests/common/periodic.rs"]
mod periodic;

use periodic::period_rms;
use periodic::{canonical_modified_period, extremes, modified_rod, parabolic_min, period_mean};
use semismooth::newton::NewtonReport;
use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::Residual;
use semismooth_contact::hb::{HbOptions, ResponseSummary, SsnHb, StructuredHbSolver};
use semismooth_contact::march::{march_to_steady_state, MarchError, MarchOptions, MarchScheme};
use semismooth_contact::rod::{build_rod, RodModel, RodSpec};

/// SSN-HB from zero with the structured solver (up to 1000 Newton iterations): the Newton
/// report and the tip summary on 4096 points.
fn ssn_hb_tip(rod: &RodModel, harmonics: usize) -> (NewtonReport, ResponseSummary) {
    let options = HbOptions {
        harmonics,
        ..HbOptions::default()
    };
    let mut hb = SsnHb::new(&rod.model, rod.omega(), &options).unwrap();
    let mut x = vec![0.0; hb.dim()];
    let options = PolyalgorithmOptions {
        max_iterations: 1000,
        ..PolyalgorithmOptions::default()
    };
    let report =
        solve_smoothing(&mut hb, &mut StructuredHbSolver::new(), &mut x, &options).unwrap();
    (report, hb.summary(&x, rod.tip_dof(), 4096).unwrap())
}

fn relative(a: f64, reference: f64) -> f64 {
    ((a - reference) / reference).abs()
}

fn refinement_table() {
    for tolerance in [1e-8, 1e-11] {
        println!("modified mass, steady-state tolerance {tolerance:e}");
        println!("spp | periods | tip max | tip min | tip min (parabola) | mean lambda | active steps | seconds");
        for spp in [1000, 2000, 4000, 8000] {
            let (period, seconds) = canonical_modified_period(spp, tolerance);
            let (lo, hi) = extremes(&period.displacements[0]);
            println!(
                "{spp} | {} | {hi:.10} | {lo:.10} | {:.10} | {:.10e} | {} | {seconds:.3}",
                period.periods,
                parabolic_min(&period.displacements[0]),
                period_mean(&period.contact_forces[0]),
                period.counters.active_steps
            );
        }
    }
}

fn harmonic_balance_against_the_reference() {
    let rod = modified_rod();
    let (period, _) = canonical_modified_period(8000, 1e-10);
    let u = &period.displacements[0];
    let (min, rms) = (parabolic_min(u), period_rms(u));
    let mean = period_mean(&period.contact_forces[0]);
    println!(
        "\nreference (8000 steps per period): tip min {min:.9} rms {rms:.9} mean lambda {mean:.9e}"
    );
    for harmonics in [10, 20, 40] {
        let (report, s) = ssn_hb_tip(&rod, harmonics);
        println!(
            "SSN-HB H {harmonics}: converged {} in {} iterations; tip min {:.9} ({:.2e} rel), \
             rms {:.9} ({:.2e} rel), mean lambda {:.9e} ({:.2e} rel)",
            report.converged(),
            report.iterations,
            s.displacement_min,
            relative(s.displacement_min, min),
            s.displacement_rms,
            relative(s.displacement_rms, rms),
            s.contact_force_mean[0],
            relative(s.contact_force_mean[0], mean)
        );
    }
}

fn consistent_mass_against_moreau_jean() {
    let rod = build_rod(&RodSpec::canonical()).unwrap();
    let tip = rod.tip_dof();
    println!("\nconsistent mass");
    let mut last = None;
    for harmonics in [20, 40] {
        let (report, s) = ssn_hb_tip(&rod, harmonics);
        println!(
            "SSN-HB H {harmonics} ({:?} after {} iterations, |F| {:.1e}): tip min {:.7} rms {:.7} \
             mean lambda {:.6e}",
            report.termination,
            report.iterations,
            report.residual_norm(),
            s.displacement_min,
            s.displacement_rms,
            s.contact_force_mean[0]
        );
        last = Some(s);
    }
    let hb = last.expect("two harmonic counts");
    for restitution in [0.0, 0.5] {
        for spp in [1000, 4000] {
            let options = MarchOptions {
                steps_per_period: spp,
                max_periods: 400,
                scheme: MarchScheme::MoreauJean {
                    theta: 0.5,
                    restitution,
                },
                ..MarchOptions::default()
            };
            let period = match march_to_steady_state(&rod.model, rod.omega(), &options, &[tip]) {
                Ok(p) => p,
                Err(MarchError::NotSteady { last_period, .. }) => *last_period,
                Err(other) => panic!("{other}"),
            };
            let u = &period.displacements[0];
            let (min, rms) = (parabolic_min(u), period_rms(u));
            let mean = period_mean(&period.contact_forces[0]);
            println!(
                "Moreau-Jean e {restitution} spp {spp}: periods {} change {:.1e}; tip min {min:.7} \
                 ({:.2e} rel to HB) rms {rms:.7} ({:.2e}) mean lambda {mean:.6e} ({:.2e})",
                period.periods,
                period.period_change,
                relative(min, hb.displacement_min),
                relative(rms, hb.displacement_rms),
                relative(mean, hb.contact_force_mean[0])
            );
        }
    }
}

fn main() {
    refinement_table();
    harmonic_balance_against_the_reference();
    consistent_mass_against_moreau_jean();
}
