//! A contact law coupling two rows of `G`, added as one type: Coulomb friction on a 2-D
//! tangent plane (the friction disk), sampled by SSN-HB like the built-in laws and solved
//! through the dense, condensed-dense and matrix-free linear paths.
//!
//! Check with no code of ours: an isotropic two-dof oscillator `m x'' + c x' + k x =
//! F (cos w t, sin w t) + lambda` with the disk law `|lambda| <= b` under a constant normal
//! load slides on the circle of the closed form in `common/rotating_oscillator.rs`. The
//! force is a pure first harmonic and every time sample of the law is exact, so harmonic
//! balance with any `H` has this solution.

use std::sync::Arc;

use semismooth::linalg::FaerDenseLu;
use semismooth::Factorize;
use semismooth_contact::hb::{
    CondensedSolve, CondensedSsnHb, HbError, HbJacobian, HbOptions, SsnHb, StructuredHbSolver,
};
use semismooth_contact::law::{ContactLaw, LawGroup, LawSamples, Measure};
use semismooth_contact::model::{ContactRow, HarmonicLoad, StructuralModel};

#[path = "common/rotating_oscillator.rs"]
mod rotating_oscillator;
use rotating_oscillator::{circle_radius, diagonal, max_difference, solved_from_zero};
use rotating_oscillator::{DAMPING, FORCE, MASS, OMEGA, STIFFNESS};

/// `phi_mu(s) = (s + sqrt(s^2 + 4 mu^2)) / 2`, the smoothing of `max(0, s)`, with its
/// slope and its `mu`-derivative (both 0 away from the kink at `mu = 0`).
fn phi(s: f64, mu: f64) -> (f64, f64, f64) {
    if mu == 0.0 {
        (s.max(0.0), if s > 0.0 { 1.0 } else { 0.0 }, 0.0)
    } else {
        let root = s.hypot(2.0 * mu);
        (0.5 * (s + root), 0.5 * (1.0 + s / root), 2.0 * mu / root)
    }
}

/// Coulomb friction on a 2-D tangent plane under a prescribed normal load: the radial
/// projection onto the disk of radius `b`, `proj(z) = b z / max(|z|, b)`, smoothed as
/// `b z / d` with `d = b + phi_mu(|z| - b)`. Its generalized Jacobian is a full 2 x 2
/// block per sample: `(b / d) (I - phi' z z^T / (d |z|))`, the identity inside the disk.
#[derive(Debug)]
struct FrictionDisk {
    radius: f64,
}

impl FrictionDisk {
    /// `(z1, z2, |z|, d, phi', d phi / d mu)` of sample `n`.
    fn sample(&self, at: &LawSamples<'_>, n: usize) -> (f64, f64, f64, f64, f64, f64) {
        let (z1, z2) = (at.z[n], at.z[at.samples + n]);
        let s = z1.hypot(z2);
        let (excess, slope, dmu) = phi(s - self.radius, at.smoothing);
        (z1, z2, s, self.radius + excess, slope, dmu)
    }
}

impl ContactLaw for FrictionDisk {
    fn rows(&self) -> usize {
        2
    }

    fn measure(&self) -> Measure {
        Measure::Velocity
    }

    fn project(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        let nt = at.samples;
        for n in 0..nt {
            let (z1, z2, _, d, _, _) = self.sample(at, n);
            out[n] = self.radius * z1 / d;
            out[nt + n] = self.radius * z2 / d;
        }
    }

    fn jacobian(&self, at: &LawSamples<'_>, dz: &mut [f64], _dread: &mut [f64]) {
        let nt = at.samples;
        for n in 0..nt {
            let (z1, z2, s, d, slope, _) = self.sample(at, n);
            let scale = self.radius / d;
            let radial = if s > 0.0 { slope / (d * s) } else { 0.0 };
            let z = [z1, z2];
            for a in 0..2 {
                for b in 0..2 {
                    let identity = if a == b { 1.0 } else { 0.0 };
                    dz[(2 * a + b) * nt + n] = scale * (identity - radial * z[a] * z[b]);
                }
            }
        }
    }

    fn smoothing_derivative(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        let nt = at.samples;
        for n in 0..nt {
            let (z1, z2, _, d, _, dmu) = self.sample(at, n);
            let scale = -self.radius * dmu / (d * d);
            out[n] = scale * z1;
            out[nt + n] = scale * z2;
        }
    }

    fn force_scale(&self) -> f64 {
        self.radius
    }
}

/// The disk's radius (`F > b`: the oscillator slides all period).
const SLIP_LIMIT: f64 = 0.3;

/// The isotropic two-dof oscillator under the rotating load `F (cos w t, sin w t)`.
fn rotating_oscillator() -> StructuralModel {
    let mut load = HarmonicLoad::zero(2);
    load.add_harmonic(1, &[FORCE, 0.0], &[0.0, FORCE]).unwrap();
    let diagonal = |v: f64| diagonal(&[v; 2]);
    StructuralModel::new(diagonal(MASS), diagonal(STIFFNESS), vec![0.0; 2])
        .with_damping(diagonal(DAMPING))
        .with_load(load)
}

/// The friction disk on the two dofs' rows.
fn disk() -> LawGroup {
    LawGroup {
        rows: vec![ContactRow::unit(0, 1.0), ContactRow::unit(1, 1.0)],
        offsets: vec![0.0, 0.0],
        law: Arc::new(FrictionDisk { radius: SLIP_LIMIT }),
    }
}

/// The HB options of the disk problems: `harmonics` and `c = k`.
fn disk_options(harmonics: usize) -> HbOptions {
    HbOptions {
        harmonics,
        c: Some(STIFFNESS),
        ..HbOptions::default()
    }
}

/// SSN-HB with the disk solved from zero with `solver` to `|F| <= 1e-12`.
fn solve_with(solver: &mut dyn Factorize<HbJacobian>, harmonics: usize) -> Vec<f64> {
    let options = disk_options(harmonics);
    let mut hb = SsnHb::with_laws(&rotating_oscillator(), OMEGA, &options, &[disk()]).unwrap();
    solved_from_zero(&mut hb, solver, 1e-12)
}

/// The disk law (two rows, a full 2 x 2 Jacobian block per sample) gives one solution
/// through the dense LU of the full Jacobian, the condensed dense LU and matrix-free GMRES
/// on the condensed system, and it is the sliding circle of the closed form.
#[test]
fn a_two_row_friction_disk_agrees_across_linear_paths_and_with_the_sliding_circle() {
    let harmonics = 5;
    let dense = solve_with(&mut FaerDenseLu::new(), harmonics);
    let condensed = StructuredHbSolver::new().with_condensed_solve(CondensedSolve::Dense);
    let condensed = solve_with(&mut { condensed }, harmonics);
    let krylov = StructuredHbSolver::new().with_condensed_solve(CondensedSolve::Krylov);
    let krylov = solve_with(&mut { krylov }, harmonics);
    // Each path stops at |F| <= 1e-12 on an O(1) problem with an O(10)-conditioned
    // Jacobian: the iterates agree far below 1e-10.
    for (name, other) in [("condensed dense", &condensed), ("matrix-free", &krylov)] {
        let gap = max_difference(&dense, other);
        assert!(gap < 1e-10, "{name} differs from dense by {gap:e}");
    }
    // U index j N + dof: harmonic 1 of x is (U[2], U[4]), of y (U[3], U[5]).
    let radius = circle_radius(SLIP_LIMIT);
    let amplitude = |dof: usize| dense[2 + dof].hypot(dense[4 + dof]);
    // Every sample of the law is exact on the circle, so the only error is Newton's
    // (|F| <= 1e-12 times a condition number of O(10)).
    for dof in 0..2 {
        assert!(
            (amplitude(dof) - radius).abs() < 1e-10,
            "dof {dof}: {} against {radius}",
            amplitude(dof)
        );
    }
    // A circle: no constant and no higher harmonic.
    let rest = dense[..2]
        .iter()
        .chain(&dense[6..2 * (2 * harmonics + 1)])
        .fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(rest < 1e-10, "off-circle coefficients {rest:e}");
}

/// The condensed form (contact forces only) of the full problem with the disk law has the
/// full problem's root once expanded.
#[test]
fn the_condensed_problem_takes_the_disk_law_and_agrees_with_the_full_one() {
    let harmonics = 5;
    let full = solve_with(&mut FaerDenseLu::new(), harmonics);
    let options = disk_options(harmonics);
    let model = rotating_oscillator();
    let with_disk = SsnHb::with_laws(&model, OMEGA, &options, &[disk()]).unwrap();
    let mut condensed = CondensedSsnHb::condense(with_disk).unwrap();
    let lambda = solved_from_zero(&mut condensed, &mut FaerDenseLu::new(), 1e-12);
    let expanded = condensed.expand(&lambda).unwrap();
    // Both stop at |F| <= 1e-12 on an O(1) problem with an O(10)-conditioned Jacobian
    // (the condensed one is the Schur complement of the full one): they agree far below
    // 1e-10.
    let gap = max_difference(&full, &expanded);
    assert!(gap < 1e-10, "condensed differs from full by {gap:e}");
    let refused = SsnHb::with_laws(
        &model,
        OMEGA,
        &options,
        &[{
            let mut short = disk();
            short.offsets.pop();
            short
        }],
    );
    assert!(matches!(refused, Err(HbError::DimensionMismatch { .. })));
}

/// A group whose offsets or reads do not fit its rows is refused with the sizes, not a
/// panic.
#[test]
fn a_law_group_that_does_not_fit_is_refused() {
    let options = HbOptions::default();
    let model = rotating_oscillator();
    let mut short = disk();
    short.offsets.pop();
    let refused = SsnHb::with_laws(&model, OMEGA, &options, &[short]).unwrap_err();
    assert!(
        matches!(
            refused,
            HbError::DimensionMismatch {
                expected: 2,
                found: 1,
                ..
            }
        ),
        "{refused:?}"
    );
    let mut off_model = disk();
    off_model.rows[1] = ContactRow::unit(7, 1.0);
    let refused = SsnHb::with_laws(&model, OMEGA, &options, &[off_model]).unwrap_err();
    assert!(
        matches!(
            refused,
            HbError::IndexOutOfRange {
                index: 7,
                count: 2,
                ..
            }
        ),
        "{refused:?}"
    );
}
