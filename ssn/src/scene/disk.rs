//! The `[bladed_disk]` section: the bladed disk of `semismooth_contact::structures` built
//! in memory, with one blade stiffness deviation per blade (`mistuning`, a list a study can
//! draw at random) and the casing as a stop on every blade's tip pad (`[contact] gap`).
//!
//! ```toml
//! [bladed_disk]
//! blades = 100                 # sectors, 1..=MAX_BLADES (3 dofs each)
//! mistuning = [0.01, -0.02]    # blade j's stiffness k_b (1 + mistuning[j]); default tuned
//! [contact]
//! gap = 1.0                    # the casing clearance of every blade's pad
//! ```

use semismooth_contact::model::{ContactRow, SparseMatrix};
use semismooth_contact::structures::BladedDisk;

use super::check::Check;
use super::*;

/// Largest `[bladed_disk] blades` accepted.
pub const MAX_BLADES: usize = 100_000;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBladedDisk {
    blades: i64,
    mistuning: Option<Vec<f64>>,
}

/// The names a `[bladed_disk]` scene's [`ModelSpec`] gives its matrices (they are built in
/// memory, never read from files).
const MASS: &str = "[bladed_disk] mass";
const STIFFNESS: &str = "[bladed_disk] stiffness";
const LOAD: &str = "[bladed_disk] load on every blade tip";

/// The disk's matrices by the names of its [`ModelSpec`]: mass, stiffness and the load
/// shape (`N x 1`) of the disk whose blade `j` has the stiffness deviation `mistuning[j]`.
pub fn bladed_disk_matrices(mistuning: &[f64]) -> Vec<(PathBuf, SparseMatrix)> {
    let (stiffness, mass, shape) = BladedDisk::mistuned_matrices(mistuning);
    let triplets: Vec<_> = shape
        .iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(i, &v)| faer::sparse::Triplet::new(i, 0, v))
        .collect();
    let load = SparseMatrix::try_new_from_triplets(shape.len(), 1, &triplets)
        .expect("entries within N x 1");
    vec![
        (PathBuf::from(MASS), mass),
        (PathBuf::from(STIFFNESS), stiffness),
        (PathBuf::from(LOAD), load),
    ]
}

impl Check<'_> {
    /// `[bladed_disk]` with the sections the disk reads: `[damping]`, `[forcing]` without a
    /// load (a unit force on every blade tip), `[contact] gap` (a stop on every pad),
    /// `[output] dof`. Returns the disk's [`ModelSpec`] and its mistuning.
    pub(super) fn bladed_disk(
        &self,
        d: RawBladedDisk,
        damping: Option<RawDamping>,
        f: &RawForcing,
        (contact, friction): (Option<RawContact>, Option<RawFrictionSection>),
        output: Option<RawOutput>,
    ) -> Result<(ModelSpec, Vec<f64>), SceneError> {
        let blades = self.count("bladed_disk.blades", d.blades, 1, MAX_BLADES)?;
        let mistuning = d.mistuning.unwrap_or_else(|| vec![0.0; blades]);
        if mistuning.len() != blades {
            return Err(self.invalid(
                "bladed_disk.mistuning",
                format!("{} values", mistuning.len()),
                &format!("one value per blade ({blades})"),
            ));
        }
        if let Some((j, v)) = mistuning
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v > -1.0 && **v <= 1e6))
        {
            return Err(self.invalid(
                &format!("bladed_disk.mistuning[{j}]"),
                v,
                "a finite number in (-1, 1e6] (blade stiffness k_b (1 + mistuning) > 0)",
            ));
        }
        let given = [
            ("forcing.vector", f.vector.is_some()),
            ("forcing.load", f.load.is_some()),
            ("forcing.node", f.node.is_some()),
            ("forcing.component", f.component.is_some()),
        ];
        if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
            return Err(self.invalid(
                key,
                "given in a [bladed_disk] scene",
                "only `amplitude` and the frequency: the disk's load is a unit force on every \
                 blade tip",
            ));
        }
        let (_, amplitude, frequency) = self.forcing(f)?;
        let damping = damping.map(|d| self.damping(&d)).transpose()?;
        let allowed = "`gap`: the casing clearance of every blade's pad";
        let gap = match contact {
            None => None,
            Some(RawContact {
                gap: Some(gap),
                node: None,
                point: None,
            }) => Some(self.response_scale("contact.gap", gap)?),
            Some(RawContact { node: Some(_), .. }) => {
                return Err(self.invalid("contact.node", "given in a [bladed_disk] scene", allowed))
            }
            Some(_) => {
                return Err(self.invalid(
                    "contact.point",
                    "given in a [bladed_disk] scene",
                    allowed,
                ))
            }
        };
        if friction.is_some() {
            return Err(self.invalid(
                "friction.point",
                "given in a [bladed_disk] scene",
                "[[friction.point]] in [model] scenes",
            ));
        }
        let contacts = gap.map_or_else(Vec::new, |gap| {
            (0..blades)
                .map(|j| DofContact {
                    row: ContactRow::unit(BladedDisk::pad(j), 1.0),
                    gap,
                    friction: None,
                })
                .collect()
        });
        let observed_dof = output.map(|o| self.output_dof(o, 3 * blades)).transpose()?;
        let spec = ModelSpec {
            scene: self.path().to_path_buf(),
            mass: PathBuf::from(MASS),
            stiffness: PathBuf::from(STIFFNESS),
            damping_matrix: None,
            damping,
            format: MatrixFormat::MatrixMarket,
            forcing_vector: PathBuf::from(LOAD),
            load_dof: None,
            amplitude,
            frequency,
            contacts,
            friction: Vec::new(),
            frictional_contacts: Vec::new(),
            observed_dof: observed_dof.or(Some(BladedDisk::tip(0))),
            dof_map: None,
        };
        Ok((spec, mistuning))
    }
}
