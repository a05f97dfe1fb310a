//! Nonlinear modes (EPMC) of a cyclic sector: under engine order 0 harmonic 1 lives on
//! nodal diameter 0 (a non-degenerate family of the tuned disk), whose backbone the sector
//! follows from its nodal-diameter linear mode; the full tuned disk's EPMC of its
//! nodal-diameter-0 mode is the reference. Engine orders that put harmonic 1 on a
//! travelling wave are refused with the reason.

use semismooth::{ParameterDependent, Residual};
use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::hb::HbOptions;
use semismooth_contact::model::Structure;
use semismooth_contact::modes::{
    backbone, AmplitudeMeasure, Backbone, BackboneOptions, Epmc, ModesError,
};
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::structures::{BladedDisk, DiskLoading};

#[path = "common/sector.rs"]
mod sector;
use sector::{tuned_disk, BLADES};

const HARMONICS: usize = 5;
/// Blade 0's tip amplitudes of the backbones: open casing at the start, the pad pressed
/// into it at the end.
const AMPLITUDES: (f64, f64) = (0.05, 3.0);

fn hb() -> HbOptions {
    HbOptions {
        harmonics: HARMONICS,
        // A multiple of N (any would do under engine order 0: no delay between sectors).
        time_samples: Some(64),
        c: Some(5.0),
    }
}

/// The casing on every blade's pad (gap 1), the disk's 1 % damping.
fn sector_of(engine_order: usize) -> (CyclicSector, Structure) {
    let loading = DiskLoading::shipped((0..BLADES).collect());
    let (sector, _) = tuned_disk().cyclic_sector(&loading, engine_order).unwrap();
    let structure = sector.structure(1).unwrap();
    (sector, structure)
}

fn backbone_of(structure: &Structure, mode: usize, tip: usize) -> Backbone {
    let mut options =
        BackboneOptions::new(mode, AmplitudeMeasure::Dof(tip), AMPLITUDES.0, AMPLITUDES.1);
    options.hb = hb();
    backbone(&structure.model, &options).unwrap()
}

#[test]
fn a_sectors_backbone_under_engine_order_0_is_the_full_disks_nodal_diameter_0_backbone() {
    let (sector, structure) = sector_of(0);
    let sector_branch = backbone_of(&structure, 1, structure.observed_dof);
    let nd0 = natural_frequencies(&sector.nodal_diameter_model(0), 1).unwrap()[0];
    let first = &sector_branch.points[0];
    eprintln!(
        "sector: {} points, first omega {} against nodal diameter 0's {nd0}",
        sector_branch.points.len(),
        first.omega
    );
    // The casing is open at the first amplitude: the linear mode of harmonic 1's real
    // model, against the nodal-diameter model's eigenvalue (another dense eigensolve of
    // another matrix, twice the size): equal to round-off (measured 1.1e-15).
    assert!(
        (first.omega - nd0).abs() < 1e-12 * nd0,
        "{} {nd0}",
        first.omega
    );

    let disk = tuned_disk();
    let full = disk
        .structure(&DiskLoading::shipped((0..BLADES).collect()))
        .unwrap();
    // The disk and tip dofs carry mass, the pads none: 2 N finite frequencies.
    let frequencies = natural_frequencies(&full.model, 2 * BLADES).unwrap();
    let mode = 1
        + (frequencies.iter())
            .position(|w| (w - nd0).abs() < 1e-9 * nd0)
            .expect("nodal diameter 0's frequency among the disk's");
    // The frequencies of the other nodal diameters lie apart (non-degenerate family).
    assert!(
        (frequencies.iter())
            .filter(|w| (*w - nd0).abs() < 1e-6 * nd0)
            .count()
            == 1
    );
    let tip = BladedDisk::tip(0);
    let full_branch = backbone_of(&full, mode, tip);

    // Every point of the sector's backbone, recovered on every blade, solves the full
    // disk's EPMC equations (its residual against the corrector's tolerance), and the
    // disk's energy is N times the sector's.
    let mut epmc = Epmc::new(&full.model, &hb(), mode, AmplitudeMeasure::Dof(tip)).unwrap();
    let mut worst: f64 = 0.0;
    for point in &sector_branch.points {
        let len = point.unknowns.len() - 2;
        let mut x = disk.recover_state(&sector, &point.unknowns[..len], HARMONICS);
        x.extend_from_slice(&point.unknowns[len..]);
        epmc.set_parameter(point.amplitude);
        let mut residual = vec![0.0; x.len()];
        epmc.residual(&x, &mut residual).unwrap();
        let size = residual.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        worst = worst.max(size / epmc.force_scale(point.amplitude));
        let energy = epmc.energy(&x);
        let expected = BLADES as f64 * point.energy;
        assert!(
            (energy - expected).abs() < 1e-12 * expected,
            "{energy} {expected}"
        );
    }
    eprintln!("largest full-disk residual over the sector's points, relative: {worst:e}");
    // The sector's corrector stops at 1e-12 of the force scale (the default relative
    // tolerance); the full disk's residual of the recovered point is that residual copied
    // on every sector, plus rounding (measured 4.4e-14).
    assert!(worst < 1e-11, "{worst:e}");

    // The full disk's own backbone reaches the same amplitude at the same frequency and
    // damping: both corrected to 1e-12 of the force scale on the same equations (measured
    // equal to the last digit in frequency, 1e-16 apart in damping ratio).
    let (a, b) = (
        sector_branch.points.last().unwrap(),
        full_branch.points.last().unwrap(),
    );
    assert_eq!(a.amplitude, b.amplitude);
    eprintln!(
        "at amplitude {}: omega {} (sector) {} (full), zeta {} {}; full {} points",
        a.amplitude,
        a.omega,
        b.omega,
        a.damping_ratio,
        b.damping_ratio,
        full_branch.points.len()
    );
    assert!(
        (a.omega - b.omega).abs() < 1e-12 * b.omega,
        "{} {}",
        a.omega,
        b.omega
    );
    assert!((a.damping_ratio - b.damping_ratio).abs() < 1e-12, "{a:?}");
    // The casing closed: the mode stiffened.
    assert!(a.omega > 1.01 * nd0, "{} {nd0}", a.omega);
}

#[test]
fn a_sector_whose_harmonic_1_is_a_travelling_wave_is_refused_naming_its_nodal_diameter() {
    let (_, structure) = sector_of(3);
    let refused = Epmc::new(&structure.model, &hb(), 1, AmplitudeMeasure::Dof(1));
    let Err(error) = refused else {
        panic!("a travelling-wave sector was accepted");
    };
    assert_eq!(
        error,
        ModesError::TravellingWaveSector {
            nodal_diameter: 3,
            sectors: BLADES
        }
    );
    assert!(error.to_string().contains("travelling wave"), "{error}");
    // Engine order N/2 = 4: harmonic 1 on nodal diameter 4, a standing wave: accepted.
    let (_, structure) = sector_of(BLADES / 2);
    Epmc::new(
        &structure.model,
        &hb(),
        1,
        AmplitudeMeasure::Dof(structure.observed_dof),
    )
    .unwrap();
}
