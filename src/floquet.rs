//! Floquet multipliers of a periodic orbit from its monodromy matrix, and the bifurcations
//! between two neighbouring orbits of a branch.
//!
//! For a periodic orbit `x*(t)` of period `T` of `x' = f(t, x)` (or a fixed point of a
//! one-period map `x_{k+1} = Phi(x_k)`), the monodromy matrix `Phi'(x*(0))` maps a small
//! perturbation at the start of a period to the perturbation one period later. Its
//! eigenvalues are the Floquet multipliers: the orbit is asymptotically stable when all
//! have modulus `< 1` and unstable when one has modulus `> 1`. Along a branch of orbits,
//! a multiplier leaves the unit circle through `+1` at a fold (turning point), through `-1`
//! at a period doubling, and a complex pair leaves it at a Neimark–Sacker bifurcation.
//!
//! The eigenvalues are computed by faer's dense real Schur decomposition
//! (`Mat::eigenvalues`). Nothing here knows where the monodromy came from: a problem
//! builds it (from the variational equation, or from the tangent of a time-stepping map)
//! and hands it over.
//!
//! ```
//! use semismooth::faer::Mat;
//! use semismooth::floquet::{Multipliers, BifurcationKind, crossing};
//! // A rotation by 90 degrees scaled by 0.9: a stable complex pair of modulus 0.9.
//! let a = Mat::from_fn(2, 2, |i, j| match (i, j) { (0, 1) => -0.9, (1, 0) => 0.9, _ => 0.0 });
//! let m = Multipliers::of(a.as_ref()).unwrap();
//! assert!((m.max_abs() - 0.9).abs() < 1e-14 && m.is_stable());
//! // A real multiplier leaving through +1 between two orbits is a fold.
//! let before = Multipliers::from_values(vec![(0.95, 0.0)]);
//! let after = Multipliers::from_values(vec![(1.05, 0.0)]);
//! assert_eq!(crossing(&before, &after), Some(BifurcationKind::Fold));
//! ```

use faer::MatRef;

/// Why the multipliers could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FloquetError {
    /// The monodromy matrix is not square.
    #[error("monodromy matrix is {rows} x {cols}, expected a square matrix")]
    NotSquare {
        /// Rows.
        rows: usize,
        /// Columns.
        cols: usize,
    },
    /// An entry is not finite.
    #[error("monodromy matrix entry ({row}, {col}) is not finite ({value})")]
    NonFinite {
        /// Row.
        row: usize,
        /// Column.
        col: usize,
        /// The value.
        value: f64,
    },
    /// The Schur iteration did not converge.
    #[error("the eigenvalue iteration did not converge on the {size} x {size} monodromy matrix")]
    NoConvergence {
        /// Size of the matrix.
        size: usize,
    },
}

/// Floquet multipliers `(re, im)`, sorted by decreasing modulus.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Multipliers {
    values: Vec<(f64, f64)>,
}

/// How a multiplier left (or entered) the unit circle between two orbits of a branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum BifurcationKind {
    /// A real multiplier through `+1` (turning point of the branch).
    Fold,
    /// A real multiplier through `-1`.
    PeriodDoubling,
    /// A complex pair through the unit circle.
    NeimarkSacker,
}

impl BifurcationKind {
    /// `"fold"`, `"period-doubling"` or `"neimark-sacker"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fold => "fold",
            Self::PeriodDoubling => "period-doubling",
            Self::NeimarkSacker => "neimark-sacker",
        }
    }
}

/// Relative size of an imaginary part below which a multiplier counts as real.
const REAL_TOLERANCE: f64 = 1e-8;

impl Multipliers {
    /// The eigenvalues of a square monodromy matrix.
    pub fn of(monodromy: MatRef<'_, f64>) -> Result<Self, FloquetError> {
        let (rows, cols) = (monodromy.nrows(), monodromy.ncols());
        if rows != cols {
            return Err(FloquetError::NotSquare { rows, cols });
        }
        for j in 0..cols {
            for i in 0..rows {
                let value = monodromy[(i, j)];
                if !value.is_finite() {
                    return Err(FloquetError::NonFinite {
                        row: i,
                        col: j,
                        value,
                    });
                }
            }
        }
        if rows == 0 {
            return Ok(Self::default());
        }
        let eig = monodromy
            .to_owned()
            .eigenvalues()
            .map_err(|_| FloquetError::NoConvergence { size: rows })?;
        Ok(Self::from_values(
            eig.iter().map(|z| (z.re, z.im)).collect(),
        ))
    }

    /// Multipliers given directly (sorted here by decreasing modulus).
    pub fn from_values(mut values: Vec<(f64, f64)>) -> Self {
        values.sort_by(|a, b| b.0.hypot(b.1).total_cmp(&a.0.hypot(a.1)));
        Self { values }
    }

    /// The multipliers `(re, im)`, by decreasing modulus.
    pub fn values(&self) -> &[(f64, f64)] {
        &self.values
    }

    /// Largest modulus (0 for none).
    pub fn max_abs(&self) -> f64 {
        self.values.first().map_or(0.0, |z| z.0.hypot(z.1))
    }

    /// The multiplier of largest modulus (`None` for none).
    pub fn dominant(&self) -> Option<(f64, f64)> {
        self.values.first().copied()
    }

    /// Every multiplier strictly inside the unit circle.
    pub fn is_stable(&self) -> bool {
        self.max_abs() < 1.0
    }

    /// The real multiplier closest to `+1` (`None` when none is real).
    pub fn nearest_real_to_one(&self) -> Option<f64> {
        self.values
            .iter()
            .filter(|(re, im)| im.abs() <= REAL_TOLERANCE * re.hypot(*im))
            .map(|z| z.0)
            .min_by(|a, b| (a - 1.0).abs().total_cmp(&(b - 1.0).abs()))
    }

    /// The multipliers outside the unit circle: (real `> 1`, real `< -1`, complex).
    pub fn outside(&self) -> Outside {
        let (real_above_one, real_below_minus_one, complex) = self.outside_counts();
        Outside {
            real_above_one,
            real_below_minus_one,
            complex,
        }
    }

    fn outside_counts(&self) -> (usize, usize, usize) {
        let mut counts = (0, 0, 0);
        for &(re, im) in &self.values {
            let r = re.hypot(im);
            if r <= 1.0 {
                continue;
            }
            if im.abs() <= REAL_TOLERANCE * r {
                if re > 0.0 {
                    counts.0 += 1;
                } else {
                    counts.1 += 1;
                }
            } else {
                counts.2 += 1;
            }
        }
        counts
    }
}

/// How many multipliers of an orbit lie outside the unit circle, by where they are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Outside {
    /// Real multipliers above `+1`.
    pub real_above_one: usize,
    /// Real multipliers below `-1`.
    pub real_below_minus_one: usize,
    /// Complex multipliers (counted one by one, so a pair counts 2).
    pub complex: usize,
}

impl Outside {
    /// Whether none is outside.
    pub fn is_stable(&self) -> bool {
        self.real_above_one + self.real_below_minus_one + self.complex == 0
    }
}

/// The bifurcation between two neighbouring orbits of a branch, from the number of
/// multipliers outside the unit circle: a change of the real ones beyond `+1` is a fold,
/// beyond `-1` a period doubling, of the complex ones a Neimark–Sacker bifurcation
/// (checked in that order; `None` when nothing changed).
pub fn crossing(before: &Multipliers, after: &Multipliers) -> Option<BifurcationKind> {
    crossing_of(before.outside(), after.outside())
}

/// [`crossing`] from the counts of the multipliers outside the unit circle.
pub fn crossing_of(a: Outside, b: Outside) -> Option<BifurcationKind> {
    if a.real_above_one != b.real_above_one {
        Some(BifurcationKind::Fold)
    } else if a.real_below_minus_one != b.real_below_minus_one {
        Some(BifurcationKind::PeriodDoubling)
    } else if a.complex != b.complex {
        Some(BifurcationKind::NeimarkSacker)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    #[test]
    fn eigenvalues_of_a_block_diagonal_matrix_are_its_blocks_eigenvalues() {
        // diag(2, [[0.5, -0.4], [0.4, 0.5]], -1.5): multipliers 2, -1.5, 0.5 +- 0.4 i.
        let mut a = Mat::<f64>::zeros(4, 4);
        a[(0, 0)] = 2.0;
        a[(1, 1)] = 0.5;
        a[(1, 2)] = -0.4;
        a[(2, 1)] = 0.4;
        a[(2, 2)] = 0.5;
        a[(3, 3)] = -1.5;
        let m = Multipliers::of(a.as_ref()).unwrap();
        let v = m.values();
        assert!((v[0].0 - 2.0).abs() < 1e-14 && v[0].1 == 0.0);
        assert!((v[1].0 + 1.5).abs() < 1e-14);
        assert!((v[2].0 - 0.5).abs() < 1e-14 && (v[2].1.abs() - 0.4).abs() < 1e-14);
        assert!(!m.is_stable());
        assert_eq!(m.outside_counts(), (1, 1, 0));
    }

    #[test]
    fn crossings_are_classified_by_where_the_multiplier_leaves() {
        let s = |v: Vec<(f64, f64)>| Multipliers::from_values(v);
        let stable = s(vec![(0.9, 0.0), (0.2, 0.1), (0.2, -0.1)]);
        let fold = s(vec![(1.1, 0.0), (0.2, 0.1), (0.2, -0.1)]);
        let pd = s(vec![(-1.1, 0.0), (0.2, 0.1), (0.2, -0.1)]);
        let ns = s(vec![(0.9, 0.0), (0.8, 0.7), (0.8, -0.7)]);
        assert_eq!(crossing(&stable, &fold), Some(BifurcationKind::Fold));
        assert_eq!(crossing(&fold, &stable), Some(BifurcationKind::Fold));
        assert_eq!(
            crossing(&stable, &pd),
            Some(BifurcationKind::PeriodDoubling)
        );
        assert_eq!(crossing(&stable, &ns), Some(BifurcationKind::NeimarkSacker));
        assert_eq!(crossing(&stable, &stable), None);
    }

    #[test]
    fn bad_matrices_are_errors() {
        let a = Mat::<f64>::zeros(2, 3);
        assert!(matches!(
            Multipliers::of(a.as_ref()),
            Err(FloquetError::NotSquare { rows: 2, cols: 3 })
        ));
        let mut b = Mat::<f64>::zeros(2, 2);
        b[(1, 0)] = f64::NAN;
        assert!(matches!(
            Multipliers::of(b.as_ref()),
            Err(FloquetError::NonFinite { row: 1, col: 0, .. })
        ));
    }
}
