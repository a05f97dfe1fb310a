//! The external force: a periodic load on harmonics of the forcing frequency `w`,
//! `f(t) = f_0 + sum_k (c_k cos(k w t) + s_k sin(k w t))`, each part a vector over the dofs.
//!
//! In complex form harmonic `k` is `z_k = c_k - i s_k` (`f(t) = Re sum_k z_k e^{i k w t}`),
//! the convention of the harmonic operator. A travelling wave `a_j cos(w t - phi_j)` is
//! `c_1 = a cos(phi)`, `s_1 = a sin(phi)` ([`HarmonicLoad::travelling_wave`]).

use super::InvalidModel;

/// One harmonic of a [`HarmonicLoad`]: `cosine cos(k w t) + sine sin(k w t)` (harmonic 0:
/// the constant `cosine`, `sine` zero).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadHarmonic {
    /// The harmonic `k` (0: constant).
    pub harmonic: usize,
    /// Amplitudes of `cos(k w t)` per dof.
    pub cosine: Vec<f64>,
    /// Amplitudes of `sin(k w t)` per dof (zero for `k = 0`).
    pub sine: Vec<f64>,
}

/// A periodic external force on `N` dofs, a sum of harmonics of the forcing frequency
/// (module documentation). The forcing frequency itself is an argument of each formulation.
#[derive(Debug, Clone, PartialEq)]
pub struct HarmonicLoad {
    dofs: usize,
    /// Distinct harmonics, in increasing order.
    harmonics: Vec<LoadHarmonic>,
}

impl HarmonicLoad {
    /// `f(t) = load cos(w t)` (`N` = `load.len()`), the classical forced response.
    pub fn cosine(load: Vec<f64>) -> Self {
        let dofs = load.len();
        Self {
            dofs,
            harmonics: vec![LoadHarmonic {
                harmonic: 1,
                sine: vec![0.0; dofs],
                cosine: load,
            }],
        }
    }

    /// No force on `dofs` dofs.
    pub fn zero(dofs: usize) -> Self {
        Self {
            dofs,
            harmonics: Vec::new(),
        }
    }

    /// A travelling wave on harmonic 1, `f_j(t) = amplitude_j cos(w t - phase_j)` (phases
    /// in radians; both of length `N`).
    pub fn travelling_wave(amplitude: &[f64], phase: &[f64]) -> Result<Self, InvalidModel> {
        check_length(phase.len(), amplitude.len())?;
        let mut load = Self::zero(amplitude.len());
        let cosine: Vec<f64> = amplitude
            .iter()
            .zip(phase)
            .map(|(a, p)| a * p.cos())
            .collect();
        let sine: Vec<f64> = amplitude
            .iter()
            .zip(phase)
            .map(|(a, p)| a * p.sin())
            .collect();
        load.add_harmonic(1, &cosine, &sine)?;
        Ok(load)
    }

    /// Adds `cosine cos(k w t) + sine sin(k w t)` (both of length `N`; for `k = 0` the
    /// constant `cosine` and a zero `sine`) to the load.
    pub fn add_harmonic(
        &mut self,
        harmonic: usize,
        cosine: &[f64],
        sine: &[f64],
    ) -> Result<(), InvalidModel> {
        check_length(cosine.len(), self.dofs)?;
        check_length(sine.len(), self.dofs)?;
        if let Some(dof) = sine
            .iter()
            .position(|s| *s != 0.0)
            .filter(|_| harmonic == 0)
        {
            return Err(InvalidModel::ConstantLoadSine {
                dof,
                value: sine[dof],
            });
        }
        let at = self.harmonics.partition_point(|h| h.harmonic < harmonic);
        if self
            .harmonics
            .get(at)
            .is_none_or(|h| h.harmonic != harmonic)
        {
            self.harmonics.insert(
                at,
                LoadHarmonic {
                    harmonic,
                    cosine: vec![0.0; self.dofs],
                    sine: vec![0.0; self.dofs],
                },
            );
        }
        let term = &mut self.harmonics[at];
        for (t, c) in term.cosine.iter_mut().zip(cosine) {
            *t += c;
        }
        for (t, s) in term.sine.iter_mut().zip(sine) {
            *t += s;
        }
        Ok(())
    }

    /// The engine-order excitation of a disk of `N = sector_dofs.len()` sectors: the load
    /// with the dofs of sector `s` (`sector_dofs[s]`) delayed by `s EO T / N`, harmonic `k`'s
    /// parts `(c, s)` rotated by `a = k s phi`, `phi = 2 pi EO / N`, into
    /// `(c cos a - s sin a, c sin a + s cos a)`; dofs of no sector keep their phase. A dof
    /// out of range or in two sectors is [`InvalidModel::SectorDof`].
    pub fn delayed_by_sector(
        mut self,
        sector_dofs: &[Vec<usize>],
        engine_order: usize,
    ) -> Result<Self, InvalidModel> {
        let mut sector_of = vec![None; self.dofs];
        for (s, dofs) in sector_dofs.iter().enumerate() {
            for &dof in dofs {
                match sector_of.get_mut(dof) {
                    Some(slot @ None) => *slot = Some(s),
                    _ => {
                        return Err(InvalidModel::SectorDof {
                            dof,
                            dofs: self.dofs,
                        })
                    }
                }
            }
        }
        let sectors = sector_dofs.len().max(1);
        let phi = 2.0 * std::f64::consts::PI * (engine_order % sectors) as f64 / sectors as f64;
        for h in &mut self.harmonics {
            for (dof, sector) in sector_of.iter().enumerate() {
                let angle = h.harmonic as f64 * sector.unwrap_or(0) as f64 * phi;
                let (c, s) = (h.cosine[dof], h.sine[dof]);
                h.cosine[dof] = c * angle.cos() - s * angle.sin();
                h.sine[dof] = c * angle.sin() + s * angle.cos();
            }
        }
        Ok(self)
    }

    /// The load with every part multiplied by `factor`.
    pub fn scaled(mut self, factor: f64) -> Self {
        for h in &mut self.harmonics {
            h.cosine.iter_mut().for_each(|v| *v *= factor);
            h.sine.iter_mut().for_each(|v| *v *= factor);
        }
        self
    }

    /// Number of dofs `N`.
    pub fn dofs(&self) -> usize {
        self.dofs
    }

    /// The harmonics present, in increasing order.
    pub fn harmonics(&self) -> &[LoadHarmonic] {
        &self.harmonics
    }

    /// `(cosine, sine)` of harmonic `k`, `None` when it carries no load.
    pub fn harmonic(&self, k: usize) -> Option<(&[f64], &[f64])> {
        self.harmonics
            .iter()
            .find(|h| h.harmonic == k)
            .map(|h| (h.cosine.as_slice(), h.sine.as_slice()))
    }

    /// The highest harmonic present (0 without load).
    pub fn highest_harmonic(&self) -> usize {
        self.harmonics.last().map_or(0, |h| h.harmonic)
    }

    /// The cosine part on the forcing frequency (harmonic 1; zeros without it): the whole
    /// load of [`HarmonicLoad::cosine`].
    pub fn forcing_cosine(&self) -> Vec<f64> {
        self.harmonic(1)
            .map_or_else(|| vec![0.0; self.dofs], |(c, _)| c.to_vec())
    }

    /// The load as `load cos(w t)` when it is one (every other part zero), else `None`:
    /// what a formulation that models only that load (the periodic LCP) can take.
    pub fn as_cosine(&self) -> Option<Vec<f64>> {
        let zero = |v: &[f64]| v.iter().all(|x| *x == 0.0);
        self.harmonics
            .iter()
            .all(|h| zero(&h.sine) && (h.harmonic == 1 || zero(&h.cosine)))
            .then(|| self.forcing_cosine())
    }

    /// `out[j] = f_j(t)` at phase `theta = w t` (`out` of length `N`; harmonics in
    /// increasing order, cosine then sine per harmonic).
    pub fn at_phase(&self, theta: f64, out: &mut [f64]) {
        out.fill(0.0);
        for h in &self.harmonics {
            let (s, c) = (h.harmonic as f64 * theta).sin_cos();
            for ((o, a), b) in out.iter_mut().zip(&h.cosine).zip(&h.sine) {
                *o += a * c + b * s;
            }
        }
    }

    /// `out += alpha F`: the load's real Fourier coefficients on the harmonic-major basis
    /// of `H` harmonics (`out[j N + dof]`, `j = 0` constant, `2k - 1` cosine, `2k` sine;
    /// harmonics above `H` are left out, [`HarmonicLoad::check_harmonics`] refuses them).
    pub fn add_coefficients(&self, alpha: f64, harmonics: usize, out: &mut [f64]) {
        let n = self.dofs;
        for h in self.harmonics.iter().filter(|h| h.harmonic <= harmonics) {
            let k = h.harmonic;
            let cosine = if k == 0 { 0 } else { (2 * k - 1) * n };
            for (o, f) in out[cosine..cosine + n].iter_mut().zip(&h.cosine) {
                *o += alpha * f;
            }
            if k > 0 {
                for (o, f) in out[2 * k * n..(2 * k + 1) * n].iter_mut().zip(&h.sine) {
                    *o += alpha * f;
                }
            }
        }
    }

    /// `Err` when the load has a harmonic above `harmonics` (a truncated basis cannot
    /// carry it).
    pub fn check_harmonics(&self, harmonics: usize) -> Result<(), InvalidModel> {
        match self.highest_harmonic() {
            k if k > harmonics => Err(InvalidModel::LoadHarmonic {
                harmonic: k,
                harmonics,
            }),
            _ => Ok(()),
        }
    }

    /// `Err` unless the load has `dofs` entries per part, all finite.
    pub(crate) fn validate(&self, dofs: usize) -> Result<(), InvalidModel> {
        if self.dofs != dofs {
            return Err(InvalidModel::LoadLength {
                found: self.dofs,
                dofs,
            });
        }
        for h in &self.harmonics {
            super::first_non_finite("load", &h.cosine)?;
            super::first_non_finite("load (sine part)", &h.sine)?;
        }
        Ok(())
    }
}

/// `Err(LoadLength)` unless `found == dofs`.
fn check_length(found: usize, dofs: usize) -> Result<(), InvalidModel> {
    if found == dofs {
        Ok(())
    } else {
        Err(InvalidModel::LoadLength { found, dofs })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn travelling_wave_is_a_cosine_delayed_per_dof() {
        let load = HarmonicLoad::travelling_wave(&[2.0, 1.0], &[0.0, 0.7]).unwrap();
        let mut f = [0.0; 2];
        for theta in [0.0, 0.3, 2.0] {
            load.at_phase(theta, &mut f);
            // cos(a - b) = cos a cos b + sin a sin b: equal up to a rounding or two.
            assert!((f[0] - 2.0 * f64::cos(theta)).abs() < 1e-15);
            assert!((f[1] - f64::cos(theta - 0.7)).abs() < 1e-15);
        }
        assert_eq!(load.as_cosine(), None);
    }

    #[test]
    fn cosine_load_keeps_its_vector_and_sums_added_harmonics() {
        let mut load = HarmonicLoad::cosine(vec![1.0, 2.0]);
        assert_eq!(load.as_cosine(), Some(vec![1.0, 2.0]));
        load.add_harmonic(0, &[0.5, 0.0], &[0.0, 0.0]).unwrap();
        load.add_harmonic(2, &[0.0, 0.0], &[3.0, 0.0]).unwrap();
        load.add_harmonic(2, &[0.0, 0.0], &[1.0, 0.0]).unwrap();
        assert_eq!(load.highest_harmonic(), 2);
        assert_eq!(load.harmonic(2), Some((&[0.0, 0.0][..], &[4.0, 0.0][..])));
        let mut coefficients = vec![0.0; 2 * 5];
        load.add_coefficients(1.0, 2, &mut coefficients);
        assert_eq!(
            coefficients,
            [0.5, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 4.0, 0.0]
        );
        assert!(load.check_harmonics(1).is_err());
        assert_eq!(
            load.add_harmonic(1, &[1.0], &[0.0]),
            Err(InvalidModel::LoadLength { found: 1, dofs: 2 })
        );
    }
}
