//! Which ocean model a cell runs, by name, and the registry of models: the built-in ones are
//! always there, and a library user adds more with [`register`] before parsing a config, which
//! then names them like built-in ones.

use super::mesh::Grid;
use super::model::{Kernel, Model, OceanParams, Stepper};
use super::normals::NormalMethod;
use crate::input::InputError;
use crate::registry::{Entry, Registry};
use crate::suggest;

/// An ocean model's name, as configs, cells and results give it. Any name reads back from a
/// results file (one written by a binary that registered more models); configs and flags accept
/// only registered ones.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct OceanKind(&'static str);

impl OceanKind {
    /// The paper's sum of four sine waves with exponent.
    pub const SINES: OceanKind = OceanKind("sines");
    /// Tessendorf's FFT ocean: a Phillips spectrum, choppy displacement and folds.
    pub const FFT: OceanKind = OceanKind("fft");

    /// The model called `name`, registered or not (results name models other binaries ran).
    pub fn named(name: &str) -> OceanKind {
        OceanKind(MODELS.intern(name))
    }

    /// The registered model called `text`, or an error listing the registered ones.
    pub fn parse(text: &str) -> Result<OceanKind, InputError> {
        lookup(text)
            .map(|m| OceanKind(m.name()))
            .ok_or_else(|| InputError(suggest::unknown("value", text, &names())))
    }

    /// The model's name.
    pub fn name(self) -> &'static str {
        self.0
    }

    /// The model behind this name; one this program never registered refuses every cell
    /// ([`Unregistered`]).
    pub fn model(self) -> &'static dyn Model {
        lookup(self.0).unwrap_or(&Unregistered)
    }
}

crate::registered_name!(OceanKind);

/// The model of a name this program never registered: it offers nothing and runs nothing, so
/// a cell naming it is refused with the registered models listed.
pub struct Unregistered;

impl Unregistered {
    fn refuse() -> InputError {
        InputError(format!(
            "ocean: not a model this program registered (registered: {})",
            names().join(", ")
        ))
    }
}

impl Model for Unregistered {
    fn name(&self) -> &'static str {
        "unregistered"
    }
    fn kernels(&self) -> &'static [Kernel] {
        &[]
    }
    fn normals(&self) -> &'static [NormalMethod] {
        &[]
    }
    fn splits_into_rows(&self, _: NormalMethod) -> Result<(), InputError> {
        Err(Unregistered::refuse())
    }
    fn check(&self, _: usize, _: NormalMethod) -> Result<(), InputError> {
        Err(Unregistered::refuse())
    }
    fn yardstick(&self) -> (Kernel, NormalMethod) {
        (Kernel::Reference, NormalMethod::Analytic)
    }
    fn prepare(
        &self,
        _: Grid,
        _: &OceanParams,
        _: NormalMethod,
        _: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        Err(Unregistered::refuse())
    }
}

impl Entry for dyn Model {
    fn entry_name(&self) -> &'static str {
        self.name()
    }
}

/// The built-in models, in the order `--help` lists them, then the registered ones.
static MODELS: Registry<dyn Model> = Registry::new(
    "ocean model",
    &[&super::sines::Sines, &super::fft::FftOcean],
);

/// Registers a model for this process: configs, flags and sweeps then know it by name. Refuses
/// a name already taken.
pub fn register<M: Model + 'static>(model: M) -> Result<OceanKind, InputError> {
    MODELS.register(Box::leak(Box::new(model))).map(OceanKind)
}

/// Every registered model, the built-in ones first.
pub fn models() -> Vec<&'static dyn Model> {
    MODELS.all()
}

/// The registered model called `name`.
pub fn lookup(name: &str) -> Option<&'static dyn Model> {
    MODELS.lookup(name)
}

/// Every registered model's name.
pub fn names() -> Vec<&'static str> {
    MODELS.names()
}
