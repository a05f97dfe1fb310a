//! The periodic response on the mesh, for ParaView: `ssn solve SCENE --vtu DIR` writes
//! `DIR/response_000.vtu`, ... (the displaced part at `N` instants `t_k = k T / N` of the
//! period `T = 2 pi / omega`) and `DIR/response.pvd`, the collection that animates them.
//!
//! Each `.vtu` is an unstructured grid (XML, written by the `vtkio` crate) of every node of
//! the `[model] mesh` deck, its `*ELEMENT` blocks as cells, and the point vector
//! `displacement`: `u(t_k) = U_0 + sum_j (U_cj cos(j omega t_k) + U_sj sin(j omega t_k))`
//! of the solution's harmonic coefficients, at each node's translational rows of the dof map
//! (components 1, 2, 3; rotations are left out), zero at a node without rows (a clamped
//! one). A reduced model's coefficients are first recovered on the full model (`u = T x`).

use std::collections::HashMap;
use std::path::Path;

use semismooth_contact::import::{DofMap, MeshElements, MeshNodes};
use semismooth_contact::reduction::CraigBampton;
use semismooth_contact::solve::Solution;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, IOBuffer, Piece,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use crate::exit::CliError;
use crate::io::OutputSet;
use crate::scene::Scene;
use crate::state::{HbState, StateShape};

/// The name of the point vector in every `.vtu`.
pub const DISPLACEMENT_ARRAY: &str = "displacement";

/// Default number of instants per period (`--vtu-frames`).
pub const DEFAULT_FRAMES: usize = 24;

/// Element types with a VTK cell, their node count and the cell (the deck's node order is
/// VTK's for all of them).
const CELLS: &[(&[&str], usize, CellType)] = &[
    (
        &["C3D8", "C3D8R", "C3D8I", "C3D8H"],
        8,
        CellType::Hexahedron,
    ),
    (
        &["C3D20", "C3D20R", "C3D20H"],
        20,
        CellType::QuadraticHexahedron,
    ),
    (&["C3D4", "C3D4H"], 4, CellType::Tetra),
    (&["C3D10", "C3D10M", "C3D10H"], 10, CellType::QuadraticTetra),
    (
        &["S4", "S4R", "CPS4", "CPE4", "CAX4", "M3D4"],
        4,
        CellType::Quad,
    ),
    (
        &["S3", "S3R", "CPS3", "CPE3", "CAX3", "M3D3"],
        3,
        CellType::Triangle,
    ),
    (
        &["S8", "S8R", "CPS8", "CPE8", "CAX8"],
        8,
        CellType::QuadraticQuad,
    ),
    (
        &["S6", "CPS6", "CPE6", "CAX6"],
        6,
        CellType::QuadraticTriangle,
    ),
    (&["B31", "B21", "T3D2", "T2D2"], 2, CellType::Line),
];

/// The mesh of a picture: its points (every node of the deck, by ascending label), its
/// cells, and where each matrix row's displacement goes.
#[derive(Debug, Clone)]
pub struct MeshPicture {
    points: Vec<f64>,
    connectivity: Vec<u64>,
    offsets: Vec<u64>,
    types: Vec<CellType>,
    /// `(row, 3 point + component - 1)` for every translational row.
    rows: Vec<(usize, usize)>,
}

impl MeshPicture {
    /// Reads the deck `mesh` (nodes and elements) and places the rows of `map` on its
    /// nodes; the error names the file, the element or the node.
    pub fn read(mesh: &Path, map: &DofMap) -> Result<Self, String> {
        let nodes = MeshNodes::read_inp(mesh).map_err(|e| e.to_string())?;
        let elements = MeshElements::read_inp(mesh).map_err(|e| e.to_string())?;
        Self::new(&nodes, &elements, map).map_err(|e| format!("{}: {e}", mesh.display()))
    }

    /// The picture of `nodes` and `elements` with the rows of `map`.
    pub fn new(nodes: &MeshNodes, elements: &MeshElements, map: &DofMap) -> Result<Self, String> {
        let sorted = nodes.sorted();
        let index: HashMap<u64, usize> = sorted
            .iter()
            .enumerate()
            .map(|(k, (n, _))| (*n, k))
            .collect();
        let mut picture = Self {
            points: sorted.iter().flat_map(|(_, x)| *x).collect(),
            connectivity: Vec::new(),
            offsets: Vec::new(),
            types: Vec::new(),
            rows: Vec::new(),
        };
        for e in &elements.elements {
            let (_, count, cell) = CELLS
                .iter()
                .find(|(kinds, _, _)| kinds.contains(&e.kind.as_str()))
                .ok_or_else(|| {
                    let known: Vec<&str> = CELLS.iter().flat_map(|c| c.0.iter().copied()).collect();
                    format!(
                        "element {} of type `{}` has no VTK cell: allowed {}",
                        e.label,
                        e.kind,
                        known.join(", ")
                    )
                })?;
            if e.nodes.len() != *count {
                return Err(format!(
                    "element {} ({}) has {} nodes: allowed {count}",
                    e.label,
                    e.kind,
                    e.nodes.len()
                ));
            }
            for n in &e.nodes {
                let k = index.get(n).ok_or_else(|| {
                    format!(
                        "element {} names node {n}, which has no *NODE line",
                        e.label
                    )
                })?;
                picture.connectivity.push(*k as u64);
            }
            picture.offsets.push(picture.connectivity.len() as u64);
            picture.types.push(*cell);
        }
        for row in 0..map.len() {
            let Some(nc) = map.node_component(row).filter(|nc| nc.component <= 3) else {
                continue;
            };
            let k = index.get(&nc.node).ok_or_else(|| {
                format!(
                    "the dof map's node {} has no *NODE line in the mesh",
                    nc.node
                )
            })?;
            picture.rows.push((row, 3 * k + nc.component as usize - 1));
        }
        Ok(picture)
    }

    /// The point vectors (3 per point) of the full model's displacement `u`.
    pub fn point_vectors(&self, u: &[f64]) -> Vec<f64> {
        let mut v = vec![0.0; self.points.len()];
        for &(row, slot) in &self.rows {
            v[slot] = u[row];
        }
        v
    }

    /// The `.vtu` document of the mesh displaced by `u` (a full-model displacement).
    pub fn vtu(&self, u: &[f64], title: &str) -> Result<Vec<u8>, String> {
        let piece = UnstructuredGridPiece {
            points: IOBuffer::F64(self.points.clone()),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity: self.connectivity.clone(),
                    offsets: self.offsets.clone(),
                },
                types: self.types.clone(),
            },
            data: Attributes {
                point: vec![Attribute::DataArray(DataArray {
                    data: IOBuffer::F64(self.point_vectors(u)),
                    ..DataArray::vectors(DISPLACEMENT_ARRAY)
                })],
                cell: Vec::new(),
            },
        };
        let vtk = Vtk {
            version: Version::new_xml(1, 0),
            title: title.to_string(),
            byte_order: ByteOrder::LittleEndian,
            data: DataSet::UnstructuredGrid {
                meta: None,
                pieces: vec![Piece::Inline(Box::new(piece))],
            },
            file_path: None,
        };
        let mut bytes = Vec::new();
        vtk.write_xml(&mut bytes)
            .map_err(|e| format!("cannot write the .vtu: {e}"))?;
        Ok(bytes)
    }
}

/// `u(t)` of the harmonic-major coefficients `coefficients` (`2H + 1` blocks of `dofs`) at
/// frequency `omega`: `U_0 + sum_j (U_cj cos(j omega t) + U_sj sin(j omega t))`.
pub fn displacement_at(coefficients: &[f64], dofs: usize, omega: f64, t: f64) -> Vec<f64> {
    let blocks = coefficients.len() / dofs.max(1);
    let mut u = coefficients[..dofs.min(coefficients.len())].to_vec();
    for j in 1..=blocks / 2 {
        let (c, s) = ((j as f64 * omega * t).cos(), (j as f64 * omega * t).sin());
        let (uc, us) = (
            &coefficients[(2 * j - 1) * dofs..2 * j * dofs],
            &coefficients[2 * j * dofs..(2 * j + 1) * dofs],
        );
        for ((u, a), b) in u.iter_mut().zip(uc).zip(us) {
            *u += a * c + b * s;
        }
    }
    u
}

/// The name of frame `k`'s file.
pub fn frame_name(k: usize) -> String {
    format!("response_{k:03}.vtu")
}

/// The `.pvd` collection of `(time, file name)` frames.
pub fn pvd(frames: &[(f64, String)]) -> String {
    let mut t = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (time, name) in frames {
        t.push_str(&format!(
            "    <DataSet timestep=\"{time:e}\" group=\"\" part=\"0\" file=\"{name}\"/>\n"
        ));
    }
    t.push_str("  </Collection>\n</VTKFile>\n");
    t
}

/// The files of the periodic response (module documentation): `frames` `.vtu` documents at
/// `t_k = k T / frames` of the full model's harmonic-major `coefficients`, then
/// `response.pvd`; `(file name, bytes)`.
pub fn periodic_response(
    picture: &MeshPicture,
    coefficients: &[f64],
    dofs: usize,
    omega: f64,
    frames: usize,
) -> Result<Vec<(String, Vec<u8>)>, String> {
    let period = 2.0 * std::f64::consts::PI / omega;
    let mut files = Vec::with_capacity(frames + 1);
    let mut listed = Vec::with_capacity(frames);
    for k in 0..frames {
        let t = k as f64 * period / frames as f64;
        let u = displacement_at(coefficients, dofs, omega, t);
        let name = frame_name(k);
        files.push((name.clone(), picture.vtu(&u, &format!("t = {t:e}"))?));
        listed.push((t, name));
    }
    files.push(("response.pvd".to_string(), pvd(&listed).into_bytes()));
    Ok(files)
}

/// `ssn solve --vtu DIR`, before the run: the scene must be a harmonic-balance `[model]`
/// scene with a `mesh` and a dof map; `DIR` is made and its `frames + 1` files claimed. The
/// picture of the mesh is read now, so that a bad mesh stops the run before it solves.
pub fn plan(
    outputs: &mut OutputSet,
    scene: &Scene,
    dir: &Path,
    frames: usize,
) -> Result<MeshPicture, CliError> {
    let bad = |e: String| CliError::BadInput(format!("{}: --vtu: {e}", scene.path.display()));
    crate::state::check_method(scene.solver.method, "--vtu").map_err(|e| bad(e.to_string()))?;
    let map = scene
        .model
        .as_ref()
        .and_then(|m| m.dof_map.as_ref())
        .ok_or_else(|| bad("the scene has no dof map (rows by node): allowed a [model] with `dof_map` or a format whose files name the nodes".into()))?;
    let mesh = scene.mesh.as_deref().ok_or_else(|| {
        bad("the scene has no mesh: allowed a [model] with mesh = \"x.inp\"".into())
    })?;
    if frames == 0 {
        return Err(bad("--vtu-frames 0: allowed 1 or more instants".into()));
    }
    let picture = MeshPicture::read(mesh, &map.map).map_err(bad)?;
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::Output(format!("{}: --vtu: {e}", dir.display())))?;
    for k in 0..frames {
        outputs.target(&dir.join(frame_name(k)), "--vtu")?;
    }
    outputs.target(&dir.join("response.pvd"), "--vtu")?;
    Ok(picture)
}

/// `ssn solve --vtu DIR`, after the run: queues the files of `solution` (its unknowns of
/// `shape`; recovered through `reduction` first when the scene was reduced).
pub fn queue(
    outputs: &mut OutputSet,
    (dir, frames): (&Path, usize),
    picture: &MeshPicture,
    solution: &Solution,
    shape: StateShape,
    reduction: Option<&CraigBampton>,
) -> Result<(), CliError> {
    let state = HbState::from_unknowns(shape, solution.omega, solution.omega_1, &solution.state);
    let (coefficients, dofs) = match reduction {
        Some(r) => (
            recover_coefficients(r, &state.displacement, shape.dofs),
            r.transform.first().map_or(0, Vec::len),
        ),
        None => (state.displacement, shape.dofs),
    };
    let files = periodic_response(picture, &coefficients, dofs, solution.omega, frames)
        .map_err(CliError::Output)?;
    for (name, bytes) in files {
        outputs.add(&dir.join(name), bytes);
    }
    Ok(())
}

/// The full model's harmonic-major coefficients of the reduced ones `x` (blocks of
/// `reduced_dofs`): `U_j = T x_j` for each block.
pub fn recover_coefficients(reduction: &CraigBampton, x: &[f64], reduced_dofs: usize) -> Vec<f64> {
    x.chunks(reduced_dofs.max(1))
        .flat_map(|block| reduction.recover(block))
        .collect()
}
