//! Three-dimensional frictional contacts: a normal row and two tangent rows of `G`.
//!
//! At a [`FrictionalContact`] the normal force `lambda_n <= 0` follows the unilateral law
//! on the normal row (`g_n . u - gap <= 0`) or is a prescribed load `-N`, and the
//! tangential force `lambda_t` (two components, on the rows `g_1`, `g_2`) lies in the
//! Coulomb disk `|lambda_t| <= mu N` and opposes the slip velocity `(g_1 . u', g_2 . u')`
//! while it slides: [`crate::law::FrictionDisk`]. Its rows follow the model's contacts'
//! and friction points' rows, in the order normal (when unilateral), first tangent,
//! second tangent.

use super::{ContactRow, InvalidModel};

/// Where the normal force of a [`FrictionalContact`] comes from.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum NormalLaw {
    /// Unilateral contact on `row` (`row . u - gap <= 0`): the disk's radius is
    /// `mu max(0, -lambda_n(t))`, zero while the contact is open (liftoff).
    Unilateral {
        /// The normal row of `G`.
        row: ContactRow,
        /// The gap along it (negative: preloaded).
        gap: f64,
    },
    /// A constant normal load `N > 0` (no normal row).
    Prescribed(f64),
}

/// A 3-D frictional contact (module documentation).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FrictionalContact {
    /// The normal law.
    pub normal: NormalLaw,
    /// The two tangent rows: the slip is `(g_1 . u, g_2 . u)`.
    pub tangents: [ContactRow; 2],
    /// The friction coefficient `mu >= 0`.
    pub coefficient: f64,
    /// A moving obstacle's gap on harmonics 1, 2, ... of the response's frequency `w`:
    /// `gap(t) = gap + sum_k (gap_cos[k-1] cos k w t + gap_sin[k-1] sin k w t)` (empty: a
    /// fixed obstacle; unilateral normal law only).
    pub gap_cos: Vec<f64>,
    /// The sine coefficients of the moving gap (as `gap_cos`).
    pub gap_sin: Vec<f64>,
    /// The obstacle's constant velocity along the two tangents: the slip is the
    /// structure's tangential velocity minus it (`[0, 0]`: a fixed obstacle).
    pub sliding_velocity: [f64; 2],
    /// A spring `k_t` in series with the slider (3-D Jenkins element) still to be written
    /// as slider dofs by [`crate::jenkins::expand_tangential_stiffness`]; the solvers refuse
    /// a model that still carries one (`None`: a rigid contact).
    pub tangential_stiffness: Option<f64>,
}

impl FrictionalContact {
    /// A contact closing along `normal` at `gap`, with friction `coefficient` in the plane
    /// of `tangents`.
    pub fn unilateral(
        normal: ContactRow,
        gap: f64,
        tangents: [ContactRow; 2],
        coefficient: f64,
    ) -> Self {
        Self::under(
            NormalLaw::Unilateral { row: normal, gap },
            tangents,
            coefficient,
        )
    }

    /// Friction `coefficient` in the plane of `tangents` under the constant normal load
    /// `normal_load` (the disk's radius is `coefficient * normal_load`).
    pub fn prescribed(normal_load: f64, tangents: [ContactRow; 2], coefficient: f64) -> Self {
        Self::under(NormalLaw::Prescribed(normal_load), tangents, coefficient)
    }

    /// A fixed obstacle with no tangential spring under the normal law `normal`.
    fn under(normal: NormalLaw, tangents: [ContactRow; 2], coefficient: f64) -> Self {
        Self {
            normal,
            tangents,
            coefficient,
            gap_cos: Vec::new(),
            gap_sin: Vec::new(),
            sliding_velocity: [0.0; 2],
            tangential_stiffness: None,
        }
    }

    /// The contact with a spring `kt` in series with its slider (to be expanded by
    /// [`crate::jenkins::expand_tangential_stiffness`]).
    pub fn with_tangential_stiffness(mut self, kt: f64) -> Self {
        self.tangential_stiffness = Some(kt);
        self
    }

    /// The contact against an obstacle sliding past at the constant `velocity` along the
    /// two tangents.
    pub fn with_sliding_velocity(mut self, velocity: [f64; 2]) -> Self {
        self.sliding_velocity = velocity;
        self
    }

    /// The contact against an obstacle whose gap moves periodically: the cosine and sine
    /// coefficients of `gap(t) - gap` on harmonics 1, 2, ... (a missing coefficient is 0).
    pub fn with_moving_gap(mut self, gap_cos: Vec<f64>, gap_sin: Vec<f64>) -> Self {
        self.gap_cos = gap_cos;
        self.gap_sin = gap_sin;
        self
    }

    /// The moving gap's `(cos, sin)` coefficients on harmonics 1, 2, ... (empty: fixed).
    pub(crate) fn gap_harmonics(&self) -> Vec<(f64, f64)> {
        let count = self.gap_cos.len().max(self.gap_sin.len());
        let at = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.0);
        (0..count)
            .map(|k| (at(&self.gap_cos, k), at(&self.gap_sin, k)))
            .collect()
    }

    /// The obstacle's gap and its rate at time `t` of a response at angular frequency
    /// `omega`: `(gap(t), gap'(t))` (the fixed gap and 0 under a prescribed load).
    pub fn gap_at(&self, omega: f64, t: f64) -> (f64, f64) {
        let NormalLaw::Unilateral { gap, .. } = self.normal else {
            return (0.0, 0.0);
        };
        let (mut value, mut rate) = (gap, 0.0);
        for (k, (a, b)) in self.gap_harmonics().into_iter().enumerate() {
            let kw = (k + 1) as f64 * omega;
            let (sin, cos) = (kw * t).sin_cos();
            value += a * cos + b * sin;
            rate += kw * (b * cos - a * sin);
        }
        (value, rate)
    }

    /// The normal row, when the normal law is unilateral.
    pub fn normal_row(&self) -> Option<&ContactRow> {
        match &self.normal {
            NormalLaw::Unilateral { row, .. } => Some(row),
            NormalLaw::Prescribed(_) => None,
        }
    }

    /// The same contact with every row mapped by `map`, which cannot fail (a change of
    /// coordinates: [`FrictionalContact::with_rows`] for a map that can).
    pub fn map_rows(&self, mut map: impl FnMut(&ContactRow) -> ContactRow) -> Self {
        match self.with_rows(|r| Ok::<_, std::convert::Infallible>(map(r))) {
            Ok(contact) => contact,
            Err(never) => match never {},
        }
    }

    /// The same contact with each of its rows replaced by `map(row)` (a renumbering onto
    /// reduced coordinates); the first error of `map`, if any.
    pub fn with_rows<E>(
        &self,
        mut map: impl FnMut(&ContactRow) -> Result<ContactRow, E>,
    ) -> Result<Self, E> {
        let normal = match &self.normal {
            NormalLaw::Unilateral { row, gap } => NormalLaw::Unilateral {
                row: map(row)?,
                gap: *gap,
            },
            NormalLaw::Prescribed(load) => NormalLaw::Prescribed(*load),
        };
        let tangents = [map(&self.tangents[0])?, map(&self.tangents[1])?];
        Ok(Self {
            normal,
            tangents,
            ..self.clone()
        })
    }

    /// Its rows of `G`: the normal row (when unilateral), then the two tangent rows.
    pub fn rows(&self) -> impl Iterator<Item = &ContactRow> + '_ {
        self.normal_row().into_iter().chain(&self.tangents)
    }

    /// The number of its rows (3 on a unilateral contact, 2 under a prescribed load).
    pub fn row_count(&self) -> usize {
        2 + usize::from(self.normal_row().is_some())
    }

    /// Its rows of `G` when they start at `first`: the normal row (on a unilateral contact)
    /// and the two tangent rows, the last two.
    pub(crate) fn rows_from(&self, first: usize) -> (Option<usize>, [usize; 2]) {
        let tangent = first + self.row_count() - 2;
        (self.normal_row().map(|_| first), [tangent, tangent + 1])
    }

    /// The offset of each of its rows in its law's argument: the gap on the normal row,
    /// 0 on the tangent rows.
    pub(crate) fn offsets(&self) -> Vec<f64> {
        match &self.normal {
            NormalLaw::Unilateral { gap, .. } => vec![*gap, 0.0, 0.0],
            NormalLaw::Prescribed(_) => vec![0.0, 0.0],
        }
    }
}

/// The frictional contacts' part of [`super::StructuralModel::validate`]: rows on existing
/// dofs and pairwise independent (a tangent parallel to the other or to the normal makes
/// the law's Jacobian singular), finite gaps, coefficients `>= 0`, normal loads `> 0`.
pub(super) fn validate_frictional(
    points: &[FrictionalContact],
    n: usize,
) -> Result<(), InvalidModel> {
    for (point, p) in points.iter().enumerate() {
        for row in p.rows() {
            if row.largest_dof() >= n {
                return Err(InvalidModel::FrictionalContactDofOutOfRange {
                    point,
                    dof: row.largest_dof(),
                    dofs: n,
                });
            }
        }
        let value = |part, value, allowed| InvalidModel::FrictionalContactValue {
            point,
            part,
            value,
            allowed,
        };
        if !(p.coefficient.is_finite() && p.coefficient >= 0.0) {
            return Err(value(
                "friction coefficient",
                p.coefficient,
                "a finite mu >= 0",
            ));
        }
        let moving = p.gap_cos.iter().chain(&p.gap_sin);
        if let Some(v) = p.sliding_velocity.iter().find(|v| !v.is_finite()) {
            return Err(value("sliding velocity", *v, "a finite number"));
        }
        if let Some(v) = moving.clone().find(|v| !v.is_finite()) {
            return Err(value("moving gap coefficient", *v, "a finite number"));
        }
        match p.normal {
            NormalLaw::Unilateral { gap, .. } if !gap.is_finite() => {
                return Err(value("gap", gap, "a finite number"));
            }
            NormalLaw::Prescribed(load) if moving.count() > 0 => {
                return Err(value(
                    "moving gap under the normal load",
                    load,
                    "a moving gap on a unilateral normal law only",
                ));
            }
            NormalLaw::Prescribed(load) if !(load.is_finite() && load > 0.0) => {
                return Err(value("normal load", load, "a finite N > 0"));
            }
            _ => {}
        }
        let rows: Vec<&ContactRow> = p.rows().collect();
        for (i, a) in rows.iter().enumerate() {
            if rows[..i].iter().any(|b| parallel(a, b)) {
                return Err(InvalidModel::FrictionalContactParallelRows { point });
            }
        }
    }
    Ok(())
}

/// Whether `a` and `b` are parallel as vectors over the dofs (`|a . b| = |a| |b|` to
/// round-off).
fn parallel(a: &ContactRow, b: &ContactRow) -> bool {
    let dot = |p: &ContactRow, q: &ContactRow| -> f64 {
        p.entries()
            .map(|(d, x)| x * q.entries().find(|(e, _)| *e == d).map_or(0.0, |(_, y)| y))
            .sum()
    };
    let (ab, aa, bb) = (dot(a, b), dot(a, a), dot(b, b));
    aa * bb - ab * ab <= 1e-12 * aa * bb
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parallel rows, a negative coefficient, a zero load and an out-of-range dof are
    /// refused with the point's index and the value.
    #[test]
    fn a_frictional_contact_with_bad_rows_or_values_is_refused() {
        let unit = ContactRow::unit;
        let tangents = [unit(0, 1.0), unit(1, 1.0)];
        let good = FrictionalContact::unilateral(unit(2, 1.0), 0.1, tangents.clone(), 0.3);
        assert_eq!(validate_frictional(std::slice::from_ref(&good), 3), Ok(()));
        assert_eq!(good.row_count(), 3);
        let skew = ContactRow::new(vec![0, 1], vec![2.0, 0.0]).unwrap();
        let parallel = FrictionalContact::prescribed(1.0, [unit(0, 1.0), skew], 0.3);
        assert_eq!(
            validate_frictional(&[good.clone(), parallel], 3),
            Err(InvalidModel::FrictionalContactParallelRows { point: 1 })
        );
        let negative = FrictionalContact::prescribed(1.0, tangents.clone(), -0.1);
        assert!(matches!(
            validate_frictional(&[negative], 3),
            Err(InvalidModel::FrictionalContactValue { value, .. }) if value == -0.1
        ));
        let unloaded = FrictionalContact::prescribed(0.0, tangents, 0.3);
        assert!(validate_frictional(&[unloaded], 3).is_err());
        assert_eq!(
            validate_frictional(&[good], 2),
            Err(InvalidModel::FrictionalContactDofOutOfRange {
                point: 0,
                dof: 2,
                dofs: 2
            })
        );
    }
}
