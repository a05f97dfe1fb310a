//! The units of a `[sweep]` window: `omega_ratio_from`/`omega_ratio_to` (units of
//! `omega_1`), `omega_from`/`omega_to` (rad per unit time, as `forcing.omega`) or
//! `frequency_hz_from`/`frequency_hz_to` (cycles per unit time, `omega = 2 pi f`), exactly
//! one pair. The run resolves the bounds to ratios once the structure's `omega_1` is known
//! ([`Scene::resolve_sweep_unit`]); until then [`SweepSettings`] holds the numbers given.

use std::f64::consts::TAU;

use super::check::Check;
use super::{RawSweep, Scene, SceneError, SweepSettings};

/// The unit of the numbers a `[sweep]` window is given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum SweepUnit {
    /// Ratios of the structure's first natural frequency `omega_1` (`omega_ratio_from/to`).
    #[default]
    RatioOfOmega1,
    /// Angular frequency in rad per unit time (`omega_from/to`).
    RadPerTime,
    /// Frequency in cycles per unit time (`frequency_hz_from/to`): `omega = 2 pi f`.
    Hertz,
}

impl SweepUnit {
    /// The ratio `omega / omega_1` of `value` given in this unit.
    pub fn ratio(self, value: f64, omega_1: f64) -> f64 {
        match self {
            SweepUnit::RatioOfOmega1 => value,
            SweepUnit::RadPerTime => value / omega_1,
            SweepUnit::Hertz => TAU * value / omega_1,
        }
    }

    /// The scene keys of the window's bounds in this unit.
    pub fn keys(self) -> [&'static str; 2] {
        match self {
            SweepUnit::RatioOfOmega1 => ["sweep.omega_ratio_from", "sweep.omega_ratio_to"],
            SweepUnit::RadPerTime => ["sweep.omega_from", "sweep.omega_to"],
            SweepUnit::Hertz => ["sweep.frequency_hz_from", "sweep.frequency_hz_to"],
        }
    }
}

/// What a `[sweep]` window allows, for messages.
const ALLOWED_WINDOW: &str = "one pair of bounds: omega_ratio_from/omega_ratio_to (units of \
                              omega_1), omega_from/omega_to (rad per unit time) or \
                              frequency_hz_from/frequency_hz_to (Hz, omega = 2 pi f)";

/// The sweep bound keys of each unit, as the scene file spells them (the alternatives one
/// override replaces: [`super::overrides`]).
pub(super) const SWEEP_BOUND_KEYS: [[&str; 2]; 3] = [
    ["omega_ratio_from", "omega_ratio_to"],
    ["omega_from", "omega_to"],
    ["frequency_hz_from", "frequency_hz_to"],
];

impl Check<'_> {
    /// The window of `[sweep]` in the one unit it is given in: both bounds positive and
    /// different; bounds of two units at once, or a lone bound, are refused with their keys.
    pub(super) fn sweep_window(&self, sw: &RawSweep) -> Result<(SweepUnit, f64, f64), SceneError> {
        let pairs = [
            (
                SweepUnit::RatioOfOmega1,
                sw.omega_ratio_from,
                sw.omega_ratio_to,
            ),
            (SweepUnit::RadPerTime, sw.omega_from, sw.omega_to),
            (SweepUnit::Hertz, sw.frequency_hz_from, sw.frequency_hz_to),
        ];
        let given: Vec<_> = pairs
            .iter()
            .filter(|(_, from, to)| from.is_some() || to.is_some())
            .collect();
        let &&(unit, from, to) = match given.as_slice() {
            [one] => one,
            [] => return Err(self.invalid("sweep.omega_ratio_from", "missing", ALLOWED_WINDOW)),
            [first, second, ..] => {
                let (a, b) = (first.0.keys()[0], second.0.keys()[0]);
                let value = format!("given together with `{a}`");
                return Err(self.invalid(b, value, ALLOWED_WINDOW));
            }
        };
        let [from_key, to_key] = unit.keys();
        let bound = |key: &str, value: Option<f64>| match value {
            Some(v) => self.positive(key, v),
            None => Err(self.invalid(key, "missing", ALLOWED_WINDOW)),
        };
        let (from, to) = (bound(from_key, from)?, bound(to_key, to)?);
        if to == from {
            let allowed = format!("a value different from {from_key}");
            return Err(self.invalid(to_key, to, &allowed));
        }
        Ok((unit, from, to))
    }
}

impl Scene {
    /// Turns the `[sweep]` bounds into ratios of `omega_1`, the structure's first natural
    /// frequency (nothing to do when they are ratios already); idempotent.
    pub fn resolve_sweep_unit(&mut self, omega_1: f64) {
        if let Some(sweep) = self.sweep.as_mut() {
            sweep.omega_ratio_from = self.sweep_unit.ratio(sweep.omega_ratio_from, omega_1);
            sweep.omega_ratio_to = self.sweep_unit.ratio(sweep.omega_ratio_to, omega_1);
        }
        self.sweep_unit = SweepUnit::RatioOfOmega1;
    }

    /// The `[sweep]` window as ratios of `omega_1`, `(from, to)`, without changing the
    /// scene.
    pub fn sweep_ratio_window(&self, sweep: &SweepSettings, omega_1: f64) -> (f64, f64) {
        let ratio = |v| self.sweep_unit.ratio(v, omega_1);
        (ratio(sweep.omega_ratio_from), ratio(sweep.omega_ratio_to))
    }
}
