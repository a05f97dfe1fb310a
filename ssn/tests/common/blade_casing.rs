//! The blade-casing scene (`scenes/blade_casing.toml`) solved two ways: SSN-HB and the
//! exact 3-D Moreau–Jean march to its steady state (shared by the test `blade_casing` and
//! the example `blade_casing`, which also writes the scene's matrices from
//! [`BladeMatrices::build`]; the blade is described there).

#![allow(dead_code)]

#[path = "../../../contact/tests/common/disk_march.rs"]
mod disk_march;

use std::f64::consts::PI;
use std::path::Path;

pub use disk_march::{extrapolated, Measures};
use disk_march::{first_harmonic, march_report, one_period, solved_from_zero};
use semismooth_contact::builder::sparse_matrix;
use semismooth_contact::hb::FrictionalContactReport;
use semismooth_contact::march::{march_from_state, MarchOptions, MarchState, SteadyPeriod};
use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::{SparseMatrix, Structure};
use ssn::scene::Scene;

/// Bending elements of the blade.
pub const ELEMENTS: usize = 4;
/// Flapwise and edgewise bending stiffness, axial stiffness (`L = rhoA = 1`).
pub const BENDING: [f64; 2] = [1.0, 4.0];
/// Axial stiffness `EA`.
pub const AXIAL: f64 = 1000.0;
/// Angle of the principal bending axes from the circumferential and axial directions.
pub const STAGGER: f64 = PI / 6.0;
/// Angle of the casing's normal from the blade's axis, towards the circumferential `y`.
pub const LEAN: f64 = 0.1;
/// Spring of the massless pad (the coating) between the tip and the casing.
pub const PAD_SPRING: f64 = 30.0;
/// Rayleigh damping ratio at the first and third natural frequencies.
pub const DAMPING_RATIO: f64 = 0.02;
/// The pad's dof (0-based).
pub const PAD: usize = 5 * ELEMENTS;
/// The tip's axial and two bending displacements (0-based).
pub const TIP: [usize; 3] = [PAD - 5, PAD - 4, PAD - 2];
/// Rotor speeds (as `omega / omega_1`, `omega` the lobes' frequency) of the comparison.
pub const COMPARED_RATIOS: [f64; 2] = [0.8, 1.1];

/// The blade's matrices: stiffness (with the pad's spring), mass (none on the pad) and
/// Rayleigh damping of the blade alone.
pub struct BladeMatrices {
    pub stiffness: SparseMatrix,
    pub mass: SparseMatrix,
    pub damping: SparseMatrix,
}

/// The tip's circumferential and axial displacement as coefficients on its bending dofs
/// `(a, b)`: `y = cos(s) a - sin(s) b`, `z = sin(s) a + cos(s) b` (`s` the stagger).
pub fn tip_plane() -> [[f64; 2]; 2] {
    let (s, c) = STAGGER.sin_cos();
    [[c, -s], [s, c]]
}

/// The casing's normal at the tip on `(u, a, b)`: `cos(lean) u + sin(lean) y`.
pub fn normal_on_tip() -> [f64; 3] {
    let (s, c) = LEAN.sin_cos();
    let y = tip_plane()[0];
    [c, s * y[0], s * y[1]]
}

/// The first tangent (circumferential, in the casing's tangent plane) on `(u, a, b)`:
/// `-sin(lean) u + cos(lean) y`; the second is the axial `z`.
pub fn tangents_on_tip() -> [[f64; 3]; 2] {
    let (s, c) = LEAN.sin_cos();
    let [y, z] = tip_plane();
    [[-s, c * y[0], c * y[1]], [0.0, z[0], z[1]]]
}

/// Hermite bending element of length `h` (stiffness `ei`, unit `rhoA`) on `(w, theta)`
/// at both ends: stiffness and consistent mass.
fn bending_element(h: f64, ei: f64) -> ([[f64; 4]; 4], [[f64; 4]; 4]) {
    let k = [
        [12.0, 6.0 * h, -12.0, 6.0 * h],
        [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
        [-12.0, -6.0 * h, 12.0, -6.0 * h],
        [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h],
    ]
    .map(|row| row.map(|v| ei / (h * h * h) * v));
    let m = [
        [156.0, 22.0 * h, 54.0, -13.0 * h],
        [22.0 * h, 4.0 * h * h, 13.0 * h, -3.0 * h * h],
        [54.0, 13.0 * h, 156.0, -22.0 * h],
        [-13.0 * h, -3.0 * h * h, -22.0 * h, 4.0 * h * h],
    ]
    .map(|row| row.map(|v| h / 420.0 * v));
    (k, m)
}

/// Adds an element matrix on `dofs` (`None`: the clamped root) into `entries`.
fn scatter<const N: usize>(
    entries: &mut Vec<(usize, usize, f64)>,
    dofs: [Option<usize>; N],
    element: &[[f64; N]; N],
) {
    for (a, i) in dofs.iter().enumerate() {
        for (b, j) in dofs.iter().enumerate() {
            if let (Some(i), Some(j)) = (i, j) {
                entries.push((*i, *j, element[a][b]));
            }
        }
    }
}

impl BladeMatrices {
    /// The blade of the module documentation.
    pub fn build() -> Self {
        let n = PAD + 1;
        let h = 1.0 / ELEMENTS as f64;
        let (mut k, mut m) = (Vec::new(), Vec::new());
        // Node i >= 1 holds 5 (i - 1) + [u, a, theta_a, b, theta_b]; node 0 is clamped.
        let node = |i: usize, offset: usize| (i > 0).then(|| 5 * (i - 1) + offset);
        let bar_k = [[1.0, -1.0], [-1.0, 1.0]].map(|r| r.map(|v| AXIAL / h * v));
        let bar_m = [[2.0, 1.0], [1.0, 2.0]].map(|r| r.map(|v| h / 6.0 * v));
        for e in 0..ELEMENTS {
            scatter(&mut k, [node(e, 0), node(e + 1, 0)], &bar_k);
            scatter(&mut m, [node(e, 0), node(e + 1, 0)], &bar_m);
            for (plane, ei) in [(1, BENDING[0]), (3, BENDING[1])] {
                let at = |end: usize, d: usize| node(e + end, plane + d);
                let dofs = [at(0, 0), at(0, 1), at(1, 0), at(1, 1)];
                let (ke, me) = bending_element(h, ei);
                scatter(&mut k, dofs, &ke);
                scatter(&mut m, dofs, &me);
            }
        }
        let damping_entries = Self::rayleigh(n, &k, &m);
        // The pad's spring on `p - n . u_tip`.
        let c = normal_on_tip();
        let spring = [1.0, -c[0], -c[1], -c[2]];
        let dofs = [PAD, TIP[0], TIP[1], TIP[2]];
        for a in 0..4 {
            for b in 0..4 {
                k.push((dofs[a], dofs[b], PAD_SPRING * spring[a] * spring[b]));
            }
        }
        let matrix = |e: &[(usize, usize, f64)]| sparse_matrix(n, e).expect("within the dofs");
        Self {
            stiffness: matrix(&k),
            mass: matrix(&m),
            damping: matrix(&damping_entries),
        }
    }

    /// `alpha M + beta K` of the blade (entries `k`, `m` without the pad) with the damping
    /// ratio [`DAMPING_RATIO`] at its first and third natural frequencies.
    fn rayleigh(
        n: usize,
        k: &[(usize, usize, f64)],
        m: &[(usize, usize, f64)],
    ) -> Vec<(usize, usize, f64)> {
        // The pad's row of the blade alone is empty: a unit mass and spring on it keep the
        // pencil regular and give the frequency 1, below the blade's first.
        let mut kp = k.to_vec();
        let mut mp = m.to_vec();
        kp.push((PAD, PAD, 1.0));
        mp.push((PAD, PAD, 1.0));
        let blade = semismooth_contact::model::StructuralModel::new(
            sparse_matrix(n, &mp).expect("within the dofs"),
            sparse_matrix(n, &kp).expect("within the dofs"),
            vec![0.0; n],
        );
        let w = semismooth_contact::rod::natural_frequencies(&blade, 4).expect("frequencies");
        let (w1, w3) = (w[1], w[3]);
        let beta = 2.0 * DAMPING_RATIO / (w1 + w3);
        let alpha = beta * w1 * w3;
        (m.iter().map(|&(i, j, v)| (i, j, alpha * v)))
            .chain(k.iter().map(|&(i, j, v)| (i, j, beta * v)))
            .collect()
    }
}

/// The shipped scene's structure.
pub fn scene_structure() -> (Scene, Structure) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/blade_casing.toml");
    let scene = Scene::from_path(&path).expect("the shipped scene reads");
    let structure = build_imported(scene.model.as_ref().expect("a [model] scene")).unwrap();
    (scene, structure)
}

/// The measures of the tip's `(a, b)` samples over one period (the first-harmonic
/// amplitudes of its circumferential and axial displacements) and the contact's report.
fn measures_from_samples(a: &[f64], b: &[f64], report: FrictionalContactReport) -> Measures {
    let plane = tip_plane();
    let amplitude = plane.map(|row| {
        let series: Vec<f64> = a
            .iter()
            .zip(b)
            .map(|(a, b)| row[0] * a + row[1] * b)
            .collect();
        first_harmonic(&series)
    });
    let mean_normal_force =
        report.normal_force.iter().sum::<f64>() / report.normal_force.len() as f64;
    Measures {
        amplitude,
        mean_normal_force: Some(mean_normal_force),
        report,
    }
}

/// SSN-HB with `harmonics` at `omega` from zero (asserted converged), measured on 4096
/// points; also its solution.
pub fn harmonic_balance(
    structure: &Structure,
    omega: f64,
    harmonics: usize,
) -> (Measures, Vec<f64>) {
    let (hb, x) = solved_from_zero(&structure.model, omega, harmonics);
    let points = 4096;
    let [a, b] = [TIP[1], TIP[2]].map(|dof| hb.displacement_samples(&x, dof, points).unwrap());
    let report = hb.frictional_contact_report(&x, 0, points).unwrap();
    (measures_from_samples(&a, &b, report), x)
}

/// The Moreau–Jean march with `steps` per period from `start` to a period-to-period
/// change of 1e-10: its measures and its steady period.
pub fn march(
    structure: &Structure,
    omega: f64,
    steps: usize,
    start: &MarchState,
) -> (Measures, SteadyPeriod) {
    let options = MarchOptions {
        steps_per_period: steps,
        tolerance: 1e-10,
        ..MarchOptions::default()
    };
    let model = &structure.model;
    let period = march_from_state(model, omega, &options, &[TIP[1], TIP[2]], start).unwrap();
    let report = march_report(&period, omega);
    let d = &period.displacements;
    (
        measures_from_samples(&one_period(&d[0]), &one_period(&d[1]), report),
        period,
    )
}

/// At `ratio` times `omega_1`: the march's extrapolation from 2000 and 4000 steps per
/// period (the coarse from rest, the fine from the coarse one's final state), the two
/// marches, and SSN-HB at each of `harmonics`.
#[allow(clippy::type_complexity)]
pub fn compare_to_march(
    ratio: f64,
    harmonics: &[usize],
) -> (Measures, Measures, Measures, Vec<(usize, Measures)>) {
    let (_, structure) = scene_structure();
    let omega = ratio * structure.omega_1;
    let rest = MarchState::rest(&structure.model);
    let (coarse, period) = march(&structure, omega, 2000, &rest);
    let (fine, _) = march(&structure, omega, 4000, &period.final_state);
    let reference = extrapolated(&coarse, &fine);
    let rows = harmonics
        .iter()
        .map(|&h| (h, harmonic_balance(&structure, omega, h).0))
        .collect();
    (reference, coarse, fine, rows)
}
