//! `[cyclic]` on a `[model]` sector and `[forcing] engine_order` on a `[bladed_disk]`: the
//! sector scene and the full disk scene under the same engine order answer the same
//! harmonic balance, and the sector's `blade_amplitudes` are the full disk's blade tips;
//! a sector scene with a friction damper between sectors (`neighbour_dofs`) answers the
//! full disk built in code with the damper between every pair of neighbours.

use std::path::Path;

use semismooth_contact::matrix_market::model_matrix_files;
use semismooth_contact::solve::Solution;
use semismooth_contact::structures::{BladedDisk, DiskLoading};
use ssn::cli::{load, Loaded};

mod common;
#[path = "../../contact/tests/common/sector.rs"]
mod sector;

use sector::{converged, engine_order_disk, nodal_diameter_resonance};

const BLADES: usize = 8;
const HARMONICS: usize = 5;

/// The sections both scenes share: Rayleigh damping `beta K`, the forcing frequency, the
/// solver (64 samples: a multiple of N, so the sector delay is a whole number of samples;
/// one complementarity constant, on which the AFT-projected equations depend).
fn common(beta: f64, omega: f64) -> String {
    format!(
        "[damping]\nalpha = 0.0\nbeta = {beta:e}\n\n[solver]\nharmonics = {HARMONICS}\n\
         time_samples = 64\nc = 5.0\ntolerance = 1e-13\n\n[forcing]\namplitude = 0.06\n\
         omega = {omega:e}\n"
    )
}

/// The scene at `path` loaded and its solve, asserted converged.
fn solved(path: &Path) -> (Loaded, Solution) {
    let loaded = load(path).unwrap_or_else(|e| panic!("{e}"));
    let s = converged(&loaded.structure, loaded.omega, &loaded.scene.solver);
    (loaded, s)
}

#[test]
fn a_sector_scene_answers_the_full_disk_scene_under_the_same_engine_order() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let disk = BladedDisk {
        blades: BLADES,
        mistuning: 0.0,
    };
    let loading = DiskLoading::shipped((0..BLADES).collect());
    let (sector, omega_1) = disk.cyclic_sector(&loading, 3).unwrap();
    let beta = 2.0 * loading.zeta / omega_1;
    let omega = 0.9;
    let m = sector.model();
    for (name, text) in model_matrix_files(&m.stiffness, &m.mass, &[0.0, 1.0, 0.0, 0.0]) {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let sector_scene = dir.join("sector.toml");
    std::fs::write(
        &sector_scene,
        format!(
            "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n\n[cyclic]\nsectors = {BLADES}\n\
             engine_order = 3\nleft = [1]\nright = [4]\n\n[[contact.point]]\ndof = 3\ngap = 1.0\n\n\
             [output]\ndof = 2\n\n{}vector = \"f.mtx\"\n",
            common(beta, omega)
        ),
    )
    .unwrap();
    let full_scene = dir.join("full.toml");
    std::fs::write(
        &full_scene,
        format!(
            "[bladed_disk]\nblades = {BLADES}\n\n[contact]\ngap = 1.0\n\n{}engine_order = 3\n",
            common(beta, omega)
        ),
    )
    .unwrap();
    let (sector_loaded, sector_solution) = solved(&sector_scene);
    let (full_loaded, full_solution) = solved(&full_scene);
    assert!(full_solution
        .contacts
        .iter()
        .any(|c| c.contact_fraction > 0.0));
    let n = 3 * BLADES;
    let u_full = &full_solution.state[..n * (2 * HARMONICS + 1)];
    let scale = u_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let reduced = &sector_solution.state[..3 * (2 * HARMONICS + 1)];
    for s in 0..BLADES {
        let u_s = sector.sector_coefficients(reduced, HARMONICS, s);
        for j in 0..2 * HARMONICS + 1 {
            for dof in 0..3 {
                let gap = (u_s[j * 4 + dof] - u_full[j * n + 3 * s + dof]).abs();
                // Same equations, both converged below 1e-13 on damped, well-conditioned
                // Jacobians (the library's test finds 1e-13): 1e-10 leaves a wide margin.
                assert!(
                    gap < 1e-10 * scale,
                    "sector {s} harmonic row {j} dof {dof}: {gap:e}"
                );
            }
        }
    }
    // Every blade's tip amplitude: the full disk's blade 0 tip is its observed dof.
    let amplitudes =
        ssn::json::blade_amplitudes(&sector_loaded.structure, &sector_solution).unwrap();
    let amplitudes = amplitudes.as_array().unwrap();
    assert_eq!(amplitudes.len(), BLADES);
    assert_eq!(full_loaded.structure.observed_dof, 1);
    let tip_0 = (0..64)
        .map(|i| {
            let t = 2.0 * std::f64::consts::PI * i as f64 / 64.0;
            (1..=HARMONICS).fold(u_full[1], |u, k| {
                let (a, b) = (u_full[(2 * k - 1) * n + 1], u_full[2 * k * n + 1]);
                u + a * (k as f64 * t).cos() + b * (k as f64 * t).sin()
            })
        })
        .fold(0.0f64, |m, u| m.max(u.abs()));
    for a in amplitudes {
        // The same 64 samples of the same coefficients, reordered by whole-sample delays.
        assert!(
            (a.as_f64().unwrap() - tip_0).abs() < 1e-10 * tip_0,
            "{a} vs {tip_0}"
        );
    }
    assert!(ssn::json::blade_amplitudes(&full_loaded.structure, &full_solution).is_none());
}

#[test]
fn cyclic_and_engine_order_keys_are_refused_where_they_do_not_belong() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let disk = BladedDisk {
        blades: BLADES,
        mistuning: 0.0,
    };
    let (sector, _) = disk
        .cyclic_sector(&DiskLoading::shipped(Vec::new()), 1)
        .unwrap();
    let m = sector.model();
    for (name, text) in model_matrix_files(&m.stiffness, &m.mass, &[0.0, 1.0, 0.0, 0.0]) {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let cases = [
        (
            "[rod]\nelements = 4\n[forcing]\namplitude = 0.1\nengine_order = 2\n",
            "forcing.engine_order",
        ),
        (
            "[bladed_disk]\nblades = 4\n[forcing]\namplitude = 0.1\nsector_dofs = [[1]]\n",
            "forcing.sector_dofs",
        ),
        (
            "[bladed_disk]\nblades = 4\n[cyclic]\nsectors = 4\nengine_order = 1\nleft = [1]\n\
             right = [4]\n[forcing]\namplitude = 0.1\n",
            "cyclic",
        ),
        (
            "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[forcing]\namplitude = 0.1\n\
             vector = \"f.mtx\"\n[[contact.point]]\ndof = 3\ngap = 1.0\nneighbour_dofs = [2]\n\
             neighbour_coefficients = [-1.0]\n",
            "contact.point.neighbour_dofs",
        ),
        (
            "[bladed_disk]\nblades = 4\n[forcing]\namplitude = 0.1\n[[contact.point]]\ndof = 3\n\
             gap = 1.0\nneighbour_dofs = [2]\n",
            "contact.point.neighbour_coefficients",
        ),
    ];
    for (i, (text, key)) in cases.iter().enumerate() {
        let path = dir.join(format!("case{i}.toml"));
        std::fs::write(&path, text).unwrap();
        let message = match load(&path) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("case {i} loaded"),
        };
        assert!(message.contains(key), "case {i}: {message}");
    }
}

#[test]
fn the_shipped_blisk_sector_with_friction_dampers_between_blades_answers_the_full_disk() {
    use semismooth_contact::structures::BladeDamper;
    let (blades, engine_order, gap, mu) = (24, 3, 0.2, 0.3);
    let scene = common::scenes_dir().join("blisk_dampers_sector.toml");
    let (loaded, sector_solution) = solved(&scene);
    let disk = BladedDisk {
        blades,
        mistuning: 0.0,
    };
    let loading = DiskLoading::shipped(Vec::new());
    let (sector, omega_1) = disk.cyclic_sector(&loading, engine_order).unwrap();
    assert!((loaded.structure.omega_1 - omega_1).abs() < 1e-12);
    // The full disk with the damper between every pair of neighbours, written blade by
    // blade on the disk's dofs.
    let mut full = engine_order_disk(&disk, &loading, engine_order);
    BladeDamper { gap, friction: mu }.add_to_disk(&disk, &mut full.model);
    let full_solution = converged(&full, loaded.omega, &loaded.scene.solver);
    assert!(full_solution
        .contacts
        .iter()
        .all(|c| c.contact_fraction > 0.0));
    let u_full = &full_solution.state[..3 * blades * (2 * HARMONICS + 1)];
    let scale = u_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let recovered = disk.recover(&sector, &sector_solution.state, HARMONICS);
    let worst = (recovered.iter().zip(u_full)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // The same discrete equations (64 samples, a multiple of N / gcd(N, EO) = 8; beta
    // written to 16 digits), both converged below 1e-13 (the library's test finds 2e-13):
    // 1e-10 leaves a wide margin.
    assert!(worst < 1e-10 * scale, "{:e}", worst / scale);
}

#[test]
fn the_shipped_sector_scene_is_the_full_100_blade_disk_under_engine_order_3() {
    let path = common::scenes_dir().join("bladed_disk_sector.toml");
    let (loaded, sector_solution) = solved(&path);
    let blades = 100;
    let disk = BladedDisk {
        blades,
        mistuning: 0.0,
    };
    let loading = DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped((0..blades).collect())
    };
    let (sector, omega_1) = disk.cyclic_sector(&loading, 3).unwrap();
    // The scene's written frequency and damping are the disk's to the digits written.
    assert!((loaded.structure.omega_1 - omega_1).abs() < 1e-12);
    let full = engine_order_disk(&disk, &loading, 3);
    let full_solution = converged(&full, loaded.omega, &loaded.scene.solver);
    assert!(full_solution
        .contacts
        .iter()
        .all(|c| c.contact_fraction > 0.0));
    let len = 3 * blades * (2 * HARMONICS + 1);
    let u_full = &full_solution.state[..len];
    let recovered = disk.recover(&sector, &sector_solution.state, HARMONICS);
    let scale = u_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = (recovered.iter().zip(u_full)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // The beta written to 16 digits is the disk's 2 zeta / omega_1 to a rounding; the same
    // equations otherwise (100 samples, a multiple of N / gcd(N, EO)): 1e-10.
    assert!(worst < 1e-10 * scale, "{:e}", worst / scale);
    let amplitudes = ssn::json::blade_amplitudes(&loaded.structure, &sector_solution).unwrap();
    assert_eq!(amplitudes.as_array().unwrap().len(), blades);
}

#[test]
fn interface_nodes_through_a_dof_map_give_the_interface_dofs() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let shipped = common::scenes_dir().join("blade_sector");
    for name in ["K.mtx", "M.mtx", "f.mtx"] {
        std::fs::copy(shipped.join(name), dir.join(name)).unwrap();
    }
    // Rows in a shuffled order: node 4 (the next sector's disk dof) is row 1, node 1 row 4.
    std::fs::write(dir.join("nodes.dof"), "4.1\n2.1\n3.1\n1.1\n").unwrap();
    let scene = |interface: &str, map: &str| {
        format!(
            "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n{map}\n[cyclic]\nsectors = 8\n\
             engine_order = 1\n{interface}\n[forcing]\nvector = \"f.mtx\"\namplitude = 0.1\n"
        )
    };
    let read = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        ssn::scene::Scene::from_path(&path)
    };
    let map = "dof_map = \"nodes.dof\"";
    let by_nodes = read(
        "nodes.toml",
        scene("left_nodes = [4]\nright_nodes = [1]", map),
    );
    let cyclic = by_nodes.unwrap().cyclic.unwrap();
    assert_eq!((cyclic.left, cyclic.right), (vec![0], vec![3]));
    let refused = [
        (scene("left_nodes = [4]\nright_nodes = [1]", ""), "dof_map"),
        (
            scene("left_nodes = [4]\nright_nodes = [9]", map),
            "cyclic.right_nodes",
        ),
        (scene("left = [1]\nright_nodes = [1]", map), "cyclic.left"),
    ];
    for (i, (text, key)) in refused.into_iter().enumerate() {
        let message = read(&format!("bad{i}.toml"), text).unwrap_err().to_string();
        assert!(message.contains(key), "case {i}: {message}");
    }
}

#[test]
fn a_sector_scene_with_a_3d_frictional_contact_between_sectors_answers_the_full_disk() {
    use semismooth_contact::model::{ContactRow, FrictionalContact};
    let (engine_order, gap, mu) = (3, 0.2, 0.3);
    let disk = BladedDisk {
        blades: BLADES,
        mistuning: 0.0,
    };
    // The amplitude of `common`.
    let loading = DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped(Vec::new())
    };
    let (sector, omega_1) = disk.cyclic_sector(&loading, engine_order).unwrap();
    let omega = nodal_diameter_resonance(&sector);
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let m = sector.model();
    for (name, text) in model_matrix_files(&m.stiffness, &m.mass, &[0.0, 1.0, 0.0, 0.0]) {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let scene = dir.join("sector.toml");
    // The pad against the next blade's tip and disk dof; tangents b - d' and d - b'.
    std::fs::write(
        &scene,
        format!(
            "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n\n[cyclic]\nsectors = {BLADES}\n\
             engine_order = {engine_order}\nleft = [1]\nright = [4]\n\n{common}\
             vector = \"f.mtx\"\n\n[output]\ndof = 2\n\n[[contact.point]]\ndofs = [3]\n\
             coefficients = [1.0]\nneighbour_dofs = [2, 1]\n\
             neighbour_coefficients = [-0.5, -0.5]\ngap = {gap}\nfriction = {mu}\n\
             tangent_dofs = [2]\ntangent_coefficients = [1.0]\ntangent_neighbour_dofs = [1]\n\
             tangent_neighbour_coefficients = [-1.0]\ntangent2_dofs = [1]\n\
             tangent2_coefficients = [1.0]\ntangent2_neighbour_dofs = [2]\n\
             tangent2_neighbour_coefficients = [-1.0]\n",
            common = common(2.0 * loading.zeta / omega_1, omega),
        ),
    )
    .unwrap();
    let text = std::fs::read_to_string(&scene).unwrap();
    // A second tangent's neighbour part without a second tangent, and neighbour parts on
    // a contact with a tangential spring, are refused with their keys.
    let bad = [
        (
            text.replace("tangent2_dofs = [1]\ntangent2_coefficients = [1.0]\n", ""),
            "contact.point.tangent2_neighbour_dofs",
        ),
        (
            text.replace(
                "friction = 0.3",
                "friction = 0.3\ntangential_stiffness = 1.0",
            ),
            "contact.point.tangential_stiffness",
        ),
    ];
    for (i, (bad, key)) in bad.iter().enumerate() {
        let path = dir.join(format!("bad{i}.toml"));
        std::fs::write(&path, bad).unwrap();
        let message = load(&path).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(message.contains(key), "{message}");
    }
    let (loaded, sector_solution) = solved(&scene);
    let mut full = engine_order_disk(&disk, &loading, engine_order);
    let row = |dofs: Vec<usize>, a: Vec<f64>| ContactRow::new(dofs, a).unwrap();
    for j in 0..BLADES {
        let (own, next) = (3 * j, 3 * ((j + 1) % BLADES));
        let normal = row(vec![own + 2, next + 1, next], vec![1.0, -0.5, -0.5]);
        let t1 = row(vec![own + 1, next], vec![1.0, -1.0]);
        let t2 = row(vec![own, next + 1], vec![1.0, -1.0]);
        (full.model.frictional_contacts).push(FrictionalContact::unilateral(
            normal,
            gap,
            [t1, t2],
            mu,
        ));
    }
    let full_solution = converged(&full, loaded.omega, &loaded.scene.solver);
    assert!((full_solution.frictional_contacts.iter()).all(|c| c.separated_fraction < 1.0));
    let u_full = &full_solution.state[..3 * BLADES * (2 * HARMONICS + 1)];
    let scale = u_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let recovered = disk.recover(&sector, &sector_solution.state, HARMONICS);
    let worst = (recovered.iter().zip(u_full)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // The same discrete equations (64 samples, a multiple of N), both converged below
    // 1e-13 (the library's test measures 1e-14): 1e-10 leaves a wide margin.
    assert!(worst < 1e-10 * scale, "{:e}", worst / scale);
}
