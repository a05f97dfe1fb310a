//! The rows of `G`: unilateral contacts and Coulomb friction points.
//!
//! A contact's normal gap and a friction point's tangential slip are linear combinations of
//! dofs, `g . u = sum_k a_k u[d_k]` (a [`ContactRow`]): one dof against a rigid obstacle
//! (`a = +-1`), or the relative displacement of two flexible parts (`u[41] - u[83]`,
//! node-to-node), or any weighted combination. The force a row carries acts on the
//! structure through `g^T`: a contact force `lambda` on row `g` adds `a_k lambda` to dof
//! `d_k`, so two parts in contact receive equal and opposite forces.
//!
//! A [`FrictionPoint`] adds Coulomb's law on a tangential row `g_t`: the friction force
//! `lambda_t` satisfies `|lambda_t| <= mu N` and opposes the slip velocity `v_t = g_t . u'`
//! when it slides, with the normal force `N` either that of a unilateral contact
//! (`N = -lambda_n`, varying, zero when the contact opens) or prescribed and constant (a
//! damper pressed by a spring or by centrifugal load, the classic friction-damper model).

use super::InvalidModel;

/// One row of `G`: the linear combination `sum_k coefficients[k] u[dofs[k]]` of dofs (at
/// least one, distinct, finite coefficients not all zero). Built by [`ContactRow::unit`] or
/// [`ContactRow::new`].
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRow {
    dofs: Vec<usize>,
    coefficients: Vec<f64>,
}

/// Why a [`ContactRow`] cannot be built.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InvalidRow {
    /// No dof.
    #[error("a contact row needs at least one dof")]
    Empty,
    /// `dofs` and `coefficients` differ in length.
    #[error("{dofs} dofs and {coefficients} coefficients: allowed one coefficient per dof")]
    LengthMismatch {
        /// Number of dofs.
        dofs: usize,
        /// Number of coefficients.
        coefficients: usize,
    },
    /// A dof appears twice.
    #[error("dof {dof} appears twice in one row: allowed distinct dofs")]
    RepeatedDof {
        /// The repeated dof (0-based).
        dof: usize,
    },
    /// A coefficient is NaN or infinite.
    #[error("coefficient {value} of dof {dof}: allowed finite numbers")]
    NonFiniteCoefficient {
        /// Its dof (0-based).
        dof: usize,
        /// The value.
        value: f64,
    },
    /// Every coefficient is zero.
    #[error("every coefficient is zero: allowed at least one non-zero coefficient")]
    Zero,
}

impl ContactRow {
    /// The row `coefficient * u[dof]` (`+1`: an obstacle on the positive side of the dof,
    /// `-1`: on its negative side).
    pub fn unit(dof: usize, coefficient: f64) -> Self {
        Self {
            dofs: vec![dof],
            coefficients: vec![coefficient],
        }
    }

    /// The row `sum_k coefficients[k] u[dofs[k]]`, checked (at least one dof, distinct
    /// dofs, one finite coefficient per dof, not all zero).
    pub fn new(dofs: Vec<usize>, coefficients: Vec<f64>) -> Result<Self, InvalidRow> {
        if dofs.is_empty() {
            return Err(InvalidRow::Empty);
        }
        if dofs.len() != coefficients.len() {
            return Err(InvalidRow::LengthMismatch {
                dofs: dofs.len(),
                coefficients: coefficients.len(),
            });
        }
        for (k, (&dof, &value)) in dofs.iter().zip(&coefficients).enumerate() {
            if !value.is_finite() {
                return Err(InvalidRow::NonFiniteCoefficient { dof, value });
            }
            if dofs[..k].contains(&dof) {
                return Err(InvalidRow::RepeatedDof { dof });
            }
        }
        if coefficients.iter().all(|a| *a == 0.0) {
            return Err(InvalidRow::Zero);
        }
        Ok(Self { dofs, coefficients })
    }

    /// The dofs of the row.
    pub fn dofs(&self) -> &[usize] {
        &self.dofs
    }

    /// The coefficients, one per dof.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// `(dof, coefficient)` pairs.
    pub fn entries(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.dofs
            .iter()
            .copied()
            .zip(self.coefficients.iter().copied())
    }

    /// The first dof: the one reports name for the row.
    pub fn first_dof(&self) -> usize {
        self.dofs[0]
    }

    /// `Some((dof, coefficient))` for a row on one dof.
    pub fn single(&self) -> Option<(usize, f64)> {
        (self.dofs.len() == 1).then(|| (self.dofs[0], self.coefficients[0]))
    }

    /// `g . u`.
    pub fn dot(&self, u: &[f64]) -> f64 {
        self.dot_at(u, 0)
    }

    /// `sum_k a_k u[base + d_k]`: the row applied to the block of `u` starting at `base`
    /// (harmonic `j` of harmonic-major coefficients: `base = j N`).
    pub fn dot_at(&self, u: &[f64], base: usize) -> f64 {
        let mut entries = self.entries();
        let (d, a) = entries.next().expect("a row has at least one dof");
        entries.fold(a * u[base + d], |s, (d, a)| s + a * u[base + d])
    }

    /// `out[base + d_k] += alpha a_k`: `alpha g^T` added to the block of `out` at `base`.
    pub fn add_transpose_at(&self, alpha: f64, out: &mut [f64], base: usize) {
        for (d, a) in self.entries() {
            out[base + d] += alpha * a;
        }
    }

    /// `g . K g` for a column-compressed symmetric `K`: the stiffness seen along the row
    /// with every other dof held (for a unit row, `K[dof, dof]`).
    pub fn quadratic_form(&self, matrix: &super::SparseMatrix) -> f64 {
        self.entries()
            .map(|(i, a)| {
                a * self
                    .entries()
                    .map(|(j, b)| b * super::diagonal_or_entry(matrix, i, j))
                    .sum::<f64>()
            })
            .sum()
    }

    /// The largest dof (rows are checked against the model's size with it).
    pub(crate) fn largest_dof(&self) -> usize {
        self.dofs.iter().copied().max().unwrap_or(0)
    }
}

/// One unilateral contact: `g . u - gap <= 0` on its row `g`, force `lambda <= 0` (the
/// obstacle, or the other part, pushes back), `(g . u - gap) lambda = 0`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPoint {
    /// The row of `G`: what closes the gap.
    pub row: ContactRow,
    /// Initial gap `g` (negative: preloaded against the obstacle at rest).
    pub gap: f64,
}

impl ContactPoint {
    /// A contact with the obstacle on the positive side of `dof` (`u[dof] - gap <= 0`).
    pub fn new(dof: usize, gap: f64) -> Self {
        Self::on_side(dof, gap, ContactDirection::Positive)
    }

    /// A contact of `dof` against an obstacle on the `direction` side
    /// (`s u[dof] - gap <= 0`, `s = direction.sign()`).
    pub fn on_side(dof: usize, gap: f64, direction: ContactDirection) -> Self {
        Self {
            row: ContactRow::unit(dof, direction.sign()),
            gap,
        }
    }

    /// A contact on any row (`row . u - gap <= 0`): two parts, `u[a] - u[b] <= gap`, with
    /// `ContactRow::new(vec![a, b], vec![1.0, -1.0])`.
    pub fn on_row(row: ContactRow, gap: f64) -> Self {
        Self { row, gap }
    }

    /// The first dof of the row: the dof reports name for the contact (for a one-dof
    /// contact, its dof).
    pub fn dof(&self) -> usize {
        self.row.first_dof()
    }

    /// The side of a one-dof contact with coefficient `+-1`; `None` for any other row.
    pub fn direction(&self) -> Option<ContactDirection> {
        match self.row.single() {
            Some((_, 1.0)) => Some(ContactDirection::Positive),
            Some((_, -1.0)) => Some(ContactDirection::Negative),
            _ => None,
        }
    }
}

/// Which side of a contact dof the obstacle is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ContactDirection {
    /// Obstacle on the positive side: `u[dof] - gap <= 0`.
    #[default]
    Positive,
    /// Obstacle on the negative side: `-u[dof] - gap <= 0`.
    Negative,
}

impl ContactDirection {
    /// `+1` or `-1`: the entry of the contact's row of `G`.
    pub fn sign(self) -> f64 {
        match self {
            ContactDirection::Positive => 1.0,
            ContactDirection::Negative => -1.0,
        }
    }
}

/// Where the normal force of a [`FrictionPoint`] comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalForce {
    /// The force of unilateral contact `index` of [`super::StructuralModel::contacts`]:
    /// `N = max(0, -lambda_n(t))`, zero while the contact is open (liftoff).
    Contact(usize),
    /// A constant normal load `N > 0`.
    Prescribed(f64),
}

/// Coulomb friction on a tangential row `g_t`: the force `lambda_t` on the row satisfies
/// `|lambda_t| <= mu N`; `lambda_t = -mu N sign(v_t)` while it slips (`v_t = g_t . u' != 0`),
/// and `v_t = 0` while it sticks.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionPoint {
    /// The tangential row: the slip is `tangent . u`.
    pub tangent: ContactRow,
    /// The friction coefficient `mu >= 0`.
    pub coefficient: f64,
    /// The normal force.
    pub normal: NormalForce,
}

impl FrictionPoint {
    /// Friction on `tangent` under the constant normal load `normal_load` (the slip limit
    /// is `coefficient * normal_load`).
    pub fn prescribed(tangent: ContactRow, coefficient: f64, normal_load: f64) -> Self {
        Self {
            tangent,
            coefficient,
            normal: NormalForce::Prescribed(normal_load),
        }
    }

    /// Friction on `tangent` under the normal force of unilateral contact `contact`.
    pub fn on_contact(tangent: ContactRow, coefficient: f64, contact: usize) -> Self {
        Self {
            tangent,
            coefficient,
            normal: NormalForce::Contact(contact),
        }
    }

    /// The slip limit `mu N` for a normal force `lambda_n <= 0` of its contact (ignored
    /// under a prescribed load): `mu max(0, -lambda_n)`.
    pub fn slip_limit(&self, lambda_n: f64) -> f64 {
        match self.normal {
            NormalForce::Prescribed(load) => self.coefficient * load,
            NormalForce::Contact(_) => self.coefficient * (-lambda_n).max(0.0),
        }
    }
}

/// The contacts' and friction points' part of [`super::StructuralModel::validate`]: rows
/// on existing dofs, finite gaps, no two contacts on parallel rows pushing the same way
/// (their rows of `G` would be dependent: the harmonic-balance Jacobian and the
/// time-marching contact problem are then singular), room between two contacts on
/// opposite sides of one motion (a two-sided clearance: `gap_1 + gap_2 / r > 0` for rows
/// `g` and `-r g`), friction coefficients `>= 0`, prescribed normal loads `> 0`, friction
/// on existing contacts, at most one per contact.
pub(super) fn validate_rows(
    contacts: &[ContactPoint],
    friction: &[FrictionPoint],
    n: usize,
) -> Result<(), InvalidModel> {
    for (contact, c) in contacts.iter().enumerate() {
        if c.row.largest_dof() >= n {
            return Err(InvalidModel::ContactDofOutOfRange {
                contact,
                dof: c.row.largest_dof(),
                dofs: n,
            });
        }
        if !c.gap.is_finite() {
            return Err(InvalidModel::NonFinite {
                part: "contact gap",
                value: c.gap,
            });
        }
        for (first, o) in contacts[..contact].iter().enumerate() {
            let Some(ratio) = parallel_ratio(&o.row, &c.row) else {
                continue;
            };
            if ratio > 0.0 {
                return Err(InvalidModel::DuplicateContactDof {
                    first,
                    second: contact,
                    dof: c.dof(),
                });
            }
            let clearance = o.gap + c.gap / -ratio;
            if clearance.is_nan() || clearance <= 0.0 {
                return Err(InvalidModel::NoClearance {
                    first,
                    second: contact,
                    dof: c.dof(),
                    clearance,
                });
            }
        }
    }
    for (point, f) in friction.iter().enumerate() {
        if f.tangent.largest_dof() >= n {
            return Err(InvalidModel::FrictionDofOutOfRange {
                point,
                dof: f.tangent.largest_dof(),
                dofs: n,
            });
        }
        if !(f.coefficient.is_finite() && f.coefficient >= 0.0) {
            return Err(InvalidModel::FrictionCoefficient {
                point,
                value: f.coefficient,
            });
        }
        match f.normal {
            NormalForce::Prescribed(load) if !(load.is_finite() && load > 0.0) => {
                return Err(InvalidModel::NormalLoad { point, value: load });
            }
            NormalForce::Contact(contact) if contact >= contacts.len() => {
                return Err(InvalidModel::FrictionContactOutOfRange {
                    point,
                    contact,
                    contacts: contacts.len(),
                });
            }
            NormalForce::Contact(contact) => {
                let earlier = friction[..point]
                    .iter()
                    .position(|o| o.normal == NormalForce::Contact(contact));
                if let Some(first) = earlier {
                    return Err(InvalidModel::DuplicateFriction {
                        first,
                        second: point,
                        contact,
                    });
                }
            }
            NormalForce::Prescribed(_) => {}
        }
    }
    Ok(())
}

/// `Some(r)` when `b = r a` (same dofs, proportional coefficients), else `None`.
fn parallel_ratio(a: &ContactRow, b: &ContactRow) -> Option<f64> {
    if a.dofs != b.dofs {
        return None;
    }
    let (k, &pivot) = a
        .coefficients
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))?;
    let ratio = b.coefficients[k] / pivot;
    let parallel = a
        .coefficients
        .iter()
        .zip(&b.coefficients)
        .all(|(x, y)| (y - ratio * x).abs() <= 1e-14 * (y.abs() + (ratio * x).abs()));
    (parallel && ratio != 0.0).then_some(ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_checked_and_applied_as_linear_combinations() {
        assert_eq!(ContactRow::new(vec![], vec![]), Err(InvalidRow::Empty));
        assert_eq!(
            ContactRow::new(vec![1, 2], vec![1.0]),
            Err(InvalidRow::LengthMismatch {
                dofs: 2,
                coefficients: 1
            })
        );
        assert_eq!(
            ContactRow::new(vec![1, 1], vec![1.0, -1.0]),
            Err(InvalidRow::RepeatedDof { dof: 1 })
        );
        assert_eq!(
            ContactRow::new(vec![0, 1], vec![0.0, 0.0]),
            Err(InvalidRow::Zero)
        );
        assert!(matches!(
            ContactRow::new(vec![0], vec![f64::NAN]),
            Err(InvalidRow::NonFiniteCoefficient { dof: 0, .. })
        ));
        let row = ContactRow::new(vec![2, 0], vec![1.0, -0.5]).unwrap();
        let u = [4.0, 7.0, 3.0, 1.0, 1.0, 9.0];
        // 3 - 0.5 * 4 on the first block, 9 - 0.5 * 1 on the second (base 3).
        assert_eq!(row.dot(&u), 1.0);
        assert_eq!(row.dot_at(&u, 3), 8.5);
        let mut out = [0.0; 3];
        row.add_transpose_at(2.0, &mut out, 0);
        assert_eq!(out, [-1.0, 0.0, 2.0]);
        let unit = ContactRow::unit(4, -1.0);
        assert_eq!(unit.single(), Some((4, -1.0)));
        assert_eq!(unit.dot(&u), -1.0);
        assert_eq!(parallel_ratio(&unit, &ContactRow::unit(4, 1.0)), Some(-1.0));
        assert_eq!(parallel_ratio(&row, &ContactRow::unit(2, -1.0)), None);
        let doubled = ContactRow::new(vec![2, 0], vec![2.0, -1.0]).unwrap();
        assert_eq!(parallel_ratio(&row, &doubled), Some(2.0));
    }

    #[test]
    fn one_dof_contacts_keep_their_side() {
        let c = ContactPoint::on_side(3, 0.1, ContactDirection::Negative);
        assert_eq!(
            (c.dof(), c.direction()),
            (3, Some(ContactDirection::Negative))
        );
        assert_eq!(ContactPoint::new(3, 0.1).row, ContactRow::unit(3, 1.0));
        let two = ContactPoint::on_row(ContactRow::new(vec![5, 2], vec![1.0, -1.0]).unwrap(), 0.0);
        assert_eq!((two.dof(), two.direction()), (5, None));
    }

    #[test]
    fn the_slip_limit_is_mu_times_the_compressive_normal_force() {
        let row = ContactRow::unit(0, 1.0);
        let prescribed = FrictionPoint::prescribed(row.clone(), 0.3, 2.0);
        assert_eq!(prescribed.slip_limit(-100.0), 0.3 * 2.0);
        let on_contact = FrictionPoint::on_contact(row, 0.5, 0);
        assert_eq!(on_contact.slip_limit(-4.0), 2.0);
        assert_eq!(on_contact.slip_limit(1.0), 0.0);
    }
}
