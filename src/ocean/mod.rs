//! The ocean surface: the grid mesh every model fills, the [`Model`] seam, and the models behind
//! it, one folder each (`sines/`: the paper's sum of sines; `fft/`: Tessendorf's FFT ocean), and
//! the registry that names them (`kind.rs`). `row_line.rs` is the one thing the projected grid's
//! placement tells a model about the mesh it placed: which rows lie evenly spaced on a line.

pub mod fft;
mod kind;
pub mod mesh;
pub mod model;
pub mod normals;
pub mod phillips;
pub mod row_line;
pub mod shared_mesh;
pub mod sines;
pub mod waves;

pub use fft::FftOcean;
pub use kind::{lookup, models, names, register, OceanKind, Unregistered};
pub use mesh::{Grid, Mesh, MeshRows};
pub use model::{GridKind, Kernel, Model, OceanParams, Stepper};
pub use normals::NormalMethod;
pub use phillips::FftParams;
pub use row_line::{RowLine, RowLines};
pub use shared_mesh::SharedMesh;
pub use waves::{Wave, WaveSet};
