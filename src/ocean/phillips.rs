//! The FFT ocean's parameters file and the equations of its spectrum (Tessendorf, "Simulating
//! Ocean Water", 2001): the Phillips spectrum and the dispersion relation, in f64.

use crate::input::InputError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The parameters of the FFT ocean, as a parameters file (`fft_params`) spells them.
/// Defaults: [`FftParams::default`], also written out in `configs/fft-ocean.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FftParams {
    /// Free text: where the values come from.
    pub description: String,
    /// Side L of the square patch the N×N grid covers, in metres; the vertex spacing is L ÷ N.
    pub patch_metres: f64,
    /// Wind speed V in m/s, which sets the largest waves (L_w = V²/g).
    pub wind_speed: f64,
    /// Direction the wind blows towards, in degrees from +x towards +y.
    pub wind_direction_degrees: f64,
    /// The Phillips constant A.
    pub amplitude: f64,
    /// Waves shorter than about this many metres are damped by exp(−k²l²).
    pub cutoff_metres: f64,
    /// λ: how far the choppy displacement moves vertices (0: none, 1: Gerstner's).
    pub choppiness: f64,
    /// g in m/s².
    pub gravity: f64,
    /// Water depth in metres for the finite-depth dispersion relation; deep water when absent.
    pub depth_metres: Option<f64>,
    /// Seed of the Gaussian draws that sample the spectrum once per run.
    pub seed: u64,
}

impl Default for FftParams {
    /// A fully developed sea under a 20 m/s wind on a 1 km patch. The amplitude makes the
    /// spectrum's variance, 2 · A · L² · L_w² / (8π) for the continuous spectrum (the factor 2:
    /// h̃ holds h̃₀(k) and h̃₀(−k)), equal to that of the Pierson-Moskowitz sea for the same
    /// wind, whose significant wave height is 0.21 V²/g = 8.6 m.
    fn default() -> Self {
        FftParams {
            description: String::new(),
            patch_metres: 1000.0,
            wind_speed: 20.0,
            wind_direction_degrees: 0.0,
            amplitude: 3.5e-8,
            cutoff_metres: 0.1,
            choppiness: 1.0,
            gravity: 9.81,
            depth_metres: None,
            seed: 1,
        }
    }
}

impl FftParams {
    /// Reads and checks a parameters file; every error names the file and the field.
    pub fn load(path: &Path) -> Result<Self, InputError> {
        let in_file =
            |problem: String| InputError(format!("fft_params file {}: {problem}", path.display()));
        let text = std::fs::read_to_string(path).map_err(|e| in_file(e.to_string()))?;
        Self::from_json(&text).map_err(|e| in_file(e.0))
    }

    /// Parses and checks a parameters file's text.
    pub fn from_json(text: &str) -> Result<Self, InputError> {
        let mut de = serde_json::Deserializer::from_str(text);
        let params: FftParams = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let path = e.path().to_string();
            let msg = crate::suggest::with_suggestion(&e.into_inner().to_string());
            match path.as_str() {
                "." | "" => InputError(msg),
                _ => InputError(format!("{path}: {msg}")),
            }
        })?;
        de.end()
            .map_err(|e| InputError(format!("not valid JSON: {e}")))?;
        params.validate()?;
        Ok(params)
    }

    /// Checks every value's range, naming the field and what is allowed.
    pub fn validate(&self) -> Result<(), InputError> {
        let at_least_zero = [
            ("wind_speed", self.wind_speed),
            ("amplitude", self.amplitude),
            ("cutoff_metres", self.cutoff_metres),
            ("choppiness", self.choppiness),
        ];
        let above_zero = [
            ("patch_metres", Some(self.patch_metres)),
            ("gravity", Some(self.gravity)),
            ("depth_metres", self.depth_metres),
        ];
        for (field, v) in at_least_zero {
            if !(v.is_finite() && v >= 0.0) {
                return Err(InputError(format!(
                    "{field}: must be a finite number >= 0, got {v}"
                )));
            }
        }
        for (field, v) in above_zero {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(InputError(format!(
                    "{field}: must be a finite number > 0, got {v}"
                )));
            }
        }
        if !self.wind_direction_degrees.is_finite() {
            return Err(InputError(format!(
                "wind_direction_degrees: must be a finite number, got {}",
                self.wind_direction_degrees
            )));
        }
        Ok(())
    }

    /// The Phillips spectrum P(k) = A · exp(−1/(k L_w)²) / k⁴ · (k̂·ŵ)² · exp(−k² l²) at the
    /// wave vector (kx, ky) in rad/m; 0 at k = 0.
    pub fn phillips(&self, kx: f64, ky: f64) -> f64 {
        let k2 = kx * kx + ky * ky;
        if k2 == 0.0 {
            return 0.0;
        }
        let largest = self.wind_speed * self.wind_speed / self.gravity;
        let (wy, wx) = self.wind_direction_degrees.to_radians().sin_cos();
        let along_wind = (kx * wx + ky * wy) * (kx * wx + ky * wy) / k2;
        let l2 = self.cutoff_metres * self.cutoff_metres;
        self.amplitude * (-1.0 / (k2 * largest * largest)).exp() / (k2 * k2)
            * along_wind
            * (-k2 * l2).exp()
    }

    /// The dispersion relation ω(k) = √(g k), or √(g k tanh(k d)) at depth d, in rad/s.
    pub fn omega(&self, k: f64) -> f64 {
        match self.depth_metres {
            Some(d) => (self.gravity * k * (k * d).tanh()).sqrt(),
            None => (self.gravity * k).sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_file_holds_the_defaults() {
        let text = include_str!("../../configs/fft-ocean.json");
        let file = FftParams::from_json(text).unwrap();
        assert_eq!(
            FftParams {
                description: String::new(),
                ..file
            },
            FftParams::default()
        );
    }

    #[test]
    fn deep_and_shallow_water_agree_where_the_water_is_deep() {
        let deep = FftParams::default();
        let shallow = FftParams {
            depth_metres: Some(10.0),
            ..FftParams::default()
        };
        let k = 2.0 * std::f64::consts::PI / 100.0;
        assert_eq!(deep.omega(k), (9.81 * k).sqrt());
        assert!(shallow.omega(k) < deep.omega(k), "shallow water is slower");
        let long = FftParams {
            depth_metres: Some(1e4),
            ..FftParams::default()
        };
        assert!((long.omega(k) - deep.omega(k)).abs() < 1e-12);
    }

    #[test]
    fn the_spectrum_has_no_waves_across_the_wind() {
        let p = FftParams::default();
        assert_eq!(p.phillips(0.0, 0.05), 0.0);
        assert!(p.phillips(0.05, 0.0) > 0.0);
        assert_eq!(p.phillips(0.0, 0.0), 0.0);
    }
}
