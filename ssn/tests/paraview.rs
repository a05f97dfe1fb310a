//! `ssn solve --vtu DIR` on the CalculiX cantilever (`fixtures/calculix_cantilever`: 81
//! nodes, 32 C3D8 elements, tip contact at node 45's y): the written `.vtu` files parse back
//! (read by the `vtkio` crate), hold the mesh, and their displacement at a node and instant
//! is the solution's there, for the full and the Craig–Bampton-reduced model.

#[path = "common/process.rs"]
mod process;

use std::path::{Path, PathBuf};

use process::{assert_success, ssn};
use vtkio::model::{Attribute, CellType, DataSet, IOBuffer, Piece, Vtk};

const FRAMES: usize = 8;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/calculix_cantilever")
        .join(name)
}

/// A scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssn-paraview-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The fixture scene `name` in `dir`, its files named by absolute path and with the mesh.
fn scene_with_mesh(dir: &Path, name: &str) -> PathBuf {
    let text = std::fs::read_to_string(fixture(name)).unwrap();
    let base = fixture("");
    let text = text.replace(
        "\"cantilever.",
        &format!("\"{}/cantilever.", base.display()),
    );
    let text = text.replace(
        "[model]\n",
        &format!(
            "[model]\nmesh = \"{}\"\n",
            fixture("cantilever.inp").display()
        ),
    );
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Solves `scene` writing the VTU files into `dir/vtu` and the CSV; returns the CSV rows
/// `(t, u_tip)`.
fn solve_with_pictures(dir: &Path, scene: &Path) -> Vec<(f64, f64)> {
    let (vtu, csv) = (dir.join("vtu"), dir.join("out.csv"));
    let frames = FRAMES.to_string();
    let o = ssn(&[
        "solve",
        scene.to_str().unwrap(),
        "--vtu",
        vtu.to_str().unwrap(),
        "--vtu-frames",
        &frames,
        "--csv",
        csv.to_str().unwrap(),
        "--quiet",
    ]);
    assert_success(&o);
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let mut w = l.split(',').map(|v| v.parse::<f64>().unwrap());
            (w.next().unwrap(), w.next().unwrap())
        })
        .collect()
}

/// A parsed `.vtu`: points, cell types and the `displacement` point vectors.
struct Frame {
    points: Vec<f64>,
    types: Vec<CellType>,
    displacement: Vec<f64>,
}

fn read_frame(path: &Path) -> Frame {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let vtk = Vtk::parse_xml(file).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("not an inline piece")
    };
    let points = match &piece.points {
        IOBuffer::F64(v) => v.clone(),
        other => panic!("points {other:?}"),
    };
    let displacement = match &piece.data.point[0] {
        Attribute::DataArray(a) if a.name == "displacement" => match &a.data {
            IOBuffer::F64(v) => v.clone(),
            other => panic!("displacement {other:?}"),
        },
        other => panic!("point data {other:?}"),
    };
    Frame {
        points,
        types: piece.cells.types.clone(),
        displacement,
    }
}

/// The (sorted) point index of `node`: the deck numbers its 81 nodes 1..=81.
fn point_of(node: usize) -> usize {
    node - 1
}

#[test]
fn the_written_frames_hold_the_mesh_and_the_solutions_tip_displacement_at_their_instants() {
    let dir = scratch("full");
    let scene = scene_with_mesh(&dir, "cantilever.toml");
    let rows = solve_with_pictures(&dir, &scene);
    let period = rows[1].0 * rows.len() as f64;
    let amplitude = rows.iter().fold(0.0f64, |m, r| m.max(r.1.abs()));
    let pvd = std::fs::read_to_string(dir.join("vtu/response.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet ").count(), FRAMES, "{pvd}");
    for k in 0..FRAMES {
        let frame = read_frame(&dir.join(format!("vtu/response_{k:03}.vtu")));
        assert_eq!(frame.points.len(), 3 * 81);
        assert_eq!(frame.types, vec![CellType::Hexahedron; 32]);
        // Node 45 is at the tip centre (80, 5, 5) mm.
        assert_eq!(
            &frame.points[3 * point_of(45)..3 * point_of(45) + 3],
            &[80.0, 5.0, 5.0]
        );
        // The CSV samples the period at Nt points, a multiple of FRAMES: the frame's instant
        // t_k = k T / FRAMES is row k Nt / FRAMES. Both sum the same Fourier coefficients (the
        // CSV by the library's inverse DFT, the frame by cosines and sines): round-off only.
        let (t, u_tip) = rows[k * rows.len() / FRAMES];
        assert!((t - k as f64 * period / FRAMES as f64).abs() < 1e-12 * period);
        let u = frame.displacement[3 * point_of(45) + 1];
        assert!(
            (u - u_tip).abs() < 1e-12 * amplitude,
            "frame {k}: {u} vs {u_tip}"
        );
        // Node 1 is at the clamped end: no rows, no displacement.
        assert_eq!(&frame.displacement[0..3], &[0.0; 3]);
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_reduced_models_frames_recover_the_full_field_at_every_node() {
    let full_dir = scratch("reduced-full");
    solve_with_pictures(&full_dir, &scene_with_mesh(&full_dir, "cantilever.toml"));
    let dir = scratch("reduced");
    let rows = solve_with_pictures(&dir, &scene_with_mesh(&dir, "cantilever_reduced.toml"));
    let amplitude = rows.iter().fold(0.0f64, |m, r| m.max(r.1.abs()));
    let mut worst = 0.0f64;
    for k in 0..FRAMES {
        let name = format!("vtu/response_{k:03}.vtu");
        let (reduced, full) = (
            read_frame(&dir.join(&name)),
            read_frame(&full_dir.join(&name)),
        );
        // The tip's y is a boundary coordinate of the reduction: exactly the reduced
        // solution's observed dof (round-off).
        let u = reduced.displacement[3 * point_of(45) + 1];
        let u_tip = rows[k * rows.len() / FRAMES].1;
        assert!(
            (u - u_tip).abs() < 1e-12 * amplitude,
            "frame {k}: {u} vs {u_tip}"
        );
        for (a, b) in reduced.displacement.iter().zip(&full.displacement) {
            worst = worst.max((a - b).abs());
        }
    }
    // Every node's recovered displacement against the full model's solve: the reduction's
    // error (16 modes: 2.7e-5 of the amplitude at the tip, docs/finite_element_models.md);
    // the interior nodes, which the truncated modes move more, measured 2.2e-4: within 5e-4.
    eprintln!(
        "worst recovered displacement error / tip amplitude: {:.2e}",
        worst / amplitude
    );
    assert!(worst < 5e-4 * amplitude, "{worst:e} of {amplitude:e}");
    std::fs::remove_dir_all(dir).unwrap();
    std::fs::remove_dir_all(full_dir).unwrap();
}

#[test]
fn pictures_without_a_mesh_or_of_a_method_without_coefficients_are_refused_before_the_run() {
    let dir = scratch("refused");
    let vtu = dir.join("vtu");
    let plain = fixture("cantilever.toml");
    let o = ssn(&[
        "solve",
        plain.to_str().unwrap(),
        "--vtu",
        vtu.to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("--vtu: the scene has no mesh"), "{e}");
    let scene = scene_with_mesh(&dir, "cantilever.toml");
    let o = ssn(&[
        "solve",
        scene.to_str().unwrap(),
        "--vtu",
        vtu.to_str().unwrap(),
        "--set",
        "solver.method=lcp-lemke",
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("--vtu: the scene's method lcp-lemke has no harmonic"),
        "{e}"
    );
    assert!(!vtu.exists(), "nothing is written for a refused run");
    std::fs::remove_dir_all(dir).unwrap();
}
