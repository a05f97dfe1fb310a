//! The contacts and friction points of a `[model]` scene: `[[contact.point]]` on one dof
//! (`dof`, `direction`) or on a combination of dofs (`dofs`, `coefficients`), with optional
//! Coulomb friction (`friction`, `tangent_dofs`, `tangent_coefficients`), and
//! `[[friction.point]]` under a prescribed `normal_load`. Dofs are 1-based as in Matrix
//! Market; their upper bound is checked when the files are read. With a `[model] dof_map`,
//! `node` and `component` (lists `nodes` and `components`) name a dof instead (module
//! `nodes`).

use semismooth_contact::model::{ContactRow, FrictionalContact};

use super::check::Check;
use super::*;

/// The keys of one row of `G` as a scene gives it: a `dof` (with `direction`), or `dofs`
/// with `coefficients`.
struct RawRow<'a> {
    /// The section's key prefix, `contact.point` or `friction.point`.
    section: &'static str,
    /// A node of the dof map, with `component`.
    node: Option<i64>,
    component: Option<i64>,
    dof: Option<i64>,
    direction: Option<i64>,
    dofs: Option<&'a [i64]>,
    nodes: Option<&'a [i64]>,
    components: Option<&'a [i64]>,
    coefficients: Option<&'a [f64]>,
}

/// Largest departure of `|cos|` from 1 at which a tangential row counts as parallel to
/// its normal row (round-off of rows given to 16 digits).
pub(super) const PARALLEL_TOLERANCE: f64 = 1e-9;

/// The Euclidean norm of `values`, scaled by the largest magnitude so that squares of
/// tiny or huge entries neither underflow nor overflow.
fn scaled_norm(values: &[f64]) -> f64 {
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if largest == 0.0 {
        return 0.0;
    }
    largest
        * values
            .iter()
            .map(|v| (v / largest).powi(2))
            .sum::<f64>()
            .sqrt()
}

/// The cosine of the angle between two rows of `G` (as vectors over the dofs).
pub(super) fn row_cosine(a: &ContactRow, b: &ContactRow) -> f64 {
    let dot: f64 = a
        .entries()
        .map(|(dof, x)| {
            b.entries()
                .filter(|(d, _)| *d == dof)
                .map(|(_, y)| x * y)
                .sum::<f64>()
        })
        .sum();
    dot / (scaled_norm(a.coefficients()) * scaled_norm(b.coefficients()))
}

impl Check<'_> {
    /// `[[contact.point]]` entries of a `[model]` scene (module documentation); one
    /// contact per dof and direction; the 3-D frictional contacts (module `frictional`)
    /// apart.
    pub(super) fn dof_contacts(
        &self,
        c: RawContact,
    ) -> Result<(Vec<DofContact>, Vec<FrictionalContact>), SceneError> {
        let allowed = "[[contact.point]] entries with dof (or dofs and coefficients), gap and \
                       optional direction";
        let points = match (c.gap, c.node, c.point) {
            (None, None, Some(points)) if !points.is_empty() => points,
            (None, None, _) => return Err(self.invalid("contact.point", "an empty list", allowed)),
            (Some(_), _, _) => {
                return Err(self.invalid("contact.gap", "given in a [model] scene", allowed))
            }
            (None, Some(_), _) => {
                return Err(self.invalid("contact.node", "given in a [model] scene", allowed))
            }
        };
        let mut contacts: Vec<DofContact> = Vec::with_capacity(points.len());
        let mut frictional = Vec::new();
        for (index, p) in points.into_iter().enumerate() {
            let entry = index + 1;
            if super::frictional::is_frictional(&p) {
                frictional.push(self.frictional_contact(&p)?);
                continue;
            }
            let row = self.contact_row(&p)?;
            let gap = self.response_scale("contact.point.gap", p.gap)?;
            if let Some((dof, sign)) = row.single() {
                let same = |c: &DofContact| c.row.single() == Some((dof, sign));
                if let Some(first) = contacts.iter().position(same) {
                    return Err(self.invalid(
                        "contact.point.dof",
                        format!("{} in entries {} and {entry}", dof + 1, first + 1),
                        "one contact per dof and direction (two contacts on one dof need \
                         opposite directions)",
                    ));
                }
                let opposite = |c: &DofContact| c.row.single() == Some((dof, -sign));
                if let Some(other) = contacts.iter().position(opposite) {
                    let clearance = gap + contacts[other].gap;
                    if clearance.is_nan() || clearance <= 0.0 {
                        return Err(self.invalid(
                            "contact.point.gap",
                            format!(
                                "{gap} in entry {entry} and {} in entry {} (both on dof {}, \
                                 opposite directions: clearance {clearance})",
                                contacts[other].gap,
                                other + 1,
                                dof + 1
                            ),
                            "two gaps on one dof whose sum is > 0 (room between the two \
                             obstacles)",
                        ));
                    }
                }
            }
            let friction = self.contact_friction(&p, &row)?;
            contacts.push(DofContact { row, gap, friction });
        }
        Ok((contacts, frictional))
    }

    /// The normal row of a `[[contact.point]]`.
    pub(super) fn contact_row(&self, p: &RawContactPoint) -> Result<ContactRow, SceneError> {
        self.row(RawRow {
            section: "contact.point",
            node: p.node,
            component: p.component,
            dof: p.dof,
            direction: p.direction,
            dofs: p.dofs.as_deref(),
            nodes: p.nodes.as_deref(),
            components: p.components.as_deref(),
            coefficients: p.coefficients.as_deref(),
        })
    }

    /// A contact's `friction`, `tangent_dofs` (or `tangent_nodes` with `tangent_components`)
    /// and `tangent_coefficients`: all three or none; the tangential row is not parallel to
    /// the contact's `normal` row (a slip along the normal is no slip).
    pub(super) fn contact_friction(
        &self,
        p: &RawContactPoint,
        normal: &ContactRow,
    ) -> Result<Option<(f64, ContactRow)>, SceneError> {
        let keys = ["tangent_dofs", "tangent_nodes", "tangent_components"]
            .map(|k| format!("contact.point.{k}"));
        let tangent = self.addresses(
            keys,
            p.tangent_dofs.as_deref(),
            p.tangent_nodes.as_deref(),
            p.tangent_components.as_deref(),
        )?;
        let Some(mu) = p.friction else {
            if tangent.is_some() || p.tangent_coefficients.is_some() {
                let key = match &tangent {
                    Some((_, key)) => key.as_str(),
                    None => "contact.point.tangent_coefficients",
                };
                return Err(self.invalid(
                    key,
                    "given without friction",
                    "a tangential row together with `friction` (the Coulomb coefficient)",
                ));
            }
            return Ok(None);
        };
        let mu = self.friction_coefficient("contact.point.friction", mu)?;
        let (dofs, dofs_key) = tangent.ok_or_else(|| {
            self.invalid(
                "contact.point.tangent_dofs",
                "missing",
                "the 1-based dofs of the tangential row (with `tangent_coefficients`) when \
                 `friction` is given, or `tangent_nodes` with `tangent_components`",
            )
        })?;
        let coefficients = p.tangent_coefficients.as_deref().ok_or_else(|| {
            self.invalid(
                "contact.point.tangent_coefficients",
                "missing",
                "one coefficient per tangent dof (the slip is their combination)",
            )
        })?;
        let tangent = self.combination(
            &dofs_key,
            "contact.point.tangent_coefficients",
            &dofs,
            coefficients,
        )?;
        let cosine = row_cosine(normal, &tangent);
        if cosine.abs() >= 1.0 - PARALLEL_TOLERANCE {
            return Err(self.invalid(
                "contact.point.tangent_coefficients",
                format!("a row parallel to the contact's normal row (cosine {cosine:.6})"),
                "a tangential row independent of the normal row (the slip direction, \
                 e.g. orthogonal to it)",
            ));
        }
        Ok(Some((mu, tangent)))
    }

    /// `[[friction.point]]` entries of a `[model]` scene: a row (`dof`, or `dofs` with
    /// `coefficients`), `normal_load > 0` and `friction >= 0`.
    pub(super) fn dof_friction(
        &self,
        f: RawFrictionSection,
    ) -> Result<Vec<DofFriction>, SceneError> {
        let points = match f.point {
            Some(points) if !points.is_empty() => points,
            _ => {
                return Err(self.invalid(
                    "friction.point",
                    "an empty list",
                    "[[friction.point]] entries with dof (or dofs and coefficients), \
                     normal_load and friction",
                ))
            }
        };
        points
            .into_iter()
            .map(|p| {
                let tangent = self.row(RawRow {
                    section: "friction.point",
                    node: p.node,
                    component: p.component,
                    dof: p.dof,
                    direction: None,
                    dofs: p.dofs.as_deref(),
                    nodes: p.nodes.as_deref(),
                    components: p.components.as_deref(),
                    coefficients: p.coefficients.as_deref(),
                })?;
                let normal_load = p.normal_load.ok_or_else(|| {
                    self.invalid(
                        "friction.point.normal_load",
                        "missing",
                        "the constant normal load N > 0 pressing the friction point",
                    )
                })?;
                let normal_load = self.positive("friction.point.normal_load", normal_load)?;
                let normal_load = self.response_scale("friction.point.normal_load", normal_load)?;
                let mu = p.friction.ok_or_else(|| {
                    self.invalid(
                        "friction.point.friction",
                        "missing",
                        "the Coulomb coefficient mu >= 0 (the slip limit is mu normal_load)",
                    )
                })?;
                Ok(DofFriction {
                    tangent,
                    coefficient: self.friction_coefficient("friction.point.friction", mu)?,
                    normal_load,
                })
            })
            .collect()
    }

    /// A Coulomb coefficient: finite and `>= 0`.
    pub(super) fn friction_coefficient(&self, key: &str, mu: f64) -> Result<f64, SceneError> {
        if (0.0..=MAX_RESPONSE_SCALE).contains(&mu) {
            Ok(mu)
        } else {
            Err(self.invalid(
                key,
                mu,
                "a finite Coulomb coefficient mu >= 0 (the slip limit is mu times the normal \
                 force)",
            ))
        }
    }

    /// One row of `G`: `dof` with an optional `direction` (+1 or -1), or `dofs` with
    /// `coefficients`, never both.
    fn row(&self, r: RawRow<'_>) -> Result<ContactRow, SceneError> {
        let key = |name: &str| format!("{}.{name}", r.section);
        let dof = self.address(r.section, r.dof, r.node, r.component)?;
        let keys = ["dofs", "nodes", "components"].map(key);
        let dofs = self.addresses(keys, r.dofs, r.nodes, r.components)?;
        match (dof, dofs) {
            (Some(dof), None) => {
                if r.coefficients.is_some() {
                    return Err(self.invalid(
                        &key("coefficients"),
                        "given with `dof`",
                        "`coefficients` together with `dofs` (a combination of dofs); a single \
                         `dof` takes `direction`",
                    ));
                }
                let dof = self.count(&key("dof"), dof, 1, usize::MAX >> 1)? - 1;
                let sign = match r.direction.unwrap_or(1) {
                    1 => 1.0,
                    -1 => -1.0,
                    d => {
                        return Err(self.invalid(
                            &key("direction"),
                            d,
                            "1 (obstacle on the positive side: u <= gap) or -1 (negative \
                             side: -u <= gap)",
                        ))
                    }
                };
                Ok(ContactRow::unit(dof, sign))
            }
            (None, Some((dofs, dofs_key))) => {
                if r.direction.is_some() {
                    return Err(self.invalid(
                        &key("direction"),
                        "given with `dofs`",
                        "`direction` with a single `dof`; with `dofs` the signs of \
                         `coefficients` give the direction",
                    ));
                }
                let coefficients = r.coefficients.ok_or_else(|| {
                    self.invalid(
                        &key("coefficients"),
                        "missing",
                        "one coefficient per dof of `dofs` (e.g. [1.0, -1.0] for the relative \
                         displacement of two dofs)",
                    )
                })?;
                self.combination(&dofs_key, &key("coefficients"), &dofs, coefficients)
            }
            (Some(_), Some(_)) => Err(self.invalid(
                &key("dofs"),
                "given together with `dof`",
                "either `dof` (one dof) or `dofs` with `coefficients` (a combination)",
            )),
            (None, None) => Err(self.invalid(
                &key("dof"),
                "missing",
                "a 1-based dof number, or `dofs` with `coefficients` (or, with a [model] \
                 dof_map, `node` with `component`)",
            )),
        }
    }

    /// The row `sum_k coefficients[k] u[dofs[k] - 1]`: distinct 1-based dofs, one finite
    /// coefficient per dof, not all zero.
    pub(super) fn combination(
        &self,
        dofs_key: &str,
        coefficients_key: &str,
        dofs: &[i64],
        coefficients: &[f64],
    ) -> Result<ContactRow, SceneError> {
        if dofs.is_empty() {
            return Err(self.invalid(dofs_key, "[]", "at least one 1-based dof number"));
        }
        let mut zero_based = Vec::with_capacity(dofs.len());
        for &d in dofs {
            let d = self.count(dofs_key, d, 1, usize::MAX >> 1)?;
            if zero_based.contains(&(d - 1)) {
                return Err(self.invalid(dofs_key, d, "distinct dofs (each dof once per row)"));
            }
            zero_based.push(d - 1);
        }
        if coefficients.len() != dofs.len() {
            return Err(self.invalid(
                coefficients_key,
                format!("{} values", coefficients.len()),
                &format!("one coefficient per dof ({} values)", dofs.len()),
            ));
        }
        for &a in coefficients {
            self.response_scale(coefficients_key, a)?;
        }
        if coefficients.iter().all(|a| *a == 0.0) {
            return Err(self.invalid(
                coefficients_key,
                "all zero",
                "at least one non-zero coefficient",
            ));
        }
        let norm = scaled_norm(coefficients);
        if norm < 1.0 / MAX_RESPONSE_SCALE {
            return Err(self.invalid(
                coefficients_key,
                format!("a row of Euclidean norm {norm:e}"),
                "coefficients of norm >= 1e-100: the contact's stiffness 1 / (G K^-1 G^T), \
                 and the complementarity constant c made from it, would not be a number \
                 (scale the row and its gap together)",
            ));
        }
        ContactRow::new(zero_based, coefficients.to_vec())
            .map_err(|e| self.invalid(coefficients_key, "", &e.to_string()))
    }
}
