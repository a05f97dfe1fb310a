//! The cases on which solving from zero is measured: a public grid of the 20-element rod
//! (forcing amplitudes, gaps, frequencies, both mass models, two harmonic counts) and the
//! hard cases beside it (a fine rod at high `H`, the undamped rod at resonance, many contact
//! points, the periodic LCP over its time grids).
//!
//! Every case is solved from the zero initial guess with its settings (the scene defaults
//! unless said otherwise); `examples/from_zero.rs` prints the table, the tests assert it.

use crate::rod::ModelError;
use crate::rod::{build_rod, DampingSpec, FrequencySpec, MassModel, RodContact, RodModel, RodSpec};
use crate::settings::{LcpScheme, Method, SolverSettings};

/// One solve from zero.
#[derive(Debug, Clone)]
pub struct GridCase {
    /// What the case is, in words (`p0 = 0.1, gap = 0.25, omega = 0.80 omega_1`).
    pub label: String,
    /// The rod, built.
    pub rod: RodModel,
    /// Harmonics (for the default settings).
    pub harmonics: usize,
    /// Settings other than the defaults of `harmonics` (`None`: the defaults).
    pub settings: Option<SolverSettings>,
}

impl GridCase {
    /// The settings the case is solved with.
    pub fn solver_settings(&self) -> SolverSettings {
        self.settings
            .clone()
            .unwrap_or_else(|| SolverSettings::with_harmonics(self.harmonics))
    }
}

/// Gaps of the public grid.
pub const GRID_GAPS: [f64; 3] = [0.25, 0.5, 0.75];
/// Frequencies of the public grid, in units of `omega_1`: 0.8 to 1.6 by 0.04.
pub fn grid_frequency_ratios() -> Vec<f64> {
    (0..=20).map(|i| 0.8 + 0.04 * i as f64).collect()
}

/// The 20-element rod of the grid: damping ratio 0.01 on mode 1, distributed load `p0`,
/// tip gap `gap`, forced at `ratio omega_1`.
pub fn grid_rod(mass: MassModel, p0: f64, gap: f64, ratio: f64) -> RodSpec {
    RodSpec {
        mass,
        amplitude: p0,
        frequency: FrequencySpec::Ratio(ratio),
        contacts: vec![RodContact { node: 20, gap }],
        ..RodSpec::canonical()
    }
}

/// The public grid over the forcing amplitudes `p0s`: one group per mass model and `H` in
/// {20, 40}, each with every `p0 x gap x omega` of [`GRID_GAPS`] and
/// [`grid_frequency_ratios`].
pub fn public_grid(p0s: &[f64]) -> Result<Vec<(String, Vec<GridCase>)>, ModelError> {
    let mut groups = Vec::new();
    for mass in [MassModel::Consistent, MassModel::Modified] {
        for harmonics in [20, 40] {
            let mut cases = Vec::new();
            for &p0 in p0s {
                for gap in GRID_GAPS {
                    for ratio in grid_frequency_ratios() {
                        cases.push(GridCase {
                            label: format!("p0 = {p0}, gap = {gap}, omega = {ratio:.2} omega_1"),
                            rod: build_rod(&grid_rod(mass, p0, gap, ratio))?,
                            harmonics,
                            settings: None,
                        });
                    }
                }
            }
            groups.push((format!("grid, {mass:?} mass, H = {harmonics}"), cases));
        }
    }
    Ok(groups)
}

/// The 40-element rod of the high-`H` cases: damping ratio 0.02, `p0 = 0.1`, tip gap 0.3,
/// forced at `omega_1`.
pub fn forty_element_rod() -> RodSpec {
    RodSpec {
        elements: 40,
        damping: Some(DampingSpec::StiffnessProportional { zeta: 0.02 }),
        amplitude: 0.1,
        contacts: vec![RodContact { node: 40, gap: 0.3 }],
        ..RodSpec::canonical()
    }
}

/// A 1,000-element rod (canonical forcing at `omega_1`) with `points` contacts spread evenly
/// over its last fifth, the gap of the contact at `x` being `0.5 sin(pi x / 2L)`: the first
/// mode's shape, so that near resonance they all close nearly together.
pub fn many_contacts_rod(points: usize) -> RodSpec {
    let elements = 1000;
    let first = elements * 4 / 5;
    let contacts = (0..points)
        .map(|i| {
            let node = if points == 1 {
                elements
            } else {
                first + (elements - first) * (i + 1) / points
            };
            let x = node as f64 / elements as f64;
            RodContact {
                node,
                gap: 0.5 * (std::f64::consts::FRAC_PI_2 * x).sin(),
            }
        })
        .collect();
    RodSpec {
        elements,
        contacts,
        ..RodSpec::canonical()
    }
}

/// The hard cases, one group each.
pub fn hard_cases() -> Result<Vec<(String, Vec<GridCase>)>, ModelError> {
    let one = |label: &str, spec: &RodSpec, harmonics: usize, settings: Option<SolverSettings>| {
        Ok::<_, ModelError>((
            label.to_string(),
            vec![GridCase {
                label: label.to_string(),
                rod: build_rod(spec)?,
                harmonics,
                settings,
            }],
        ))
    };
    let mut groups = vec![
        one("40 elements, H = 80", &forty_element_rod(), 80, None)?,
        one("40 elements, H = 160", &forty_element_rod(), 160, None)?,
        one(
            "undamped, omega_1, H = 20",
            &RodSpec {
                damping: None,
                ..RodSpec::canonical()
            },
            20,
            None,
        )?,
        one(
            "two contacts (node 10 and tip), H = 20",
            &RodSpec {
                mass: MassModel::Modified,
                contacts: vec![
                    RodContact { node: 20, gap: 0.5 },
                    RodContact { node: 10, gap: 0.3 },
                ],
                ..RodSpec::canonical()
            },
            20,
            None,
        )?,
    ];
    for points in [10, 50, 100] {
        groups.push(one(
            &format!("1000 elements, {points} contacts, H = 20"),
            &many_contacts_rod(points),
            20,
            None,
        )?);
    }
    // The periodic LCP of the 40-element rod, as built (consistent mass) and with the tip's
    // mass moved to its neighbour (modified mass, the massless contact node), with the
    // trapezoidal rule and with BDF2.
    for (name, mass, lcp_scheme) in [
        (
            "40 elements, lcp-ssn, Nt = 128..2048",
            MassModel::Consistent,
            LcpScheme::Trapezoidal,
        ),
        (
            "40 elements, modified mass, lcp-ssn, Nt = 128..2048",
            MassModel::Modified,
            LcpScheme::Trapezoidal,
        ),
        (
            "40 elements, lcp-ssn BDF2, Nt = 128..2048",
            MassModel::Consistent,
            LcpScheme::Bdf2,
        ),
        (
            "40 elements, modified mass, lcp-ssn BDF2, Nt = 128..2048",
            MassModel::Modified,
            LcpScheme::Bdf2,
        ),
    ] {
        let forty = build_rod(&RodSpec {
            mass,
            ..forty_element_rod()
        })?;
        let lcp_cases = [128, 256, 512, 1024, 2048]
            .into_iter()
            .map(|nt| GridCase {
                label: format!("Nt = {nt}"),
                rod: forty.clone(),
                harmonics: 20,
                settings: Some(SolverSettings {
                    method: Method::LcpSsn,
                    time_samples: nt,
                    lcp_scheme,
                    ..SolverSettings::with_harmonics(20)
                }),
            })
            .collect();
        groups.push((name.into(), lcp_cases));
    }
    Ok(groups)
}
