//! The paper's sum of sines with exponent (sections 3.2-3.5): wave parameters, validation and the
//! scalar height and slope of one point, written straight from the equations.

use serde::{Deserialize, Serialize};
use std::f32::consts::PI;
use std::path::Path;

/// The most waves a set may hold.
pub const MAX_WAVES: usize = 16;

/// The least steepness exponent a wave takes.
pub const MIN_STEEPNESS: f32 = 1.0;

/// One sine wave with exponent, as a waves file spells it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wave {
    /// Height scale A of the wave (world units).
    pub amplitude: f32,
    /// Distance L between two crests (world units, > 0).
    pub wavelength: f32,
    /// Phase speed (world units per second).
    pub speed: f32,
    /// Direction of travel in the x-y plane; normalised by the program.
    pub direction: [f32; 2],
    /// The exponent k applied to (sin S + 1)/2 (>= 1).
    pub steepness: f32,
    /// Whether the wave takes part in the sum.
    #[serde(default = "enabled_default")]
    pub enabled: bool,
}

fn enabled_default() -> bool {
    true
}

/// Errors in a waves file or wave set, each naming the wave and the field.
#[derive(Debug, thiserror::Error)]
pub enum WaveError {
    /// A field has a value outside what is allowed.
    #[error("waves[{index}].{field}: {problem}")]
    Invalid {
        /// Position of the wave in the file, from 0.
        index: usize,
        /// Name of the offending field.
        field: &'static str,
        /// What is wrong and what is allowed.
        problem: String,
    },
    /// A wave object does not parse (unknown field, wrong type, missing field).
    #[error("waves[{index}]: {message}")]
    Parse {
        /// Position of the wave in the file, from 0.
        index: usize,
        /// serde's description of the problem.
        message: String,
    },
    /// The set as a whole is wrong (file shape, number of waves).
    #[error("{0}")]
    Set(String),
    /// A waves file could not be read or is wrong; names the file.
    #[error("waves file {}: {problem}", path.display())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong, reading or in the file.
        problem: String,
    },
}

impl Wave {
    /// Checks the wave's values; `index` names it in the error.
    pub fn validate(&self, index: usize) -> Result<(), WaveError> {
        let bad = |field: &'static str, problem: String| WaveError::Invalid {
            index,
            field,
            problem,
        };
        for (field, v) in [
            ("amplitude", self.amplitude),
            ("wavelength", self.wavelength),
            ("speed", self.speed),
            ("steepness", self.steepness),
        ] {
            if !v.is_finite() {
                return Err(bad(field, format!("must be a finite number, got {v}")));
            }
        }
        if self.direction.iter().any(|d| !d.is_finite()) {
            return Err(bad(
                "direction",
                format!("must be two finite numbers, got {:?}", self.direction),
            ));
        }
        if self.wavelength <= 0.0 {
            return Err(bad(
                "wavelength",
                format!("must be > 0, got {}", self.wavelength),
            ));
        }
        if self.steepness < MIN_STEEPNESS {
            return Err(bad(
                "steepness",
                format!("must be >= {MIN_STEEPNESS}, got {}", self.steepness),
            ));
        }
        let [dx, dy] = self.direction;
        if (dx * dx + dy * dy).sqrt() == 0.0 || !(dx * dx + dy * dy).is_normal() {
            return Err(bad(
                "direction",
                format!("must be a non-zero vector, got {:?}", self.direction),
            ));
        }
        Ok(())
    }

    /// The direction scaled to unit length.
    pub fn unit_direction(&self) -> [f32; 2] {
        let [dx, dy] = self.direction;
        let len = (dx * dx + dy * dy).sqrt();
        [dx / len, dy / len]
    }

    /// Angular frequency 2π/L.
    pub fn frequency(&self) -> f32 {
        2.0 * PI / self.wavelength
    }

    /// Phase constant φ = speed · 2π/L.
    pub fn phase_constant(&self) -> f32 {
        self.speed * self.frequency()
    }
}

/// A validated set of 1 to 16 waves.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WaveSet {
    /// The waves in file order.
    pub waves: Vec<Wave>,
}

/// Deep-water phase speed c = sqrt(g·L / 2π) for a wavelength L in metres.
fn deep_water_speed(wavelength: f32) -> f32 {
    (9.81 * wavelength / (2.0 * PI)).sqrt()
}

impl Default for WaveSet {
    /// A long-crested deep-ocean swell: four waves whose speeds follow the deep-water dispersion
    /// relation, wavelengths spread over a factor of four, directions within 40° of the wind and
    /// amplitudes about 1/60 of the wavelength so no crest is steeper than real swell.
    fn default() -> Self {
        let wave = |amplitude: f32, wavelength: f32, direction: [f32; 2], steepness: f32| Wave {
            amplitude,
            wavelength,
            speed: deep_water_speed(wavelength),
            direction,
            steepness,
            enabled: true,
        };
        WaveSet {
            waves: vec![
                wave(1.0, 60.0, [1.0, 0.1], 2.0),
                wave(0.5, 31.0, [0.8, 0.6], 2.0),
                wave(0.3, 18.0, [0.9, -0.45], 2.5),
                wave(0.2, 14.0, [0.6, 0.8], 3.0),
            ],
        }
    }
}

impl WaveSet {
    /// Builds a set after checking every wave and the count.
    pub fn new(waves: Vec<Wave>) -> Result<Self, WaveError> {
        if waves.is_empty() || waves.len() > MAX_WAVES {
            return Err(WaveError::Set(format!(
                "waves: must hold 1 to {MAX_WAVES} waves, got {}",
                waves.len()
            )));
        }
        for (i, w) in waves.iter().enumerate() {
            w.validate(i)?;
        }
        Ok(WaveSet { waves })
    }

    /// Parses a waves file's JSON text: `{"waves": [ ... ]}`.
    pub fn from_json(text: &str) -> Result<Self, WaveError> {
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| WaveError::Set(format!("waves file is not valid JSON: {e}")))?;
        let obj = value.as_object().ok_or_else(|| {
            WaveError::Set("waves file: must be an object {\"waves\": [...]}".into())
        })?;
        if let Some(key) = obj.keys().find(|k| k.as_str() != "waves") {
            return Err(WaveError::Set(format!(
                "waves file: unknown field `{key}`, expected `waves`"
            )));
        }
        let list = obj
            .get("waves")
            .and_then(|w| w.as_array())
            .ok_or_else(|| WaveError::Set("waves: must be a list of wave objects".into()))?;
        Self::from_values(list)
    }

    /// Parses and checks a list of JSON wave objects (also used by configs that embed waves).
    pub fn from_values(list: &[serde_json::Value]) -> Result<Self, WaveError> {
        let waves = list
            .iter()
            .enumerate()
            .map(|(index, v)| {
                Wave::deserialize(v).map_err(|e| WaveError::Parse {
                    index,
                    message: crate::suggest::with_suggestion(&e.to_string()),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::new(waves)
    }

    /// Reads a waves file.
    pub fn load(path: &Path) -> Result<Self, WaveError> {
        let file = |problem: String| WaveError::File {
            path: path.to_path_buf(),
            problem,
        };
        let text = std::fs::read_to_string(path).map_err(|e| file(e.to_string()))?;
        Self::from_json(&text).map_err(|e| file(e.to_string()))
    }

    /// Height f(x, y, t) = Σ A·((sin S + 1)/2)^k, evaluated in f64 for use as an oracle.
    pub fn height_f64(&self, x: f64, y: f64, t: f64) -> f64 {
        self.enabled()
            .map(|w| {
                let s = phase_f64(w, x, y, t);
                w.amplitude as f64 * ((s.sin() + 1.0) / 2.0).powf(w.steepness as f64)
            })
            .sum()
    }

    /// Partial derivatives (∂f/∂x, ∂f/∂y) of section 3.5, evaluated in f64.
    pub fn slope_f64(&self, x: f64, y: f64, t: f64) -> (f64, f64) {
        self.enabled().fold((0.0, 0.0), |(sx, sy), w| {
            let s = phase_f64(w, x, y, t);
            let [dx, dy] = w.unit_direction();
            let k = w.steepness as f64;
            let common = 0.5
                * k
                * (w.frequency() as f64)
                * w.amplitude as f64
                * ((s.sin() + 1.0) / 2.0).powf(k - 1.0)
                * s.cos();
            (sx + common * dx as f64, sy + common * dy as f64)
        })
    }

    /// Unit normal (−∂f/∂x, −∂f/∂y, 1)/‖·‖ evaluated in f64.
    pub fn normal_f64(&self, x: f64, y: f64, t: f64) -> [f64; 3] {
        let (sx, sy) = self.slope_f64(x, y, t);
        let len = (sx * sx + sy * sy + 1.0).sqrt();
        [-sx / len, -sy / len, 1.0 / len]
    }

    /// The waves that take part in the sum.
    pub fn enabled(&self) -> impl Iterator<Item = &Wave> {
        self.waves.iter().filter(|w| w.enabled)
    }
}

/// S = (D·P)·2π/L + t·speed·2π/L in f64, with D normalised.
fn phase_f64(w: &Wave, x: f64, y: f64, t: f64) -> f64 {
    let [dx, dy] = w.unit_direction();
    let freq = 2.0 * std::f64::consts::PI / w.wavelength as f64;
    (dx as f64 * x + dy as f64 * y) * freq + t * w.speed as f64 * freq
}
