//! Cyclic symmetry of the tuned bladed disk: the engine-order load on the full disk against
//! the closed-form travelling wave, the sector's natural frequencies per nodal diameter
//! against the full disk's, and the sector's harmonic balance with a casing contact
//! against the full disk's under engine orders 0, 3 and 7, on every linear solver.

use nalgebra::{Complex, Matrix2, Vector2};
use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::settings::{LinearSolverChoice, SolverSettings};
use semismooth_contact::solve::{solve, Solution};
use semismooth_contact::structures::{BladedDisk, DiskLoading};

#[path = "common/sector.rs"]
mod sector;
use sector::{converged, engine_order_disk, nodal_diameter_resonance, settings};

const BLADES: usize = 8;

fn tuned_disk() -> BladedDisk {
    BladedDisk::tuned(BLADES)
}

/// The full tuned disk under `loading` with the load of sector `s` delayed by
/// `s EO T / N`.
fn full_disk(loading: &DiskLoading, engine_order: usize) -> semismooth_contact::model::Structure {
    engine_order_disk(&tuned_disk(), loading, engine_order)
}

#[test]
fn an_engine_order_load_on_the_tuned_disk_gives_the_closed_form_travelling_wave_on_its_nodal_diameter(
) {
    let engine_order = 3;
    let loading = DiskLoading {
        stops: Vec::new(),
        ..DiskLoading::shipped(Vec::new())
    };
    let structure = full_disk(&loading, engine_order);
    let omega = 0.9;
    let solution = converged(
        &structure,
        omega,
        &settings(1, LinearSolverChoice::Structured),
    );
    let n = 3 * BLADES;
    let u = &solution.state[..3 * n];
    // Closed form: on nodal diameter EO the ring spring adds 2 k_d (1 - cos phi) to the disk
    // dof; the free massless pad follows the tip. With D = beta K, per sector
    // (K_nd (1 + i w beta) - w^2 I) z = (0, amplitude) on (d, b), sector s is z e^{-i s phi}.
    let phi = 2.0 * std::f64::consts::PI * engine_order as f64 / BLADES as f64;
    let beta = 2.0 * loading.zeta / structure.omega_1;
    let ring = 1.0 + 2.0 * (1.0 - phi.cos());
    let k_nd = Matrix2::new(ring + 1.0, -1.0, -1.0, 1.0);
    let z_nd = k_nd.map(|k| Complex::new(k, omega * beta * k))
        - Matrix2::identity() * Complex::from(omega * omega);
    let z = z_nd
        .lu()
        .solve(&Vector2::new(
            Complex::from(0.0),
            Complex::from(loading.amplitude),
        ))
        .unwrap();
    let mut gap = 0.0f64;
    let mut tips = Vec::new();
    for s in 0..BLADES {
        let shift = Complex::from_polar(1.0, -(s as f64) * phi);
        let (disk, tip) = (z[0] * shift, z[1] * shift);
        for (dof, want) in [(3 * s, disk), (3 * s + 1, tip), (3 * s + 2, tip)] {
            let got = Complex::new(u[n + dof], -u[2 * n + dof]);
            gap = gap.max((got - want).norm() / z[1].norm());
        }
        tips.push(Complex::new(u[n + 3 * s + 1], -u[2 * n + 3 * s + 1]));
    }
    // Linear, damped and 10 % from resonance: both sides are LU solves of conditions
    // below 1e2, agreeing to a few hundred roundings.
    assert!(gap < 1e-12, "{gap:e}");
    // The spatial DFT of the tip amplitudes over the sectors holds only e^{-i EO 2pi s/N}.
    for d in 0..BLADES {
        let coefficient: Complex<f64> = (tips.iter().enumerate())
            .map(|(s, t)| {
                t * Complex::from_polar(
                    1.0,
                    2.0 * std::f64::consts::PI * (d * s) as f64 / BLADES as f64,
                )
            })
            .sum::<Complex<f64>>()
            / BLADES as f64;
        let expected = if d == engine_order { z[1].norm() } else { 0.0 };
        assert!(
            (coefficient.norm() - expected).abs() < 1e-12 * z[1].norm(),
            "{d}: {coefficient}"
        );
    }
}

#[test]
fn the_sectors_natural_frequencies_per_nodal_diameter_are_the_full_disks() {
    let disk = tuned_disk();
    let (sector, _) = disk
        .cyclic_sector(&DiskLoading::shipped(Vec::new()), 0)
        .unwrap();
    let full = disk.structure(&DiskLoading::shipped(Vec::new())).unwrap();
    // Two finite frequencies per sector (the pads are massless).
    let full_frequencies = natural_frequencies(&full.model, 2 * BLADES).unwrap();
    let mut from_sector = Vec::new();
    for d in 0..=BLADES / 2 {
        // The real form doubles every frequency; diameters 1..N/2-1 appear twice in the disk.
        let pair = natural_frequencies(&sector.nodal_diameter_model(d), 4).unwrap();
        let copies = if d == 0 || 2 * d == BLADES { 1 } else { 2 };
        for f in [pair[0], pair[2]] {
            from_sector.extend(std::iter::repeat_n(f, copies));
        }
        assert!((pair[0] - pair[1]).abs() < 1e-12 && (pair[2] - pair[3]).abs() < 1e-12);
    }
    from_sector.sort_by(f64::total_cmp);
    assert_eq!(from_sector.len(), full_frequencies.len());
    // Both are dense symmetric eigensolves of conditions near 10: a few roundings apart.
    for (a, b) in from_sector.iter().zip(&full_frequencies) {
        assert!((a - b).abs() < 1e-10 * b, "{a} vs {b}");
    }
    assert!((sector.lowest_frequency().unwrap() - full.omega_1).abs() < 1e-12);
}

#[test]
fn the_sector_with_a_casing_contact_solves_the_full_disk_under_engine_orders_0_3_and_7() {
    let harmonics = 5;
    let disk = tuned_disk();
    // Three times the shipped load: every engine order's resonance closes the casing.
    let loading = DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped((0..BLADES).collect())
    };
    for engine_order in [0, 3, 7] {
        let full = full_disk(&loading, engine_order);
        let (sector, omega_1) = disk.cyclic_sector(&loading, engine_order).unwrap();
        assert!((omega_1 - full.omega_1).abs() < 1e-12 * omega_1);
        let sector_structure = sector.structure(1).unwrap();
        // Forced at the resonance of the engine order's nodal diameter: the casing closes.
        let omega = nodal_diameter_resonance(&sector);
        let reference = converged(
            &full,
            omega,
            &settings(harmonics, LinearSolverChoice::Structured),
        );
        let n = 3 * BLADES;
        let len = n * (2 * harmonics + 1);
        let u_full = &reference.state[..len];
        let scale = u_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let closed = reference.contacts.iter().any(|c| c.contact_fraction > 0.0);
        assert!(closed, "EO {engine_order}: the casing stays open");
        for choice in [
            LinearSolverChoice::Structured,
            LinearSolverChoice::Dense,
            LinearSolverChoice::CondensedDense,
        ] {
            let solution = converged(&sector_structure, omega, &settings(harmonics, choice));
            let reduced = &solution.state[..3 * (2 * harmonics + 1)];
            let mut gap = 0.0f64;
            for s in 0..BLADES {
                let u_s = sector.sector_coefficients(reduced, harmonics, s);
                for j in 0..2 * harmonics + 1 {
                    for dof in 0..4 {
                        let full_dof = (3 * s + dof) % n;
                        gap = gap.max((u_s[j * 4 + dof] - u_full[j * n + full_dof]).abs());
                    }
                }
            }
            if choice == LinearSolverChoice::Structured {
                check_blade_amplitudes(&sector_structure, &solution, u_full, harmonics);
            }
            // Both converge to residuals below 1e-13 on well-conditioned (damped, condition
            // below 1e3) Jacobians with the same active set: 1e-10 leaves a wide margin.
            eprintln!(
                "EO {engine_order} {choice:?}: relative gap {:e}",
                gap / scale
            );
            assert!(gap < 1e-10 * scale, "EO {engine_order} {choice:?}: {gap:e}");
        }
    }
}

#[test]
fn bad_sectors_and_formulations_without_the_couplings_are_refused_with_their_numbers() {
    use semismooth_contact::cyclic::InvalidSector;
    use semismooth_contact::model::{ContactPoint, StructuralModel};
    let disk = tuned_disk();
    let loading = DiskLoading::shipped((0..BLADES).collect());
    let (sector, _) = disk.cyclic_sector(&loading, 3).unwrap();
    let model = sector.model().clone();
    let new = |model: StructuralModel, left: Vec<usize>, right: Vec<usize>| {
        CyclicSector::new(model, left, right, BLADES, 3).err()
    };
    assert_eq!(
        new(model.clone(), vec![0], vec![]),
        Some(InvalidSector::InterfaceLengths { left: 1, right: 0 })
    );
    assert_eq!(
        new(model.clone(), vec![0], vec![0]),
        Some(InvalidSector::InterfaceDof { dof: 0, dofs: 4 })
    );
    let on_right = model.clone().with_contact(ContactPoint::new(3, 1.0));
    assert_eq!(
        new(on_right, vec![0], vec![3]),
        Some(InvalidSector::RowOnRightInterface { row: 1, dof: 3 })
    );
    assert!(CyclicSector::new(model, vec![0], vec![3], 0, 3).is_err());
    assert!(sector.structure(3).is_err());
    // The reduced model carries couplings that only the harmonic operator reads.
    let reduced = sector.reduce();
    assert!(natural_frequencies(&reduced, 1).is_err());
    let lcp = semismooth_contact::lcp::PeriodicLcp::new(&reduced, 1.0, Default::default());
    assert!(lcp.is_err());
    let structure = sector.structure(1).unwrap();
    let march = SolverSettings {
        method: semismooth_contact::settings::Method::March,
        ..SolverSettings::default()
    };
    assert!(solve(&structure, 1.0, &march, None).is_err());
    // A dof in two sectors or out of range is named with the model's size.
    use semismooth_contact::model::{HarmonicLoad, InvalidModel};
    let load = || HarmonicLoad::cosine(vec![1.0; 3]);
    for sectors in [vec![vec![0], vec![0]], vec![vec![1], vec![3]]] {
        let bad = sectors[1][0];
        assert_eq!(
            load().delayed_by_sector(&sectors, 1),
            Err(InvalidModel::SectorDof { dof: bad, dofs: 3 })
        );
    }
}

/// The blade-tip amplitudes the sector recovers for every blade are the full disk's, each
/// evaluated on the same 64 instants from its own coefficients.
fn check_blade_amplitudes(
    sector: &semismooth_contact::model::Structure,
    solution: &Solution,
    u_full: &[f64],
    harmonics: usize,
) {
    let (nr, n) = (3, 3 * BLADES);
    let tip = |u: &[f64], stride: usize, dof: usize| -> Vec<f64> {
        (0..2 * harmonics + 1)
            .map(|j| u[j * stride + dof])
            .collect()
    };
    let coupling = sector.model.cyclic.as_ref().unwrap();
    let amplitudes = coupling.sector_amplitudes(&tip(&solution.state, nr, 1), 64);
    assert_eq!(amplitudes.len(), BLADES);
    for (s, amplitude) in amplitudes.iter().enumerate() {
        let c = tip(u_full, n, 3 * s + 1);
        let full = (0..64)
            .map(|i| {
                let t = 2.0 * std::f64::consts::PI * i as f64 / 64.0;
                (1..=harmonics).fold(c[0], |u, k| {
                    u + c[2 * k - 1] * (k as f64 * t).cos() + c[2 * k] * (k as f64 * t).sin()
                })
            })
            .fold(0.0f64, |m, u| m.max(u.abs()));
        // The sector delays by whole samples (64 EO / 8): the same samples, reordered.
        assert!(
            (amplitude - full).abs() < 1e-10 * full,
            "blade {s}: {amplitude} vs {full}"
        );
    }
}

#[test]
fn a_mistuning_pattern_turned_by_one_blade_keeps_the_first_frequency_and_bad_patterns_are_refused()
{
    let disk = BladedDisk {
        blades: BLADES,
        mistuning: 0.02,
    };
    let loading = DiskLoading::shipped((0..BLADES).collect());
    let builder = disk.structure(&loading).unwrap();
    let mut turned = disk.deterministic_mistuning();
    turned.rotate_left(1);
    let explicit = disk.structure_with_mistuning(&loading, &turned).unwrap();
    // Another stiffness matrix, the same disk turned by one blade: a permutation of the
    // dofs, so the same natural frequencies (to the eigensolver's round-off).
    let dense = |s: &semismooth_contact::model::Structure| s.model.stiffness.to_dense();
    assert_ne!(dense(&builder), dense(&explicit));
    let relative = (builder.omega_1 - explicit.omega_1).abs() / builder.omega_1;
    assert!(relative <= 1e-10, "{relative:e}");
    for bad in [
        vec![0.0; BLADES - 1],
        vec![-1.0; BLADES],
        vec![f64::NAN; BLADES],
    ] {
        assert!(disk.structure_with_mistuning(&loading, &bad).is_err());
    }
}
