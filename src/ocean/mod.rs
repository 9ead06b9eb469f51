//! The ocean surface: the grid mesh every model fills, the [`Model`] seam, and the models behind
//! it, one folder each (`sines/`: the paper's sum of sines; `fft/`: Tessendorf's FFT ocean).

pub mod fft;
pub mod mesh;
pub mod model;
pub mod normals;
pub mod phillips;
pub mod sines;
pub mod waves;

pub use fft::FftOcean;
pub use mesh::{Grid, Mesh, MeshRows};
pub use model::{GridKind, Kernel, Model, OceanParams, Stepper};
pub use normals::NormalMethod;
pub use phillips::FftParams;
pub use waves::{Wave, WaveSet};

crate::named! {
    /// Which model the helper computes each frame.
    pub enum OceanKind {
        /// The paper's sum of four sine waves with exponent.
        Sines,
        /// Tessendorf's FFT ocean: a Phillips spectrum, choppy displacement and folds.
        Fft,
    }
}

impl OceanKind {
    /// The model behind this value: the one place a new model is wired in.
    pub fn model(self) -> &'static dyn Model {
        match self {
            OceanKind::Sines => &sines::Sines,
            OceanKind::Fft => &fft::FftOcean,
        }
    }
}
