//! Validation of a parsed scene, section by section: every refusal names the file, the key,
//! the value and what is allowed.

use std::path::{Path, PathBuf};

use super::*;
use semismooth_contact::solve::FrictionSupport;

pub(super) struct Check<'a> {
    path: &'a Path,
    /// The `[model]`'s dof map, once read.
    dof_map: Option<&'a DofMapFile>,
    /// The `[model]`'s mesh node coordinates, once read.
    mesh: Option<&'a semismooth_contact::import::MeshNodes>,
}

impl<'a> Check<'a> {
    /// The checks of the scene file `path` (no dof map yet).
    fn new(path: &'a Path) -> Self {
        Check {
            path,
            dof_map: None,
            mesh: None,
        }
    }

    /// The scene file.
    pub(super) fn path(&self) -> &Path {
        self.path
    }

    /// The `[model]`'s mesh (`None`: none, or not read yet).
    pub(super) fn mesh(&self) -> Option<&semismooth_contact::import::MeshNodes> {
        self.mesh
    }

    /// The `[model]`'s dof map (`None`: none, or not read yet).
    pub(super) fn dof_map(&self) -> Option<&DofMapFile> {
        self.dof_map
    }

    /// The checks of the same file with the `[model]`'s dof map `dof_map`.
    pub(super) fn with_dof_map<'b>(&self, dof_map: Option<&'b DofMapFile>) -> Check<'b>
    where
        'a: 'b,
    {
        Check {
            path: self.path,
            dof_map,
            mesh: None,
        }
    }

    pub(super) fn invalid(&self, key: &str, value: impl ToString, allowed: &str) -> SceneError {
        SceneError::invalid(self.path, key, value, allowed)
    }

    /// Refuses the first of `keys` that is given (`value` says why it may not be).
    fn refuse_given(
        &self,
        keys: &[(&str, bool)],
        value: &str,
        allowed: &str,
    ) -> Result<(), SceneError> {
        match keys.iter().find(|(_, given)| *given) {
            Some((key, _)) => Err(self.invalid(key, value, allowed)),
            None => Ok(()),
        }
    }

    pub(super) fn positive(&self, key: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.invalid(key, v, "a finite number > 0"))
        }
    }

    pub(super) fn non_negative(&self, key: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(self.invalid(key, v, "a finite number >= 0"))
        }
    }

    /// A length or force of the response: `|v| <= MAX_RESPONSE_SCALE`, so that residuals
    /// and their squares (merit functions) stay finite.
    pub(super) fn response_scale(&self, key: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() && v.abs() <= MAX_RESPONSE_SCALE {
            Ok(v)
        } else {
            Err(self.invalid(
                key,
                format!("{v:e}"),
                "a finite number with |value| <= 1e100",
            ))
        }
    }

    pub(super) fn count(
        &self,
        key: &str,
        v: i64,
        min: usize,
        max: usize,
    ) -> Result<usize, SceneError> {
        if v >= min as i64 && v <= max as i64 {
            Ok(v as usize)
        } else {
            Err(self.invalid(key, v, &format!("an integer in {min}..={max}")))
        }
    }

    /// `count` of `v` when given, else `default`.
    pub(super) fn count_or(
        &self,
        key: &str,
        v: Option<i64>,
        min: usize,
        max: usize,
        default: usize,
    ) -> Result<usize, SceneError> {
        v.map_or(Ok(default), |v| self.count(key, v, min, max))
    }
}

/// The sections a `[rod]` scene reads beside `[rod]` and `[forcing]`: damping, contacts,
/// whether friction points were given, the observed dof.
type RodParts = (
    Option<RawDamping>,
    Option<RawContact>,
    bool,
    Option<RawOutput>,
);

/// Validates a parsed scene section by section, in file order; the first invalid value is
/// the error.
pub(super) fn resolve(mut raw: RawScene, path: &Path) -> Result<Scene, SceneError> {
    let ck = Check::new(path);
    let forcing = ck.forcing_or_obstacle(&mut raw)?;
    let mut bladed_disk = None;
    let neighbour_rows = ck.neighbour_rows(raw.contact.as_ref(), raw.friction.as_ref())?;
    // The mesh deck's path (read and checked with the model: `Check::model`).
    let mesh = raw
        .model
        .as_ref()
        .and_then(|m| m.mesh.as_deref())
        .map(|name| path.parent().unwrap_or(Path::new("")).join(name));
    let (rod, model, output_dof) = match (&raw.rod, raw.model, raw.bladed_disk) {
        (None, None, Some(d)) => {
            let (model, mistuning) = ck.bladed_disk(
                d,
                raw.damping,
                &forcing,
                (raw.contact, raw.friction),
                raw.output,
            )?;
            bladed_disk = Some(mistuning);
            let output_dof = model.observed_dof;
            (RodSpec::canonical(), Some(model), output_dof)
        }
        (_, _, Some(_)) => {
            return Err(ck.invalid(
                "bladed_disk",
                "given together with [rod] or [model]",
                "one of [rod], [model] or [bladed_disk]",
            ))
        }
        (Some(raw_rod), None, None) => {
            let parts = (raw.damping, raw.contact, raw.friction.is_some(), raw.output);
            let (rod, output_dof) = ck.rod_scene(raw_rod, &forcing, parts)?;
            (rod, None, output_dof)
        }
        (None, Some(m), None) => {
            let model = ck.model(
                m,
                raw.damping,
                &forcing,
                (raw.contact, raw.friction),
                raw.output,
            )?;
            let output_dof = model.observed_dof;
            (RodSpec::canonical(), Some(model), output_dof)
        }
        (Some(_), Some(_), None) => {
            return Err(ck.invalid(
                "model",
                "given together with [rod]",
                "either [rod] (the built-in rod) or [model] (Matrix Market files)",
            ))
        }
        (None, None, None) => {
            return Err(ck.invalid(
                "rod",
                "missing",
                "a [rod] section (the built-in rod), a [model] section (Matrix Market files) \
                 or a [bladed_disk] section",
            ))
        }
    };
    // An LCP without contact is empty: allowed, solved as the linear response.
    let solver = ck.solver(&raw.solver)?;
    let contacts = model
        .as_ref()
        .map_or(rod.contacts.len(), |m| m.contacts.len());
    ck.lcp_size(&solver, contacts, raw.solver.time_samples.is_some())?;
    if let Some(m) = &model {
        ck.friction_method(&solver, m)?;
    }
    let sweep = raw.sweep.map(|sw| ck.sweep(&sw)).transpose()?;
    let sweep_unit = sweep.as_ref().map(|(_, unit)| *unit).unwrap_or_default();
    let sweep = sweep.map(|(settings, _)| settings);
    let modes = raw.modes.map(|m| ck.modes(&m)).transpose()?;
    let load_parts = ck.load_parts(&forcing, model.is_some(), solver.harmonics)?;
    let (engine_order, cyclic) =
        ck.cyclic_keys(&forcing, (raw.cyclic, neighbour_rows), &model, &bladed_disk)?;
    let reduction = raw.reduction.map(|r| ck.reduction(&r)).transpose()?;
    Ok(Scene {
        path: path.to_path_buf(),
        title: raw.title,
        rod,
        model,
        mesh,
        bladed_disk,
        output_dof,
        load_parts,
        engine_order,
        cyclic,
        solver,
        sweep,
        sweep_unit,
        sweep_keys: sweep_unit.keys(),
        modes,
        reduction,
    })
}

impl Check<'_> {
    /// A `[rod]` scene: the rod with its damping, forcing and contacts, and its observed
    /// dof; friction points (`with_friction`) are refused, they belong to `[model]` scenes.
    fn rod_scene(
        &self,
        raw_rod: &RawRod,
        forcing: &RawForcing,
        (damping, contact, with_friction, output): RodParts,
    ) -> Result<(RodSpec, Option<usize>), SceneError> {
        let mut rod = self.rod(raw_rod)?;
        self.load_parts(forcing, false, 0)?;
        rod.damping = damping.map(|d| self.damping(&d)).transpose()?;
        (rod.load, rod.amplitude, rod.frequency) = self.forcing(forcing)?;
        if let Some(c) = contact {
            rod.contacts = self.contacts(c, rod.elements)?;
        }
        if with_friction {
            return Err(self.invalid(
                "friction.point",
                "given in a [rod] scene",
                "[[friction.point]] in [model] scenes (`ssn export-model` writes a rod as one)",
            ));
        }
        let output_dof = output
            .map(|o| self.output_dof(o, rod.elements))
            .transpose()?;
        Ok((rod, output_dof))
    }

    /// `[rod]`: the mesh and the material; the other sections fill in damping, forcing and
    /// contacts (none until they do).
    fn rod(&self, r: &RawRod) -> Result<RodSpec, SceneError> {
        let spec = RodSpec {
            elements: self.count(
                "rod.elements",
                r.elements,
                1,
                semismooth_contact::rod::MAX_ELEMENTS,
            )?,
            length: self.positive("rod.length", r.length.unwrap_or(1.0))?,
            axial_stiffness: self
                .positive("rod.axial_stiffness", r.axial_stiffness.unwrap_or(1.0))?,
            mass_per_length: self
                .positive("rod.mass_per_length", r.mass_per_length.unwrap_or(1.0))?,
            mass: match r.mass {
                RawMass::Consistent => MassModel::Consistent,
                RawMass::Lumped => MassModel::Lumped,
                RawMass::Modified => MassModel::Modified,
            },
            damping: None,
            load: LoadKind::Distributed,
            amplitude: 0.0,
            frequency: FrequencySpec::Ratio(1.0),
            contacts: Vec::new(),
        };
        self.rod_scales(&spec)?;
        Ok(spec)
    }

    /// The rod must vibrate at a representable frequency: the modified mass needs a node
    /// with mass besides the massless tip, and the element length `h = L / elements`, the
    /// element stiffness `EA / h`, mass `rhoA h` and the first frequency
    /// `(pi / 2) sqrt(EA / rhoA) / L` must stay within `[1e-100, 1e100]` (far inside
    /// floating point, so that squares and products of them neither overflow nor vanish).
    fn rod_scales(&self, s: &RodSpec) -> Result<(), SceneError> {
        if s.mass == MassModel::Modified && s.elements < 2 {
            return Err(self.invalid(
                "rod.elements",
                format!("{} with mass = \"modified\"", s.elements),
                "at least 2 with the modified mass (the tip node is massless, so a one-element \
                 rod has no vibration mode)",
            ));
        }
        let h = s.length / s.elements as f64;
        let omega_1 =
            0.5 * std::f64::consts::PI * (s.axial_stiffness / s.mass_per_length).sqrt() / s.length;
        let in_range = |v: f64| (1e-100..=1e100).contains(&v);
        for (what, v) in [
            ("the element length L / elements", h),
            (
                "the element stiffness EA elements / L",
                s.axial_stiffness / h,
            ),
            ("the element mass rhoA L / elements", s.mass_per_length * h),
            (
                "the first natural frequency (pi / 2) sqrt(EA / rhoA) / L",
                omega_1,
            ),
        ] {
            if !in_range(v) {
                return Err(self.invalid(
                    "rod.length",
                    format!(
                        "{:?} (with axial_stiffness = {:?}, mass_per_length = {:?}, elements = {}: \
                         {what} is {v:e})",
                        s.length, s.axial_stiffness, s.mass_per_length, s.elements
                    ),
                    "length, axial_stiffness and mass_per_length whose element length, element \
                     stiffness, element mass and first natural frequency lie in [1e-100, 1e100]",
                ));
            }
        }
        Ok(())
    }

    /// `[damping]`: stiffness-proportional (`zeta`) or Rayleigh (`alpha`, `beta`), chosen by
    /// `model` or by the keys present.
    pub(super) fn damping(&self, d: &RawDamping) -> Result<DampingSpec, SceneError> {
        let model = match (d.model, d.zeta, d.alpha, d.beta) {
            (Some(m), _, _, _) => m,
            (None, Some(_), None, None) => RawDampingModel::StiffnessProportional,
            (None, None, a, b) if a.is_some() || b.is_some() => RawDampingModel::Rayleigh,
            (None, None, None, None) => {
                return Err(self.invalid(
                    "damping",
                    "an empty section",
                    "`zeta` (stiffness-proportional) or `alpha`/`beta` (Rayleigh); omit [damping] for none",
                ))
            }
            _ => {
                return Err(self.invalid(
                    "damping.zeta",
                    "given together with alpha/beta",
                    "either `zeta` (model = \"stiffness-proportional\") or `alpha`/`beta` (model = \"rayleigh\")",
                ))
            }
        };
        match model {
            RawDampingModel::StiffnessProportional => {
                if d.alpha.is_some() || d.beta.is_some() {
                    return Err(self.invalid(
                        "damping.alpha",
                        "given with model = \"stiffness-proportional\"",
                        "only `zeta` for this model",
                    ));
                }
                let zeta = d.zeta.ok_or_else(|| {
                    self.invalid(
                        "damping.zeta",
                        "missing",
                        "a finite number >= 0 (required by model = \"stiffness-proportional\")",
                    )
                })?;
                Ok(DampingSpec::StiffnessProportional {
                    zeta: self.non_negative("damping.zeta", zeta)?,
                })
            }
            RawDampingModel::Rayleigh => {
                if d.zeta.is_some() {
                    return Err(self.invalid(
                        "damping.zeta",
                        "given with model = \"rayleigh\"",
                        "only `alpha` and `beta` for this model",
                    ));
                }
                if d.alpha.is_none() && d.beta.is_none() {
                    return Err(self.invalid(
                        "damping.model",
                        "\"rayleigh\" without alpha or beta",
                        "model = \"rayleigh\" with `alpha` and/or `beta` (D = alpha M + beta K); \
                         omit [damping] for no damping",
                    ));
                }
                Ok(DampingSpec::Rayleigh {
                    alpha: self.non_negative("damping.alpha", d.alpha.unwrap_or(0.0))?,
                    beta: self.non_negative("damping.beta", d.beta.unwrap_or(0.0))?,
                })
            }
        }
    }

    /// `[forcing]`: the load, its amplitude and its frequency (`omega_1` by default).
    pub(super) fn forcing(
        &self,
        f: &RawForcing,
    ) -> Result<(LoadKind, f64, FrequencySpec), SceneError> {
        let amplitude = self.response_scale("forcing.amplitude", f.amplitude)?;
        let frequency = match (f.omega_ratio, f.omega) {
            (Some(r), None) => FrequencySpec::Ratio(self.positive("forcing.omega_ratio", r)?),
            (None, Some(w)) => FrequencySpec::Absolute(self.positive("forcing.omega", w)?),
            (None, None) => FrequencySpec::Ratio(1.0),
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    "forcing.omega",
                    "given together with omega_ratio",
                    "either `omega_ratio` (units of omega_1) or `omega` (rad per unit time)",
                ))
            }
        };
        let load = match f.load.unwrap_or_default() {
            RawLoad::Distributed => LoadKind::Distributed,
            RawLoad::Tip => LoadKind::Tip,
        };
        Ok((load, amplitude, frequency))
    }

    /// `[contact]`: one contact (`gap`, at `node` or the tip) or a list of
    /// `[[contact.point]]` at distinct nodes of the `elements`-element rod.
    fn contacts(&self, c: RawContact, elements: usize) -> Result<Vec<RodContact>, SceneError> {
        match (c.gap, c.point) {
            (Some(gap), None) => Ok(vec![RodContact {
                node: self.count_or("contact.node", c.node, 1, elements, elements)?,
                gap: self.response_scale("contact.gap", gap)?,
            }]),
            (None, Some(points)) if c.node.is_none() => {
                if points.is_empty() {
                    return Err(self.invalid(
                        "contact.point",
                        "an empty list",
                        "at least one [[contact.point]] with node and gap",
                    ));
                }
                let mut contacts: Vec<RodContact> = Vec::with_capacity(points.len());
                for p in points {
                    self.refuse_given(
                        &[
                            ("contact.point.dof", p.dof.is_some()),
                            ("contact.point.direction", p.direction.is_some()),
                            ("contact.point.component", p.component.is_some()),
                            ("contact.point.nodes", p.nodes.is_some()),
                            ("contact.point.components", p.components.is_some()),
                            ("contact.point.dofs", p.dofs.is_some()),
                            ("contact.point.coefficients", p.coefficients.is_some()),
                            ("contact.point.friction", p.friction.is_some()),
                            ("contact.point.tangent_dofs", p.tangent_dofs.is_some()),
                            ("contact.point.tangent_nodes", p.tangent_nodes.is_some()),
                            (
                                "contact.point.tangent_components",
                                p.tangent_components.is_some(),
                            ),
                            (
                                "contact.point.tangent_coefficients",
                                p.tangent_coefficients.is_some(),
                            ),
                        ],
                        "given in a [rod] scene",
                        "`node` and `gap` (a rod's contact is a stop on its axial \
                         displacement, without friction; `dof`, `direction`, `dofs`, \
                         `coefficients`, `friction` and `tangent_*` belong to [model] scenes)",
                    )?;
                    let node = p.node.ok_or_else(|| {
                        self.invalid("contact.point.node", "missing", "an integer node number")
                    })?;
                    let node = self.count("contact.point.node", node, 1, elements)?;
                    if contacts.iter().any(|c| c.node == node) {
                        return Err(self.invalid(
                            "contact.point.node",
                            node,
                            "distinct nodes (one contact per node)",
                        ));
                    }
                    contacts.push(RodContact {
                        node,
                        gap: self.response_scale("contact.point.gap", p.gap)?,
                    });
                }
                Ok(contacts)
            }
            (None, None) => Err(self.invalid(
                "contact",
                "a section without gap",
                "`gap` (and optional `node`) or [[contact.point]] entries; omit [contact] for a linear problem",
            )),
            _ => Err(self.invalid(
                "contact.gap",
                "given together with [[contact.point]] or node",
                "either `gap` (+ optional `node`) or [[contact.point]] entries",
            )),
        }
    }

    /// `[model]` and the sections an imported structure reads: `[damping]` (unless a
    /// damping file is given), `[forcing]` with a load `vector` file, `[[contact.point]]`
    /// with 1-based `dof`, `gap` and `direction` (+1 or -1), `[output] dof`. File names are
    /// relative to the scene's directory; dof upper bounds are checked when the files are
    /// read.
    fn model(
        &self,
        m: RawModel,
        damping: Option<RawDamping>,
        f: &RawForcing,
        (contact, friction): (Option<RawContact>, Option<RawFrictionSection>),
        output: Option<RawOutput>,
    ) -> Result<ModelSpec, SceneError> {
        let dir = self.path.parent().unwrap_or(Path::new(""));
        let file = |key: &str, name: &str| {
            if name.trim().is_empty() {
                Err(self.invalid(
                    key,
                    "\"\"",
                    "a file name (relative to the scene's directory)",
                ))
            } else {
                Ok(dir.join(name))
            }
        };
        let mass = file("model.mass", &m.mass)?;
        let stiffness = file("model.stiffness", &m.stiffness)?;
        let damping_matrix = m.damping.map(|d| file("model.damping", &d)).transpose()?;
        let damping = damping.map(|d| self.damping(&d)).transpose()?;
        if damping_matrix.is_some() && damping.is_some() {
            return Err(self.invalid(
                "damping",
                "a [damping] section together with model.damping",
                "either a damping matrix file or a [damping] section",
            ));
        }
        if f.load.is_some() {
            return Err(self.invalid(
                "forcing.load",
                "given in a [model] scene",
                "`vector` (a Matrix Market file of the load shape, N x 1)",
            ));
        }
        let (_, amplitude, frequency) = self.forcing(f)?;
        let files = super::formats::ModelFiles {
            stiffness: &stiffness,
            mass: &mass,
            damping: damping_matrix.as_deref(),
            dof_map: m.dof_map.map(|d| file("model.dof_map", &d)).transpose()?,
        };
        let (format, dof_map) = self.model_format(m.format, files)?;
        let mesh = m.mesh.map(|d| file("model.mesh", &d)).transpose()?;
        let mesh = mesh.map(|p| self.mesh_nodes(&p)).transpose()?;
        let ck = Check {
            path: self.path,
            dof_map: dof_map.as_ref(),
            mesh: mesh.as_ref(),
        };
        let (forcing_vector, load_dof) = ck.load_shape(f, &file)?;
        let (contacts, frictional_contacts) = contact
            .map(|c| ck.dof_contacts(c))
            .transpose()?
            .unwrap_or_default();
        let friction = friction
            .map(|f| ck.dof_friction(f))
            .transpose()?
            .unwrap_or_default();
        let observed_dof = output.map(|o| ck.model_output(o)).transpose()?;
        Ok(ModelSpec {
            scene: self.path.to_path_buf(),
            format,
            mass,
            stiffness,
            damping_matrix,
            damping,
            forcing_vector,
            load_dof,
            amplitude,
            frequency,
            contacts,
            friction,
            frictional_contacts,
            observed_dof,
            dof_map,
        })
    }

    /// `[forcing]`, or for a `[model]` scene driven by its moving obstacles alone (a 3-D
    /// contact with `gap_cos`, `gap_sin` or `sliding_velocity`) and without `[forcing]`, no
    /// load with the period of `[obstacle] omega` (else `omega_1`); `[obstacle] omega`
    /// beside `[forcing]` sets the forcing's `omega` when that is not given.
    fn forcing_or_obstacle(&self, raw: &mut RawScene) -> Result<RawForcing, SceneError> {
        let omega = raw.obstacle.as_ref().map(|o| o.omega);
        if let Some(mut forcing) = raw.forcing.take() {
            if forcing.omega.is_none() && forcing.omega_ratio.is_none() {
                forcing.omega = omega;
            }
            return Ok(forcing);
        }
        let points = raw.contact.as_ref().and_then(|c| c.point.as_deref());
        let moving = points
            .unwrap_or(&[])
            .iter()
            .any(|p| p.gap_cos.is_some() || p.gap_sin.is_some() || p.sliding_velocity.is_some());
        if !(moving && raw.model.is_some()) {
            return Err(self.invalid(
                "forcing",
                "missing",
                "a [forcing] section, or (a [model] scene whose only excitation is a moving \
                 obstacle: gap_cos, gap_sin or sliding_velocity on a 3-D contact) [obstacle] \
                 omega",
            ));
        }
        Ok(RawForcing {
            load_free: true,
            omega,
            ..RawForcing::default()
        })
    }

    /// `[forcing]` of a `[model]` scene: the load shape from a `vector` file, or a unit point
    /// load on `node`'s `component` (through the dof map; 0-based dof), not both.
    fn load_shape(
        &self,
        f: &RawForcing,
        file: &dyn Fn(&str, &str) -> Result<PathBuf, SceneError>,
    ) -> Result<(PathBuf, Option<usize>), SceneError> {
        if f.vector.is_some() && f.node.is_some() {
            return Err(self.invalid(
                "forcing.node",
                "given together with `vector`",
                "either `vector` (a load shape file) or `node` and `component` (a unit point \
                 load)",
            ));
        }
        if f.load_free {
            // A unit load on dof 0 times the amplitude 0: no load.
            return Ok((PathBuf::new(), Some(0)));
        }
        if let Some(dof) = self.address("forcing", None, f.node, f.component)? {
            return Ok((PathBuf::new(), Some(dof as usize - 1)));
        }
        let vector = f.vector.as_deref().ok_or_else(|| {
            self.invalid(
                "forcing.vector",
                "missing",
                "a Matrix Market file of the load shape, N x 1 (relative to the scene), or \
                 `node` and `component` (a unit point load, through the [model] dof_map)",
            )
        })?;
        Ok((file("forcing.vector", vector)?, None))
    }

    /// A scene with friction is solved by the methods that model it: `ssn-hb` and `march`
    /// (exact Coulomb friction), and `penalty-hb` (regularised friction) when every
    /// friction point has a prescribed normal load (3-D frictional contacts: any normal
    /// law).
    fn friction_method(&self, solver: &SolverSettings, m: &ModelSpec) -> Result<(), SceneError> {
        let on_contacts = m.contacts.iter().filter(|c| c.friction.is_some()).count();
        let points = m.friction.len() + on_contacts;
        if !m.frictional_contacts.is_empty()
            && solver.method.friction() == FrictionSupport::Unsupported
        {
            return Err(self.invalid(
                "solver.method",
                format!(
                    "\"{}\" with {} 3-D frictional contacts",
                    solver.method.name(),
                    m.frictional_contacts.len()
                ),
                "\"ssn-hb\" or \"march\" (the Coulomb disk of 3-D frictional contacts), or \
                 \"penalty-hb\" (its regularised vector law)",
            ));
        }
        let allowed = match solver.method.friction() {
            _ if points == 0 => return Ok(()),
            FrictionSupport::Exact => return Ok(()),
            FrictionSupport::RegularisedUnderPrescribedLoad if on_contacts == 0 => return Ok(()),
            FrictionSupport::RegularisedUnderPrescribedLoad => {
                "\"ssn-hb\" or \"march\" (penalty-hb regularises friction only under a \
                 prescribed normal load, [[friction.point]])"
            }
            _ => {
                "\"ssn-hb\" or \"march\" (exact Coulomb friction), or \"penalty-hb\" \
                 (regularised friction under prescribed normal loads)"
            }
        };
        let what = if solver.method.friction() == FrictionSupport::RegularisedUnderPrescribedLoad {
            format!(
                "\"{}\" with {on_contacts} friction points on contacts",
                solver.method.name()
            )
        } else {
            format!("\"{}\" with {points} friction points", solver.method.name())
        };
        Err(self.invalid("solver.method", what, allowed))
    }

    /// The periodic LCP's matrix is dense, of order `contacts x time_samples`: that order
    /// must not exceed [`semismooth_contact::lcp::MAX_LCP_SIZE`], so `solver.time_samples` is refused
    /// above `MAX_LCP_SIZE / contacts` for `lcp-lemke` and `lcp-ssn`.
    fn lcp_size(
        &self,
        solver: &SolverSettings,
        contacts: usize,
        given: bool,
    ) -> Result<(), SceneError> {
        let nt = solver.time_samples;
        if !solver.method.is_lcp()
            || contacts.saturating_mul(nt) <= semismooth_contact::lcp::MAX_LCP_SIZE
        {
            return Ok(());
        }
        let most = semismooth_contact::lcp::MAX_LCP_SIZE / contacts;
        let value = if given {
            nt.to_string()
        } else {
            format!("{nt} (the default)")
        };
        let allowed = if most >= 8 {
            format!(
                "an integer in 8..={most} for {} with {contacts} contacts (contacts x \
                 time_samples <= {}: the LCP matrix is dense)",
                solver.method.name(),
                semismooth_contact::lcp::MAX_LCP_SIZE
            )
        } else {
            format!(
                "none for {} with {contacts} contacts (contacts x time_samples <= {} with \
                 time_samples >= 8: the LCP matrix is dense); use ssn-hb or penalty-hb",
                solver.method.name(),
                semismooth_contact::lcp::MAX_LCP_SIZE
            )
        };
        Err(self.invalid("solver.time_samples", value, &allowed))
    }

    /// `[solver]`: the method and its discretisation and iteration settings, defaults filled
    /// in (an HB method needs more AFT samples than `2 H`).
    fn solver(&self, s: &RawSolver) -> Result<SolverSettings, SceneError> {
        let method = s.method;
        let default = SolverSettings::default();
        let harmonics = self.count_or(
            "solver.harmonics",
            s.harmonics,
            1,
            MAX_HARMONICS,
            default.harmonics,
        )?;
        let time_samples = match (s.time_samples, method.is_harmonic_balance()) {
            (Some(n), true) => {
                let n = self.count("solver.time_samples", n, 1, MAX_TIME_SAMPLES)?;
                if n <= 2 * harmonics {
                    return Err(self.invalid(
                        "solver.time_samples",
                        n,
                        &format!(
                            "an integer > 2 * harmonics = {} (the AFT needs more samples than basis functions)",
                            2 * harmonics
                        ),
                    ));
                }
                n
            }
            (Some(n), false) => self.count("solver.time_samples", n, 8, MAX_TIME_SAMPLES)?,
            (None, true) => default_hb_time_samples(harmonics),
            (None, false) => SolverSettings::for_method(method).time_samples,
        };
        let c = s.c.map(|c| self.positive("solver.c", c)).transpose()?;
        let penalty_stiffness = s
            .penalty_stiffness
            .map(|k| self.positive("solver.penalty_stiffness", k))
            .transpose()?;
        let friction_regularisation = self.positive(
            "solver.friction_regularisation",
            s.friction_regularisation
                .unwrap_or(default.friction_regularisation),
        )?;
        let max_iterations = self.count_or(
            "solver.max_iterations",
            s.max_iterations,
            1,
            100_000,
            default.max_iterations,
        )?;
        let tolerance =
            self.positive("solver.tolerance", s.tolerance.unwrap_or(default.tolerance))?;
        let steps_per_period = self.count_or(
            "solver.steps_per_period",
            s.steps_per_period,
            8,
            MAX_TIME_SAMPLES,
            default.steps_per_period,
        )?;
        let max_periods = self.count_or(
            "solver.max_periods",
            s.max_periods,
            2,
            1_000_000,
            default.max_periods,
        )?;
        let march_tolerance = self.positive(
            "solver.march_tolerance",
            s.march_tolerance.unwrap_or(default.march_tolerance),
        )?;
        let restitution = s.restitution.unwrap_or(default.restitution);
        if !(0.0..=1.0).contains(&restitution) {
            return Err(self.invalid("solver.restitution", restitution, "a number in [0, 1]"));
        }
        let accuracy = s
            .accuracy
            .map(|a| {
                if (MIN_ACCURACY..=MAX_ACCURACY).contains(&a) {
                    Ok(a)
                } else {
                    Err(self.invalid(
                        "solver.accuracy",
                        a,
                        &format!("a relative accuracy in [{MIN_ACCURACY:e}, {MAX_ACCURACY}]"),
                    ))
                }
            })
            .transpose()?;
        if accuracy.is_some() {
            // The search chooses the discretisation: one given as well would be ignored.
            self.refuse_given(
                &[
                    ("solver.harmonics", s.harmonics.is_some()),
                    ("solver.time_samples", s.time_samples.is_some()),
                    ("solver.steps_per_period", s.steps_per_period.is_some()),
                ],
                "given with solver.accuracy",
                "not both: with an accuracy the method chooses its discretisation",
            )?;
        }
        Ok(SolverSettings {
            method,
            harmonics,
            time_samples,
            c,
            penalty_stiffness,
            friction_regularisation,
            linear_solver: s.linear_solver,
            max_iterations,
            globalization: s.globalization,
            tolerance,
            steps_per_period,
            max_periods,
            march_tolerance,
            restitution,
            lcp_scheme: s.lcp_scheme,
            accuracy,
            estimate_error: default.estimate_error,
        })
    }

    /// `[sweep]`: a non-empty frequency interval in one unit (kept as given) and arclength
    /// steps with `min_step <= step <= max_step`.
    fn sweep(&self, sw: &RawSweep) -> Result<(SweepSettings, SweepUnit), SceneError> {
        let (unit, from, to) = self.sweep_window(sw)?;
        let defaults = SweepSettings::new(from, to);
        let step = self.positive("sweep.step", sw.step.unwrap_or(defaults.step))?;
        let min_step = self.positive("sweep.min_step", sw.min_step.unwrap_or(defaults.min_step))?;
        let max_step = self.positive("sweep.max_step", sw.max_step.unwrap_or(defaults.max_step))?;
        if step < min_step || step > max_step {
            return Err(self.invalid(
                "sweep.step",
                step,
                &format!("min_step ({min_step}) <= step <= max_step ({max_step})"),
            ));
        }
        let settings = SweepSettings {
            step,
            min_step,
            max_step,
            max_points: self.count_or(
                "sweep.max_points",
                sw.max_points,
                2,
                1_000_000,
                defaults.max_points,
            )?,
            stability: sw.stability.unwrap_or(defaults.stability),
            period_two: sw.period_two.unwrap_or(defaults.period_two),
            ..defaults
        };
        Ok((settings, unit))
    }
}

impl Check<'_> {
    /// `[modes]`: a mode number >= 1 and two different positive amplitudes, or two
    /// increasing positive energies.
    fn modes(&self, m: &RawModes) -> Result<ModesSettings, SceneError> {
        let (amplitudes, energy_range) =
            match (m.amplitude_from, m.amplitude_to, m.energy_from, m.energy_to) {
                (Some(from), Some(to), None, None) => {
                    let from = self.positive("modes.amplitude_from", from)?;
                    let to = self.positive("modes.amplitude_to", to)?;
                    if to == from {
                        return Err(self.invalid(
                            "modes.amplitude_to",
                            to,
                            "a value different from amplitude_from",
                        ));
                    }
                    ((from, to), None)
                }
                (None, None, Some(from), Some(to)) => {
                    let from = self.positive("modes.energy_from", from)?;
                    let to = self.positive("modes.energy_to", to)?;
                    if to <= from {
                        return Err(self.invalid(
                            "modes.energy_to",
                            to,
                            "a value above energy_from",
                        ));
                    }
                    ((f64::NAN, f64::NAN), Some((from, to)))
                }
                _ => {
                    return Err(self.invalid(
                        "modes.amplitude_from",
                        m.amplitude_from.unwrap_or(f64::NAN),
                        "amplitude_from and amplitude_to, or energy_from and energy_to (one pair)",
                    ))
                }
            };
        Ok(ModesSettings {
            mode: self.count_or("modes.mode", m.mode, 1, 1_000_000, 1)?,
            amplitude_from: amplitudes.0,
            amplitude_to: amplitudes.1,
            energy_range,
            max_points: self.count_or("modes.max_points", m.max_points, 2, 1_000_000, 1000)?,
        })
    }
}
