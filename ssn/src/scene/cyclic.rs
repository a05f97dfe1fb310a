//! `[cyclic]` on a `[model]` sector and `[forcing] engine_order` on a full model.
//!
//! ```toml
//! [cyclic]               # the [model] files are one sector of a tuned disk
//! sectors = 24           # N >= 1
//! engine_order = 3       # EO >= 0
//! left = [1, 2]          # 1-based interface dofs; right[j] is the next sector's left[j]
//! right = [7, 8]         # (or left_nodes/right_nodes through the [model] dof_map: every
//!                        # component of left_nodes[j] against the same of right_nodes[j])
//!
//! [forcing]              # on a full model (or a [bladed_disk]): sector s lags 2 pi EO s / N
//! engine_order = 3
//! sector_dofs = [[1, 2, 3], [4, 5, 6]]   # 1-based; the [bladed_disk] builder knows its own
//! ```
//!
//! A contact between sectors on a `[cyclic]` sector: its row also reads the next sector's
//! dofs (numbered as this sector's), delayed by `EO T / N`.
//!
//! ```toml
//! [[contact.point]]      # the pad against the next sector's blade
//! dofs = [3]
//! coefficients = [1.0]
//! neighbour_dofs = [2]
//! neighbour_coefficients = [-1.0]
//! gap = 0.1
//! friction = 0.3         # its friction row may read the next sector too
//! tangent_dofs = [2]
//! tangent_coefficients = [1.0]
//! tangent_neighbour_dofs = [1]
//! tangent_neighbour_coefficients = [-1.0]
//! ```
//!
//! A 3-D contact between sectors (rows with `tangent2_dofs`) takes the same keys on its
//! normal and first tangent, and `tangent2_neighbour_dofs`/`tangent2_neighbour_coefficients`
//! on its second tangent (a rigid contact: not with `tangential_stiffness`).

use serde::Deserialize;

use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::matrix_market::ModelSpec;
use semismooth_contact::model::{NeighbourRow, Structure};

use super::check::Check;
use super::{RawContact, RawForcing, RawFrictionSection, Scene, SceneError};

/// Largest `[cyclic] sectors` and `engine_order` accepted.
pub const MAX_SECTORS: usize = 100_000;

/// The `[cyclic]` section as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCyclic {
    sectors: i64,
    engine_order: i64,
    left: Option<Vec<i64>>,
    right: Option<Vec<i64>>,
    left_nodes: Option<Vec<i64>>,
    right_nodes: Option<Vec<i64>>,
}

/// A `[model]` scene's `[cyclic]` section: its structure is one sector of `sectors`,
/// excited by `engine_order`, with matching 0-based interface dofs `left` and `right`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CyclicSpec {
    /// The number of sectors `N`.
    pub sectors: usize,
    /// The engine order `EO`.
    pub engine_order: usize,
    /// Left interface dofs (0-based).
    pub left: Vec<usize>,
    /// Right interface dofs (0-based), `right[j]` the next sector's `left[j]`.
    pub right: Vec<usize>,
    /// The rows between this sector and the next (`neighbour_dofs` of the contacts and
    /// friction points), numbered as the model numbers its rows.
    pub neighbour_rows: Vec<NeighbourRow>,
}

/// `[forcing] engine_order` on a full model: the load on the dofs of sector `s` delayed by
/// `s EO T / N`.
#[derive(Debug, Clone, PartialEq)]
pub struct EngineOrderSpec {
    /// The engine order `EO`.
    pub engine_order: usize,
    /// The dofs of each sector (0-based).
    pub sector_dofs: Vec<Vec<usize>>,
}

impl Check<'_> {
    /// `[forcing] engine_order` (on a `[model]` or `[bladed_disk]`: `model`; `bladed_disk`
    /// its mistuning) and `[cyclic]` (on a `[model]` only), not both.
    pub(super) fn cyclic_keys(
        &self,
        f: &RawForcing,
        (raw, neighbour_rows): (Option<RawCyclic>, Vec<NeighbourRow>),
        model: &Option<ModelSpec>,
        bladed_disk: &Option<Vec<f64>>,
    ) -> Result<(Option<EngineOrderSpec>, Option<CyclicSpec>), SceneError> {
        let engine_order = match model.is_some() {
            true => self.engine_order(f, bladed_disk.as_ref().map(Vec::len))?,
            false if f.engine_order.is_some() => {
                return Err(self.invalid(
                    "forcing.engine_order",
                    "given in a [rod] scene",
                    "engine_order on a [model] or [bladed_disk] scene",
                ))
            }
            false => None,
        };
        let is_model = model.is_some() && bladed_disk.is_none();
        let with_map = self.with_dof_map(model.as_ref().and_then(|m| m.dof_map.as_ref()));
        let cyclic = raw.map(|c| with_map.cyclic(c, is_model)).transpose()?;
        let cyclic = cyclic.map(|c| CyclicSpec {
            neighbour_rows: neighbour_rows.clone(),
            ..c
        });
        if cyclic.is_none() && !neighbour_rows.is_empty() {
            return Err(self.invalid(
                "contact.point.neighbour_dofs",
                "given without [cyclic]",
                "rows on the next sector's dofs in a [cyclic] sector scene",
            ));
        }
        if cyclic.is_some() && engine_order.is_some() {
            return Err(self.invalid(
                "forcing.engine_order",
                "given together with [cyclic]",
                "the sector's engine order in [cyclic] engine_order",
            ));
        }
        Ok((engine_order, cyclic))
    }

    /// `[cyclic]` (only on a `[model]` scene: `model`).
    fn cyclic(&self, raw: RawCyclic, model: bool) -> Result<CyclicSpec, SceneError> {
        if !model {
            return Err(self.invalid(
                "cyclic",
                "given without a [model] section",
                "[cyclic] on a [model] scene whose files are one sector",
            ));
        }
        let sectors = self.count("cyclic.sectors", raw.sectors, 1, MAX_SECTORS)?;
        let engine_order = self.count("cyclic.engine_order", raw.engine_order, 0, MAX_SECTORS)?;
        let dofs = |key: &str, list: &[i64]| -> Result<Vec<usize>, SceneError> {
            list.iter()
                .map(|&d| Ok(self.count(key, d, 1, usize::MAX >> 1)? - 1))
                .collect()
        };
        let (left, right) = match (&raw.left, &raw.right, &raw.left_nodes, &raw.right_nodes) {
            (Some(left), Some(right), None, None) => {
                (dofs("cyclic.left", left)?, dofs("cyclic.right", right)?)
            }
            (None, None, Some(left), Some(right)) => self.interface_nodes(left, right)?,
            _ => {
                return Err(self.invalid(
                    "cyclic.left",
                    "an incomplete or mixed interface",
                    "`left` and `right` (1-based dofs), or `left_nodes` and `right_nodes` \
                     (through the [model] dof_map)",
                ))
            }
        };
        if left.len() != right.len() {
            return Err(self.invalid(
                "cyclic.right",
                format!("{} dofs", right.len()),
                &format!("as many dofs as cyclic.left ({})", left.len()),
            ));
        }
        Ok(CyclicSpec {
            sectors,
            engine_order,
            left,
            right,
            neighbour_rows: Vec::new(),
        })
    }

    /// `[cyclic] left_nodes`/`right_nodes` as 0-based dofs through the dof map: every
    /// component of `left[j]` (ascending) against the same component of `right[j]`.
    fn interface_nodes(
        &self,
        left: &[i64],
        right: &[i64],
    ) -> Result<(Vec<usize>, Vec<usize>), SceneError> {
        if left.len() != right.len() {
            return Err(self.invalid(
                "cyclic.right_nodes",
                format!("{} nodes", right.len()),
                &format!("as many nodes as cyclic.left_nodes ({})", left.len()),
            ));
        }
        let components = |node: i64| match (self.dof_map(), u64::try_from(node)) {
            (Some(map), Ok(n)) => map.map.components(n),
            _ => Vec::new(),
        };
        let (mut left_dofs, mut right_dofs) = (Vec::new(), Vec::new());
        for (&l, &r) in left.iter().zip(right) {
            for (key, node) in [("cyclic.left_nodes", l), ("cyclic.right_nodes", r)] {
                if components(node).is_empty() {
                    // No dof map, or a node it does not name: its error names the file.
                    self.resolve(key, key, node, None)?;
                }
            }
            let (cl, cr) = (components(l), components(r));
            if cl != cr {
                return Err(self.invalid(
                    "cyclic.right_nodes",
                    format!("node {r} with components {cr:?} against node {l}'s {cl:?}"),
                    "a right node with the components of its left node",
                ));
            }
            for c in cl {
                let c = Some(i64::from(c));
                let dof = |key, node| -> Result<usize, SceneError> {
                    Ok(self.resolve(key, key, node, c)? as usize - 1)
                };
                left_dofs.push(dof("cyclic.left_nodes", l)?);
                right_dofs.push(dof("cyclic.right_nodes", r)?);
            }
        }
        Ok((left_dofs, right_dofs))
    }

    /// The parts on the next sector of the scene's rows (module documentation), numbered
    /// as the model numbers its rows: the contacts, their friction rows, the friction
    /// points.
    pub(super) fn neighbour_rows(
        &self,
        contact: Option<&RawContact>,
        friction: Option<&RawFrictionSection>,
    ) -> Result<Vec<NeighbourRow>, SceneError> {
        let all = contact.and_then(|c| c.point.as_deref()).unwrap_or_default();
        let points: Vec<_> = (all.iter())
            .filter(|p| !super::frictional::is_frictional(p))
            .collect();
        let frictions = points.iter().filter(|p| p.friction.is_some()).count();
        let mut rows = Vec::new();
        let mut part = |row: usize, key: &str, dofs: &Option<Vec<i64>>, a: &Option<Vec<f64>>| {
            let (dofs_key, a_key) = (
                format!("{key}neighbour_dofs"),
                format!("{key}neighbour_coefficients"),
            );
            match (dofs, a) {
                (None, None) => Ok(()),
                (Some(dofs), Some(a)) => {
                    let part = self.combination(&dofs_key, &a_key, dofs, a)?;
                    rows.push(NeighbourRow { row, part });
                    Ok(())
                }
                (Some(_), None) => {
                    Err(self.invalid(&a_key, "missing", "one coefficient per neighbour dof"))
                }
                (None, Some(_)) => Err(self.invalid(
                    &dofs_key,
                    "missing",
                    "the next sector's 1-based dofs of the row",
                )),
            }
        };
        let mut friction_row = points.len();
        for (i, p) in points.iter().enumerate() {
            if p.tangent2_neighbour_dofs.is_some() || p.tangent2_neighbour_coefficients.is_some() {
                return Err(self.invalid(
                    "contact.point.tangent2_neighbour_dofs",
                    "given without a second tangent",
                    "a 3-D contact (tangent2_dofs) whose second tangent reads the next sector",
                ));
            }
            part(
                i,
                "contact.point.",
                &p.neighbour_dofs,
                &p.neighbour_coefficients,
            )?;
            if p.friction.is_some() {
                let (dofs, a) = (&p.tangent_neighbour_dofs, &p.tangent_neighbour_coefficients);
                part(friction_row, "contact.point.tangent_", dofs, a)?;
                friction_row += 1;
            }
        }
        let friction_points = friction
            .and_then(|f| f.point.as_deref())
            .unwrap_or_default();
        for (f, p) in friction_points.iter().enumerate() {
            let row = points.len() + frictions + f;
            part(
                row,
                "friction.point.",
                &p.neighbour_dofs,
                &p.neighbour_coefficients,
            )?;
        }
        // The 3-D contacts' rows follow: normal, tangent, second tangent of each.
        let first = points.len() + frictions + friction_points.len();
        let frictional = all.iter().filter(|p| super::frictional::is_frictional(p));
        for (j, p) in frictional.enumerate() {
            let row = first + 3 * j;
            let parts = [
                &p.neighbour_dofs,
                &p.tangent_neighbour_dofs,
                &p.tangent2_neighbour_dofs,
            ];
            if parts.iter().any(|d| d.is_some()) && p.tangential_stiffness.is_some() {
                return Err(self.invalid(
                    "contact.point.tangential_stiffness",
                    "given with neighbour parts",
                    "a rigid 3-D contact between sectors (no tangential_stiffness)",
                ));
            }
            part(
                row,
                "contact.point.",
                &p.neighbour_dofs,
                &p.neighbour_coefficients,
            )?;
            let (dofs, a) = (&p.tangent_neighbour_dofs, &p.tangent_neighbour_coefficients);
            part(row + 1, "contact.point.tangent_", dofs, a)?;
            let (dofs, a) = (
                &p.tangent2_neighbour_dofs,
                &p.tangent2_neighbour_coefficients,
            );
            part(row + 2, "contact.point.tangent2_", dofs, a)?;
        }
        Ok(rows)
    }

    /// `[forcing] engine_order` and `sector_dofs`; a `[bladed_disk]` of `disk_blades`
    /// blades gives its own sectors. `None` without `engine_order`.
    fn engine_order(
        &self,
        f: &RawForcing,
        disk_blades: Option<usize>,
    ) -> Result<Option<EngineOrderSpec>, SceneError> {
        let Some(order) = f.engine_order else {
            if f.sector_dofs.is_some() {
                return Err(self.invalid(
                    "forcing.sector_dofs",
                    "given without forcing.engine_order",
                    "sector_dofs together with engine_order",
                ));
            }
            return Ok(None);
        };
        let engine_order = self.count("forcing.engine_order", order, 0, MAX_SECTORS)?;
        let sector_dofs = match (&f.sector_dofs, disk_blades) {
            (None, Some(blades)) => (0..blades)
                .map(|j| vec![3 * j, 3 * j + 1, 3 * j + 2])
                .collect(),
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    "forcing.sector_dofs",
                    "given in a [bladed_disk] scene",
                    "nothing: the disk's sectors are its blades",
                ))
            }
            (None, None) => {
                return Err(self.invalid(
                    "forcing.sector_dofs",
                    "missing",
                    "the 1-based dofs of each sector, [[...], [...], ...]",
                ))
            }
            (Some(lists), None) => lists
                .iter()
                .map(|list| {
                    (list.iter())
                        .map(|&d| Ok(self.count("forcing.sector_dofs", d, 1, usize::MAX >> 1)? - 1))
                        .collect::<Result<Vec<usize>, SceneError>>()
                })
                .collect::<Result<_, _>>()?,
        };
        Ok(Some(EngineOrderSpec {
            engine_order,
            sector_dofs,
        }))
    }
}

impl Scene {
    /// The structure of the scene's model with its engine-order load delayed sector by
    /// sector, or reduced to its cyclic sector (observed at its observed dof); errors in
    /// words naming the scene key.
    pub fn apply_cyclic(&self, structure: Structure) -> Result<Structure, String> {
        let mut structure = structure;
        if let Some(eo) = &self.engine_order {
            let load = structure.model.load.clone();
            structure.model.load = load
                .delayed_by_sector(&eo.sector_dofs, eo.engine_order)
                .map_err(|e| format!("invalid `forcing.sector_dofs`: {e}"))?;
        }
        let Some(c) = &self.cyclic else {
            return Ok(structure);
        };
        check_interface(c, structure.model.dofs())?;
        let observed = structure.observed_dof;
        let sector = CyclicSector::new(
            structure.model,
            c.left.clone(),
            c.right.clone(),
            c.sectors,
            c.engine_order,
        )
        .and_then(|s| s.with_neighbour_rows(c.neighbour_rows.clone()))
        .map_err(|e| format!("invalid [cyclic]: {e}"))?;
        sector
            .structure(observed)
            .map_err(|e| format!("invalid [cyclic]: {e}"))
    }
}

/// `Err` naming the key (and the 1-based dof, as the scene writes it) where an interface
/// dof of `[cyclic]` is beyond the sector's `dofs` or appears twice over both sides.
fn check_interface(c: &CyclicSpec, dofs: usize) -> Result<(), String> {
    let mut seen = std::collections::HashSet::new();
    for (key, side) in [("cyclic.left", &c.left), ("cyclic.right", &c.right)] {
        for &dof in side {
            if dof >= dofs || !seen.insert(dof) {
                return Err(format!(
                    "invalid `{key}` = {}: allowed distinct dofs in 1..={dofs} over `left` and \
                     `right` (1-based, as in Matrix Market)",
                    dof + 1
                ));
            }
        }
    }
    Ok(())
}
