//! The readers of finite-element matrix files against each other: `fixtures/fe_formats` holds
//! one beam (`beam.inp`, 4 x 1 x 1 C3D8 elements, 48 free dofs) whose stiffness and mass
//! CalculiX wrote, rounded to 10 significant digits and written again by `generate.py` (from
//! the formats' descriptions, not from these readers) as Abaqus matrix files, a Nastran
//! punch file of DMIG matrices and Ansys-style Harwell-Boeing files with their mapping file.
//! Every reader must give the same `K`, `M` and (node, component) map as the CalculiX reader:
//! bit for bit, since every file carries the same decimal numbers.

use std::path::{Path, PathBuf};

use semismooth_contact::import::{DofMap, Part};
use semismooth_contact::matrix_market::{
    labelled_files_dof_map, read_abaqus_matrix, read_calculix_matrix, read_dmig,
    read_harwell_boeing, select_dmig, MatrixFormat,
};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fe_formats")
        .join(name)
}

/// `K`, `M` (dense) and the map of the CalculiX files.
fn calculix() -> (faer::Mat<f64>, faer::Mat<f64>, DofMap) {
    let map = DofMap::read(&fixture("beam.dof")).unwrap();
    let n = map.len();
    let k = read_calculix_matrix(&fixture("beam.sti"), n).unwrap();
    let m = read_calculix_matrix(&fixture("beam.mas"), n).unwrap();
    (k.to_dense(), m.to_dense(), map)
}

#[test]
fn abaqus_nastran_and_harwell_boeing_files_give_calculix_matrices_and_map() {
    let (k, m, map) = calculix();
    assert_eq!(map.len(), 48);
    assert!(k.norm_max() > 0.0 && m.norm_max() > 0.0);

    let (stif, mass) = (fixture("beam_STIF1.mtx"), fixture("beam_MASS1.mtx"));
    let files = [
        (Part::Stiffness, stif.as_path()),
        (Part::Mass, mass.as_path()),
    ];
    let abaqus_map = labelled_files_dof_map(MatrixFormat::Abaqus, &files).unwrap();
    assert_eq!(abaqus_map, map);
    let kind = MatrixFormat::Abaqus.file_kind();
    let on_rows = |path: &Path| {
        read_abaqus_matrix(path)
            .unwrap()
            .on_rows(&abaqus_map, path, kind)
            .unwrap()
            .to_dense()
    };
    assert_eq!(on_rows(&stif), k);
    assert_eq!(on_rows(&mass), m);

    let punch = fixture("beam.pch");
    let files = [
        (Part::Stiffness, punch.as_path()),
        (Part::Mass, punch.as_path()),
    ];
    let nastran_map = labelled_files_dof_map(MatrixFormat::NastranDmig, &files).unwrap();
    assert_eq!(nastran_map, map);
    let all = read_dmig(&punch).unwrap();
    let names: Vec<&str> = all.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["KAAX", "MAAX"]);
    let kind = MatrixFormat::NastranDmig.file_kind();
    for (part, expected) in [(Part::Stiffness, &k), (Part::Mass, &m)] {
        let matrix = select_dmig(&all, part, &punch).unwrap();
        let dense = matrix
            .on_rows(&nastran_map, &punch, kind)
            .unwrap()
            .to_dense();
        assert_eq!(&dense, expected, "{part}");
    }

    let mapping = DofMap::read_ansys_mapping(&fixture("beam.mapping")).unwrap();
    assert_eq!(mapping, map);
    let hb_k = read_harwell_boeing(&fixture("beam_K.matrix")).unwrap();
    let hb_m = read_harwell_boeing(&fixture("beam_M.matrix")).unwrap();
    assert_eq!(hb_k.to_dense(), k);
    assert_eq!(hb_m.to_dense(), m);
}

#[test]
fn a_defect_of_a_fixture_names_its_file_and_line() {
    let dir = std::env::temp_dir().join(format!("fe-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let edited = |name: &str, line: usize, text: &str| {
        let original = std::fs::read_to_string(fixture(name)).unwrap();
        let mut lines: Vec<&str> = original.lines().collect();
        lines[line - 1] = text;
        let path = dir.join(name);
        std::fs::write(&path, lines.join("\n")).unwrap();
        path
    };
    let abaqus = edited("beam_STIF1.mtx", 5, "2,1, 3,9, 1.0");
    let e = read_abaqus_matrix(&abaqus).unwrap_err().to_string();
    for w in ["beam_STIF1.mtx", "line 5", "component `9`", "1..=6"] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    let punch = edited(
        "beam.pch",
        4,
        "*                      2               1 9.87179487X+05",
    );
    let e = read_dmig(&punch).unwrap_err().to_string();
    for w in [
        "beam.pch",
        "line 4",
        "field 4",
        "9.87179487X+05",
        "real number",
    ] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    let hb = edited(
        "beam_K.matrix",
        3,
        "RSA                       48            47           719             0",
    );
    let e = read_harwell_boeing(&hb).unwrap_err().to_string();
    for w in ["beam_K.matrix", "line 3", "48 x 47", "square"] {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
