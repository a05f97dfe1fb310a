//! The 3-D frictional oscillator solved two ways: SSN-HB and the exact Moreau–Jean march
//! to its steady state (shared by the test `frictional_march` and the example
//! `frictional_march_table`).
//!
//! A unit mass on `(x, y)` (springs 1, damping 0.1) is pressed on a flat at the gap 0.05 by
//! a massless normal dof `z` (spring 10, static load 1: `N = 0.5` at rest), with the
//! Coulomb disk `mu = 0.4` on `(x, y)`, under the loads `(fx cos w t, fy sin w t,
//! fz cos w t)`. While closed, `N(t) = 0.5 + fz cos w t` exactly (the massless `z` sits at
//! the gap): `fz < 0.5` keeps it closed, `fz > 0.5` lifts it off.

#![allow(dead_code)]

use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::Residual;
use semismooth_contact::hb::{FrictionalContactReport, HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::march::{march_to_steady_state, MarchOptions, SteadyPeriod};
use semismooth_contact::model::{
    ContactRow, FrictionalContact, HarmonicLoad, SparseMatrix, StructuralModel,
};
use std::f64::consts::PI;

/// One case of the oscillator: its name, in-plane loads `(fx, fy)`, normal load `fz`,
/// forcing frequency `w`.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    pub name: &'static str,
    pub plane: (f64, f64),
    pub normal: f64,
    pub omega: f64,
}

/// Stick-slip with a turning slip direction: an elliptical in-plane load, the normal force
/// varying in `[0.2, 0.8]` (never open).
pub const STICK_SLIP: Case = Case {
    name: "stick-slip, turning slip",
    plane: (0.25, 0.15),
    normal: 0.3,
    omega: 0.6,
};

/// Liftoff: the normal load `0.8 cos w t` exceeds the preload 0.5 for part of each period.
pub const LIFTOFF: Case = Case {
    name: "liftoff",
    plane: (0.3, 0.2),
    normal: 0.8,
    omega: 0.8,
};

/// The gap of the normal row.
pub const GAP: f64 = 0.05;

/// A diagonal matrix.
fn diagonal(values: &[f64]) -> SparseMatrix {
    let entries: Vec<_> = (values.iter().enumerate())
        .map(|(i, v)| faer::sparse::Triplet::new(i, i, *v))
        .collect();
    SparseMatrix::try_new_from_triplets(values.len(), values.len(), &entries).unwrap()
}

/// The oscillator of `case` (module documentation).
pub fn oscillator(case: &Case) -> StructuralModel {
    let mut load = HarmonicLoad::zero(3);
    let (fx, fy) = case.plane;
    load.add_harmonic(0, &[0.0, 0.0, 1.0], &[0.0; 3]).unwrap();
    load.add_harmonic(1, &[fx, 0.0, case.normal], &[0.0, fy, 0.0])
        .unwrap();
    let contact = FrictionalContact::unilateral(
        ContactRow::unit(2, 1.0),
        GAP,
        [ContactRow::unit(0, 1.0), ContactRow::unit(1, 1.0)],
        0.4,
    );
    StructuralModel {
        mass: diagonal(&[1.0, 1.0, 0.0]),
        damping: Some(diagonal(&[0.1, 0.1, 0.0])),
        stiffness: diagonal(&[1.0, 1.0, 10.0]),
        load,
        contacts: Vec::new(),
        friction: Vec::new(),
        frictional_contacts: vec![contact],
        cyclic: None,
    }
}

/// What is compared: the first-harmonic amplitudes of two in-plane displacements, the
/// mean normal force where it is compared, and the contact's report over the period.
#[derive(Debug, Clone)]
pub struct Measures {
    pub amplitude: [f64; 2],
    /// `None` where the mean normal force is not compared.
    pub mean_normal_force: Option<f64>,
    pub report: FrictionalContactReport,
}

impl Measures {
    /// The largest relative difference to `reference` of the two amplitudes, the dissipated
    /// energy and (where both have it) the mean normal force.
    pub fn difference(&self, reference: &Measures) -> f64 {
        let relative = |a: f64, b: f64| (a - b).abs() / b.abs();
        let normal = match (self.mean_normal_force, reference.mean_normal_force) {
            (Some(a), Some(b)) => relative(a, b),
            _ => 0.0,
        };
        relative(self.amplitude[0], reference.amplitude[0])
            .max(relative(self.amplitude[1], reference.amplitude[1]))
            .max(relative(
                self.report.dissipated_energy,
                reference.report.dissipated_energy,
            ))
            .max(normal)
    }
}

/// The march's first-order Richardson extrapolation `2 fine - coarse` of every measure
/// from `coarse` and `fine` (half the step), with `fine`'s series.
pub fn extrapolated(coarse: &Measures, fine: &Measures) -> Measures {
    let richardson = |f: f64, c: f64| 2.0 * f - c;
    let mut out = fine.clone();
    for a in 0..2 {
        out.amplitude[a] = richardson(fine.amplitude[a], coarse.amplitude[a]);
    }
    out.mean_normal_force = (fine.mean_normal_force)
        .zip(coarse.mean_normal_force)
        .map(|(f, c)| richardson(f, c));
    out.report.dissipated_energy = richardson(
        fine.report.dissipated_energy,
        coarse.report.dissipated_energy,
    );
    out
}

/// The amplitude of the first harmonic of equally spaced samples over one period.
pub fn first_harmonic(u: &[f64]) -> f64 {
    let n = u.len() as f64;
    let (mut a, mut b) = (0.0, 0.0);
    for (j, v) in u.iter().enumerate() {
        let (sin, cos) = (2.0 * PI * j as f64 / n).sin_cos();
        a += v * cos;
        b += v * sin;
    }
    2.0 * a.hypot(b) / n
}

/// SSN-HB of `model` with `harmonics` at `omega` solved from zero (asserted converged):
/// the problem and its solution.
pub fn solved_from_zero(
    model: &StructuralModel,
    omega: f64,
    harmonics: usize,
) -> (SsnHb, Vec<f64>) {
    let options = HbOptions {
        harmonics,
        ..HbOptions::default()
    };
    let mut hb = SsnHb::new(model, omega, &options).unwrap();
    let mut x = vec![0.0; hb.dim()];
    let newton = PolyalgorithmOptions::default();
    let report = solve_smoothing(&mut hb, &mut StructuredHbSolver::new(), &mut x, &newton).unwrap();
    assert!(
        report.converged(),
        "H = {harmonics}: {:?}",
        report.termination
    );
    (hb, x)
}

/// SSN-HB with `harmonics` from zero (asserted converged), measured on 4096 points.
pub fn harmonic_balance(case: &Case, harmonics: usize) -> Measures {
    let (hb, x) = solved_from_zero(&oscillator(case), case.omega, harmonics);
    let points = 4096;
    let amplitude =
        [0, 1].map(|dof| first_harmonic(&hb.displacement_samples(&x, dof, points).unwrap()));
    let report = hb.frictional_contact_report(&x, 0, points).unwrap();
    Measures {
        amplitude,
        mean_normal_force: None,
        report,
    }
}

/// A march series over one period without its closing sample (the series hold both ends).
pub fn one_period(series: &[f64]) -> Vec<f64> {
    series[..series.len() - 1].to_vec()
}

/// The report of the first frictional contact over the march's steady `period` at `omega`
/// (a slip below 1e-8 of the peak counts as stick).
pub fn march_report(period: &SteadyPeriod, omega: f64) -> FrictionalContactReport {
    let forces = &period.frictional_forces;
    let slip = &period.frictional_slip_velocities;
    let peak = (0..slip[0].len()).fold(0.0f64, |a, n| a.max(slip[0][n].hypot(slip[1][n])));
    FrictionalContactReport::from_march(
        0,
        one_period(&forces[0]),
        (
            [one_period(&forces[1]), one_period(&forces[2])],
            [one_period(&slip[0]), one_period(&slip[1])],
        ),
        omega,
        1e-8 * peak,
    )
}

/// The Moreau–Jean march (the model's scheme: `theta = 1` for the massless normal dof)
/// with `steps` per period to a period-to-period change of 1e-10.
pub fn march(case: &Case, steps: usize) -> Measures {
    let model = oscillator(case);
    let options = MarchOptions {
        steps_per_period: steps,
        tolerance: 1e-10,
        ..MarchOptions::default()
    };
    let period = march_to_steady_state(&model, case.omega, &options, &[0, 1]).unwrap();
    let amplitude = [0, 1].map(|o| first_harmonic(&one_period(&period.displacements[o])));
    Measures {
        amplitude,
        mean_normal_force: None,
        report: march_report(&period, case.omega),
    }
}
