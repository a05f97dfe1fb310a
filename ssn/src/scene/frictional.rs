//! 3-D frictional contacts of a `[model]` scene: a `[[contact.point]]` with `friction` and
//! either `node` with a unit `normal = [nx, ny, nz]` (the node's three components through
//! the `[model] dof_map`; the obstacle is at `gap` along the normal, `u . n <= gap`) and
//! optional unit `tangents = [[...], [...]]` orthogonal to it and to each other (completed
//! by the program when absent), or rows: `dofs`/`coefficients` for the normal,
//! `tangent_dofs`/`tangent_coefficients` and `tangent2_dofs`/`tangent2_coefficients` for
//! the two tangents. With a `[model] mesh`, `normal = "radial"` is the unit vector from an
//! `axis = [ax, ay, az]` through `axis_origin` (default the origin) to the node,
//! perpendicular to the axis. A moving obstacle adds `gap_cos`/`gap_sin` (the gap's Fourier
//! coefficients on harmonics 1, 2, ... of the response's frequency) and
//! `sliding_velocity = [v1, v2]` (the obstacle's velocity along the two tangents).

use semismooth_contact::model::{ContactRow, FrictionalContact};

use super::check::Check;
use super::contacts::{row_cosine, PARALLEL_TOLERANCE};
use super::*;

/// Largest departure of a given unit vector's norm from 1, and of a dot product from 0
/// between vectors that must be orthogonal (vectors given to about 10 digits).
const UNIT_TOLERANCE: f64 = 1e-9;

/// Whether a `[[contact.point]]` declares a 3-D frictional contact.
pub(super) fn is_frictional(p: &RawContactPoint) -> bool {
    let moving = p.gap_cos.is_some() || p.gap_sin.is_some() || p.sliding_velocity.is_some();
    p.normal.is_some() || p.tangents.is_some() || p.tangent2_dofs.is_some() || moving
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Two unit tangents completing the unit normal `n` to a right-handed frame: `t1` along
/// `e x n` with `e` the axis least aligned with `n`, `t2 = n x t1`.
pub(super) fn completed_tangents(n: &[f64; 3]) -> [[f64; 3]; 2] {
    let axis = (0..3)
        .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[axis] = 1.0;
    let t = cross(&e, n);
    let norm = dot(&t, &t).sqrt();
    let t1 = t.map(|v| v / norm);
    [t1, cross(n, &t1)]
}

impl Check<'_> {
    /// A 3-D frictional contact from a `[[contact.point]]` (module documentation).
    pub(super) fn frictional_contact(
        &self,
        p: &RawContactPoint,
    ) -> Result<FrictionalContact, SceneError> {
        let mu = p.friction.ok_or_else(|| {
            self.invalid(
                "contact.point.friction",
                "missing",
                "the Coulomb coefficient mu >= 0 of a 3-D contact (normal and tangents)",
            )
        })?;
        let mu = self.friction_coefficient("contact.point.friction", mu)?;
        if let Some(kt) = p
            .tangential_stiffness
            .filter(|kt| !(kt.is_finite() && *kt > 0.0))
        {
            return Err(self.invalid(
                "contact.point.tangential_stiffness",
                kt,
                "a finite k_t > 0 (a spring in series with the slider in each tangent \
                 direction)",
            ));
        }
        let gap = self.response_scale("contact.point.gap", p.gap)?;
        let (normal, tangents) = match &p.normal {
            Some(n) => self.node_frame(p, &self.normal_vector(p, n)?)?,
            None => self.row_frame(p)?,
        };
        let mut point = FrictionalContact::unilateral(normal, gap, tangents, mu);
        if let Some(kt) = p.tangential_stiffness {
            point = point.with_tangential_stiffness(kt);
        }
        self.moving_obstacle(p, point)
    }

    /// The point with its obstacle's moving gap and sliding velocity (finite numbers).
    fn moving_obstacle(
        &self,
        p: &RawContactPoint,
        point: FrictionalContact,
    ) -> Result<FrictionalContact, SceneError> {
        let finite = |key: &str, values: &[f64]| -> Result<Vec<f64>, SceneError> {
            values
                .iter()
                .map(|v| self.response_scale(key, *v))
                .collect()
        };
        let gap_cos = finite("contact.point.gap_cos", p.gap_cos.as_deref().unwrap_or(&[]))?;
        let gap_sin = finite("contact.point.gap_sin", p.gap_sin.as_deref().unwrap_or(&[]))?;
        let velocity = match p.sliding_velocity.as_deref() {
            None => [0.0; 2],
            Some(&[v1, v2]) => {
                let v = finite("contact.point.sliding_velocity", &[v1, v2])?;
                [v[0], v[1]]
            }
            Some(other) => {
                return Err(self.invalid(
                    "contact.point.sliding_velocity",
                    format!("{} values", other.len()),
                    "two values [v1, v2]: the obstacle's velocity along the two tangents",
                ))
            }
        };
        Ok(point
            .with_moving_gap(gap_cos, gap_sin)
            .with_sliding_velocity(velocity))
    }

    /// The rows of `node`'s three components along `normal` and the tangents.
    fn node_frame(
        &self,
        p: &RawContactPoint,
        normal: &[f64],
    ) -> Result<(ContactRow, [ContactRow; 2]), SceneError> {
        let refused = [
            ("dof", p.dof.is_some()),
            ("dofs", p.dofs.is_some()),
            ("component", p.component.is_some()),
            ("tangent_dofs", p.tangent_dofs.is_some()),
            ("tangent2_dofs", p.tangent2_dofs.is_some()),
        ];
        if let Some((key, _)) = refused.iter().find(|(_, given)| *given) {
            return Err(self.invalid(
                &format!("contact.point.{key}"),
                "given with `normal`",
                "`node` with `normal` (the node's three components), or rows without `normal`",
            ));
        }
        let node = p.node.ok_or_else(|| {
            self.invalid(
                "contact.point.node",
                "missing",
                "the contact's node (its components 1, 2, 3 through the [model] dof_map) \
                 with `normal`",
            )
        })?;
        let n = self.unit_vector("contact.point.normal", normal)?;
        let tangents = match &p.tangents {
            None => completed_tangents(&n),
            Some(given) => self.given_tangents(&n, given)?,
        };
        let dofs = (1..=3)
            .map(|c| self.resolve("contact.point.node", "contact.point.normal", node, Some(c)))
            .collect::<Result<Vec<_>, _>>()?;
        let row =
            |v: &[f64; 3]| self.combination("contact.point.node", "contact.point.normal", &dofs, v);
        Ok((row(&n)?, [row(&tangents[0])?, row(&tangents[1])?]))
    }

    /// `value` as a unit 3-vector.
    fn unit_vector(&self, key: &str, value: &[f64]) -> Result<[f64; 3], SceneError> {
        let v: [f64; 3] = value.try_into().map_err(|_| {
            self.invalid(
                key,
                format!("{} values", value.len()),
                "a unit vector of 3 values",
            )
        })?;
        let norm = dot(&v, &v).sqrt();
        if !(norm - 1.0).abs().le(&UNIT_TOLERANCE) {
            return Err(self.invalid(
                key,
                format!("a vector of norm {norm}"),
                "a unit vector (norm 1 to 1e-9)",
            ));
        }
        Ok(v)
    }

    /// Two unit tangents orthogonal to `n` and to each other.
    fn given_tangents(
        &self,
        n: &[f64; 3],
        given: &[Vec<f64>],
    ) -> Result<[[f64; 3]; 2], SceneError> {
        let key = "contact.point.tangents";
        let [a, b] = given else {
            return Err(self.invalid(
                key,
                format!("{} vectors", given.len()),
                "two unit vectors [[t1x, t1y, t1z], [t2x, t2y, t2z]]",
            ));
        };
        let (t1, t2) = (self.unit_vector(key, a)?, self.unit_vector(key, b)?);
        for (what, d) in [
            ("the normal", dot(&t1, n)),
            ("the normal", dot(&t2, n)),
            ("each other", dot(&t1, &t2)),
        ] {
            if d.abs() > UNIT_TOLERANCE {
                return Err(self.invalid(
                    key,
                    format!("tangents with cosine {d:.3e} to {what}"),
                    "two unit tangents orthogonal to the normal and to each other",
                ));
            }
        }
        Ok([t1, t2])
    }

    /// The normal row (`dofs`/`coefficients`, or `dof`), the first tangent
    /// (`tangent_dofs`/`tangent_coefficients`) and the second
    /// (`tangent2_dofs`/`tangent2_coefficients`), none parallel to another.
    fn row_frame(&self, p: &RawContactPoint) -> Result<(ContactRow, [ContactRow; 2]), SceneError> {
        if p.tangents.is_some() {
            return Err(self.invalid(
                "contact.point.tangents",
                "given without `normal`",
                "`tangents` with `node` and `normal`; with rows, `tangent_dofs` and \
                 `tangent2_dofs`",
            ));
        }
        let normal = self.contact_row(p)?;
        let Some((_, first)) = self.contact_friction(p, &normal)? else {
            unreachable!("a 3-D point's friction was checked");
        };
        let key = "contact.point.tangent2_coefficients";
        let (dofs, coefficients) = match (&p.tangent2_dofs, &p.tangent2_coefficients) {
            (Some(d), Some(c)) => (d, c),
            _ => {
                return Err(self.invalid(
                    key,
                    "missing",
                    "`tangent2_dofs` with `tangent2_coefficients` (the second tangent row)",
                ))
            }
        };
        let second = self.combination("contact.point.tangent2_dofs", key, dofs, coefficients)?;
        for other in [&normal, &first] {
            let cosine = row_cosine(other, &second);
            if cosine.abs() >= 1.0 - PARALLEL_TOLERANCE {
                return Err(self.invalid(
                    key,
                    format!("a row parallel to the normal or first tangent (cosine {cosine:.6})"),
                    "a second tangent row independent of the normal and the first tangent",
                ));
            }
        }
        Ok((normal, [first, second]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The completed frame is orthonormal and right-handed for any unit normal.
    #[test]
    fn completed_tangents_make_an_orthonormal_frame() {
        for n in [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.6, 0.0, 0.8],
            [1.0 / 3f64.sqrt(); 3],
        ] {
            let [t1, t2] = completed_tangents(&n);
            for (a, b, expected) in [
                (&t1, &t1, 1.0),
                (&t2, &t2, 1.0),
                (&t1, &t2, 0.0),
                (&t1, &n, 0.0),
                (&t2, &n, 0.0),
            ] {
                assert!((dot(a, b) - expected).abs() < 1e-15);
            }
            let c = cross(&t1, &t2);
            assert!((dot(&c, &n) - 1.0).abs() < 1e-15);
        }
    }
}
