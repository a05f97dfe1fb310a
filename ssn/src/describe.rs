//! A scene's resolved structure and run in words (`ssn scene-check`).

use semismooth_contact::matrix_market::ModelSpec;
use semismooth_contact::model::{FrictionalContact, NormalLaw, Structure};
use semismooth_contact::rod::DampingSpec;

use crate::io::printable;
use crate::scene::Scene;
use semismooth_contact::solve::DiscretisationKind;

/// The first lines of a description: the scene's file and its title.
fn scene_header(path: &std::path::Path, title: Option<&str>) -> String {
    let mut out = format!(
        "scene             {}\n",
        printable(&path.display().to_string())
    );
    if let Some(t) = title {
        out.push_str(&format!("title             {}\n", printable(t)));
    }
    out
}

/// The resolved model of a scene forced at `omega`, in words (`ssn scene-check`).
pub fn describe(scene: &Scene, rod: &Structure, omega: f64, modes: &[f64]) -> String {
    use semismooth_contact::rod::{FrequencySpec, LoadKind};
    if let Some(spec) = &scene.model {
        return describe_imported(scene, spec, rod, omega, modes);
    }
    let s = &scene.rod;
    let mut out = scene_header(&scene.path, scene.title.as_deref());
    let mut line = |t: String| {
        out.push_str(&t);
        out.push('\n');
    };
    line(format!(
        "rod               {} elements, L = {}, EA = {}, rhoA = {}, {:?} mass",
        s.elements, s.length, s.axial_stiffness, s.mass_per_length, s.mass
    ));
    line(format!(
        "unknowns          {} dofs (node 0 clamped)",
        rod.model.dofs()
    ));
    let freqs: Vec<String> = modes.iter().map(|w| format!("{w:.6}")).collect();
    line(format!("natural freqs     {}", freqs.join(", ")));
    line(damping_line(s.damping.as_ref(), rod.omega_1));
    let ratio = match s.frequency {
        FrequencySpec::Ratio(r) => r,
        FrequencySpec::Absolute(w) => w / rod.omega_1,
    };
    line(format!(
        "forcing           {} p0 = {}, omega = {:.6} ({:.4} omega_1)",
        match s.load {
            LoadKind::Distributed => "distributed",
            LoadKind::Tip => "tip force",
        },
        s.amplitude,
        omega,
        ratio
    ));
    if s.contacts.is_empty() {
        line("contact           none: linear problem (one factorization, no FFT)".into());
    } else {
        for c in &s.contacts {
            line(format!(
                "contact           node {} (dof {}), gap {}{}",
                c.node,
                c.node - 1,
                c.gap,
                if c.node == s.elements { " (tip)" } else { "" }
            ));
        }
        line(format!(
            "contact stiffness static {:.6e}, shared {:.6e} (default c = 10 x shared = {:.6e}), local K[dof,dof] = {:.6e} (penalty unit)",
            rod.model.static_contact_stiffness().unwrap_or(f64::NAN),
            rod.model.shared_contact_stiffness().unwrap_or(f64::NAN),
            rod.model.default_complementarity_constant(),
            rod.model.contact_stiffness_scale()
        ));
    }
    out.push_str(&describe_run(scene, rod));
    out
}

/// The solver, sweep and contact-mass lines of [`describe`] (rod and imported scenes).
pub fn describe_run(scene: &Scene, rod: &Structure) -> String {
    let mut out = String::new();
    let mut line = |t: String| {
        out.push_str(&t);
        out.push('\n');
    };
    let v = &scene.solver;
    line(match v.method.discretisation() {
        DiscretisationKind::Harmonics => format!(
            "solver            {} H = {}, Nt = {}, {:?} linear solver, {:?} globalization",
            v.method.name(),
            v.harmonics,
            v.time_samples,
            v.linear_solver,
            v.globalization
        ),
        DiscretisationKind::StepsPerPeriod => format!(
            "solver            {}, {} steps per period, tolerance {:e}",
            v.method.name(),
            v.steps_per_period,
            v.march_tolerance
        ),
        DiscretisationKind::TimeSamples => format!(
            "solver            {}, Nt = {} steps per period",
            v.method.name(),
            v.time_samples
        ),
    });
    if let Some(sw) = &scene.sweep {
        line(format!(
            "sweep             omega/omega_1 from {} to {}, step {} in [{}, {}], at most {} points",
            sw.omega_ratio_from,
            sw.omega_ratio_to,
            sw.step,
            sw.min_step,
            sw.max_step,
            sw.max_points
        ));
    }
    let massive: Vec<String> = rod
        .model
        .contacts
        .iter()
        .flat_map(|c| c.row.dofs())
        .chain(rod.model.friction.iter().flat_map(|f| f.tangent.dofs()))
        .filter(|&&dof| semismooth_contact::model::diagonal_entry(&rod.model.mass, dof) > 0.0)
        .map(|dof| (dof + 1).to_string())
        .fold(Vec::new(), |mut list, dof| {
            if !list.contains(&dof) {
                list.push(dof);
            }
            list
        });
    if !massive.is_empty() {
        let (what, remedy) = if scene.model.is_some() {
            (
                "contact dof(s)",
                "put each contact on a massless pad dof (a zero row and column of M) joined to \
                 the structure by a stiff spring (about 10 x the static stiffness there)",
            )
        } else {
            (
                "contact node(s)",
                "mass = \"modified\" makes the tip contact massless",
            )
        };
        line(format!(
            "note              {what} {} carry mass: time marching then needs an impact \
             law and harmonic balance imposes none, so the two need not agree, the periodic \
             LCP may be hard for Lemke and the stability is undecided; {remedy}",
            massive.join(", ")
        ));
    }
    out
}

/// The resolved structure of a `[model]` scene forced at `omega` in words
/// (`ssn scene-check`), followed by the solver lines every scene has.
pub fn describe_imported(
    scene: &crate::scene::Scene,
    spec: &ModelSpec,
    structure: &Structure,
    omega: f64,
    modes: &[f64],
) -> String {
    let model = &structure.model;
    let mut out = scene_header(&scene.path, scene.title.as_deref());
    let mut line = |t: String| {
        out.push_str(&t);
        out.push('\n');
    };
    let massless = (0..model.dofs())
        .filter(|&i| semismooth_contact::model::diagonal_entry(&model.mass, i) == 0.0)
        .count();
    line(format!(
        "model             M = {}, K = {}{}",
        printable(&spec.mass.display().to_string()),
        printable(&spec.stiffness.display().to_string()),
        spec.damping_matrix.as_ref().map_or(String::new(), |d| {
            format!(", D = {}", printable(&d.display().to_string()))
        }),
    ));
    if let Some(m) = &spec.dof_map {
        let nodes = m.map.node_range().unwrap_or((0, 0));
        line(format!(
            "dof map           {}: nodes {}..={}",
            printable(&m.path.display().to_string()),
            nodes.0,
            nodes.1
        ));
    }
    line(format!(
        "unknowns          {} dofs ({massless} with a zero mass diagonal), {} stored entries in K",
        model.dofs(),
        model.stiffness.val().len()
    ));
    let freqs: Vec<String> = modes.iter().map(|w| format!("{w:.6}")).collect();
    line(format!("natural freqs     {}", freqs.join(", ")));
    line(match spec.damping {
        None if spec.damping_matrix.is_some() => "damping           from the damping file".into(),
        _ => damping_line(spec.damping.as_ref(), structure.omega_1),
    });
    let shape = match spec.load_dof {
        Some(dof) => format!("a unit point load on dof {}", dof_words(spec, dof)),
        None => printable(&spec.forcing_vector.display().to_string()),
    };
    line(format!(
        "forcing           {} x {shape}, omega = {:.6} ({:.4} omega_1)",
        spec.amplitude,
        omega,
        omega / structure.omega_1
    ));
    let frictional = &structure.model.frictional_contacts;
    if spec.contacts.is_empty() && spec.friction.is_empty() && frictional.is_empty() {
        line("contact           none: linear problem (one factorization, no FFT)".into());
    }
    for c in &spec.contacts {
        let row = match c.row.single() {
            Some((dof, a)) if a.abs() == 1.0 => format!(
                "dof {}, gap {}, obstacle on the {} side",
                dof_words(spec, dof),
                c.gap,
                if a > 0.0 { "positive" } else { "negative" }
            ),
            _ => format!("{} <= gap {}", row_words(&c.row), c.gap),
        };
        line(format!("contact           {row}"));
        if let Some((mu, tangent)) = &c.friction {
            line(format!(
                "  friction        mu = {mu} on the slip {}",
                row_words(tangent)
            ));
        }
    }
    for f in &spec.friction {
        line(format!(
            "friction          mu = {} under normal load {} (slip limit {}) on the slip {}",
            f.coefficient,
            f.normal_load,
            f.coefficient * f.normal_load,
            row_words(&f.tangent)
        ));
    }
    for t in frictional_contact_lines(frictional) {
        line(t);
    }
    line(format!(
        "observed dof      {}",
        dof_words(spec, structure.observed_dof)
    ));
    out.push_str(&describe_run(scene, structure));
    out
}

/// At most this many 3-D frictional contacts are described one by one.
const DESCRIBED_FRICTIONAL_CONTACTS: usize = 8;

/// One line per 3-D frictional contact (the first [`DESCRIBED_FRICTIONAL_CONTACTS`], then
/// how many more): its normal law, friction coefficient, tangent rows and moving obstacle.
fn frictional_contact_lines(contacts: &[FrictionalContact]) -> Vec<String> {
    let mut lines: Vec<String> = (contacts.iter().take(DESCRIBED_FRICTIONAL_CONTACTS))
        .map(|c| {
            let normal = match &c.normal {
                NormalLaw::Unilateral { row, gap } => format!("{} <= gap {gap}", row_words(row)),
                NormalLaw::Prescribed(load) => format!("normal load {load}"),
                _ => "normal law".into(),
            };
            let moving = if c.gap_cos.is_empty() && c.gap_sin.is_empty() {
                String::new()
            } else {
                format!(", moving gap cos {:?} sin {:?}", c.gap_cos, c.gap_sin)
            };
            let sliding = if c.sliding_velocity == [0.0; 2] {
                String::new()
            } else {
                format!(", obstacle sliding at {:?}", c.sliding_velocity)
            };
            format!(
                "contact 3-D       {normal}, mu = {} on the slips {} and {}{moving}{sliding}",
                c.coefficient,
                row_words(&c.tangents[0]),
                row_words(&c.tangents[1])
            )
        })
        .collect();
    if contacts.len() > DESCRIBED_FRICTIONAL_CONTACTS {
        lines.push(format!(
            "contact 3-D       and {} more",
            contacts.len() - DESCRIBED_FRICTIONAL_CONTACTS
        ));
    }
    lines
}

/// The 0-based `dof` as a scene names it: `7`, or `7 (node 9, component 1)` with a dof map.
fn dof_words(spec: &ModelSpec, dof: usize) -> String {
    let node = spec
        .dof_map
        .as_ref()
        .and_then(|m| m.map.node_component(dof));
    match node {
        Some(r) => format!("{} (node {}, component {})", dof + 1, r.node, r.component),
        None => (dof + 1).to_string(),
    }
}

/// A row of `G` in words: `1 u[41] - 1 u[83]` (1-based dofs).
fn row_words(row: &semismooth_contact::model::ContactRow) -> String {
    let terms: Vec<String> = row
        .entries()
        .map(|(dof, a)| format!("{a} u[{}]", dof + 1))
        .collect();
    terms.join(" + ").replace("+ -", "- ")
}

/// The `damping` line of a description: the damping a `[damping]` section builds
/// (`omega_1` converts a modal damping ratio to the stiffness factor).
fn damping_line(damping: Option<&DampingSpec>, omega_1: f64) -> String {
    match damping {
        None => "damping           none (no damping matrix)".into(),
        Some(DampingSpec::StiffnessProportional { zeta }) => format!(
            "damping           D = beta K, beta = 2 zeta / omega_1 = {:.6e} (zeta = {zeta})",
            2.0 * zeta / omega_1
        ),
        Some(DampingSpec::Rayleigh { alpha, beta }) => {
            format!("damping           D = {alpha} M + {beta} K")
        }
    }
}
