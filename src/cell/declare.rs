//! The machinery behind the declaration in `cell/mod.rs`: what one line of `dimensions!`
//! generates, and the value type every dimension shares with the outputs.

use crate::input::InputError;
use std::fmt;

/// One dimension's value in a cell, as configs, labels and tables show it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Value {
    /// A number: a mesh size, a workload index, a helper count.
    Count(usize),
    /// A named value: a mode, a method, a kernel.
    Name(&'static str),
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Count(n) => write!(f, "{n}"),
            Value::Name(s) => f.write_str(s),
        }
    }
}

/// A type a dimension's values have.
pub trait DimValue: Copy + PartialEq + Sized {
    /// The value as outputs show it.
    fn value(self) -> Value;
    /// The typed value back, when `value` is one of this type's.
    fn from_value(value: Value) -> Option<Self>;
    /// Parses a value given on the command line.
    fn parse(text: &str) -> Result<Self, InputError>;
    /// Every value, for types with a fixed set of them.
    fn names() -> Option<Vec<&'static str>> {
        None
    }
    /// Refuses a value read from a config that this program cannot run, for types whose values
    /// read back from results files are open (a kind another program registered).
    fn check_known(self) -> Result<(), InputError> {
        Ok(())
    }
}

impl DimValue for usize {
    fn value(self) -> Value {
        Value::Count(self)
    }
    fn from_value(value: Value) -> Option<Self> {
        match value {
            Value::Count(n) => Some(n),
            Value::Name(_) => None,
        }
    }
    fn parse(text: &str) -> Result<Self, InputError> {
        text.parse()
            .map_err(|_| InputError(format!("`{text}` is not a whole number >= 0")))
    }
}

/// Implements [`DimValue`] for named enums.
macro_rules! dim_values {
    ($($t:ty),+ $(,)?) => {$(
        impl $crate::cell::DimValue for $t {
            fn value(self) -> $crate::cell::Value {
                $crate::cell::Value::Name($crate::named::Named::name(self))
            }
            fn from_value(value: $crate::cell::Value) -> Option<Self> {
                match value {
                    $crate::cell::Value::Name(name) => <$t as $crate::named::Named>::parse(name).ok(),
                    $crate::cell::Value::Count(_) => None,
                }
            }
            fn parse(text: &str) -> Result<Self, $crate::input::InputError> {
                <$t as $crate::named::Named>::parse(text).map_err(|e| $crate::input::InputError(e.0))
            }
            fn names() -> Option<Vec<&'static str>> {
                Some(<$t as $crate::named::Named>::names())
            }
        }
    )+};
}
pub(crate) use dim_values;

/// How a cell stores a dimension: plainly when every cell has it, as an `Option` when serial
/// cells have none.
pub trait Slot<T>: Sized {
    /// The stored value, if the cell has one.
    fn get(&self) -> Option<T>;
    /// Stores `value`; `None` when a cell of this kind must have one.
    fn store(value: Option<T>) -> Option<Self>;
}

impl<T: Copy> Slot<T> for T {
    fn get(&self) -> Option<T> {
        Some(*self)
    }
    fn store(value: Option<T>) -> Option<Self> {
        value
    }
}

impl<T: Copy> Slot<T> for Option<T> {
    fn get(&self) -> Option<T> {
        *self
    }
    fn store(value: Option<T>) -> Option<Self> {
        Some(value)
    }
}

/// A dimension's field type: `all` cells have it, `threaded` ones only (serial has no helper).
macro_rules! field_type {
    (all, $t:ty) => { $t };
    (threaded, $t:ty) => { Option<$t> };
}
pub(crate) use field_type;

/// `Some(value)` for a declared quiet value, `None` without one.
macro_rules! optional {
    () => {
        None
    };
    ($e:expr) => {
        Some($e)
    };
}
pub(crate) use optional;

/// A value's per-dimension check: the declared function, or none.
macro_rules! check_fn {
    () => {
        |_| Ok(())
    };
    ($f:path) => {
        $f
    };
}
pub(crate) use check_fn;

/// Declares the study's dimensions; see `cell/mod.rs` for the one invocation and what each part
/// of a line means.
macro_rules! dimensions {
    ($(
        $(#[doc = $doc:literal])+
        $variant:ident($field:ident: $ty:ty) {
            config: $key:ident = [$($default:expr),+ $(,)?],
            cells: $scope:ident,
            row: $row:literal,
            label: $label:literal,
            title: $title:literal
            $(, title_one: $title_one:literal)?
            $(, quiet: $quiet:expr)?
            $(, check: $check:path)?
            $(,)?
        }
    )+) => {
        $crate::named! {
            case = "snake_case";
            /// A swept dimension of the study.
            pub enum Dim {
                $($(#[doc = $doc])+ $variant,)+
            }
        }

        impl Dim {
            /// Every dimension, in the order labels and tables show them.
            pub const ALL: &'static [Dim] = &[$(Dim::$variant),+];

            /// The config key listing this dimension's values.
            pub fn config_key(self) -> &'static str {
                match self { $(Dim::$variant => stringify!($key),)+ }
            }

            /// False when serial cells have no value (they have no helper to hand off to).
            pub fn in_serial_cells(self) -> bool {
                match self { $(Dim::$variant => stringify!($scope) == "all",)+ }
            }

            /// True when the dimension defines a row: a row's cells differ only in the other
            /// dimensions, and their trials run interleaved.
            pub fn row(self) -> bool {
                match self { $(Dim::$variant => $row,)+ }
            }

            /// The value labels leave out (a dimension added after the paper, at the paper's
            /// setting); `None` when every value is shown.
            pub fn quiet(self) -> Option<Value> {
                match self {
                    $(Dim::$variant => $crate::cell::declare::optional!($($quiet)?)
                        .map(<$ty as $crate::cell::DimValue>::value),)+
                }
            }

            /// The value's part of a cell label, e.g. `w2`.
            pub fn label(self, value: Value) -> String {
                match self { $(Dim::$variant => format!($label, value),)+ }
            }

            /// The value as a table heading names it, e.g. `atomic hand-off`, `1 helper`.
            pub fn title(self, value: Value) -> String {
                match self {
                    $(Dim::$variant => {
                        // A count of one takes the singular form, where the noun has one.
                        $(if value == Value::Count(1) {
                            return format!($title_one, value);
                        })?
                        format!($title, value)
                    })+
                }
            }

            /// Every value the dimension can take, when they are a fixed set of names.
            pub fn names(self) -> Option<Vec<&'static str>> {
                match self { $(Dim::$variant => <$ty as $crate::cell::DimValue>::names(),)+ }
            }

            /// Parses one of this dimension's values, as given on the command line.
            pub fn parse_value(self, text: &str) -> Result<Value, $crate::input::InputError> {
                match self {
                    $(Dim::$variant => <$ty as $crate::cell::DimValue>::parse(text)
                        .map($crate::cell::DimValue::value),)+
                }
            }
        }

        /// The parameters that identify a cell: one field per dimension.
        #[derive(Clone, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
        #[serde(try_from = "StoredKey")]
        pub struct CellKey {
            $($(#[doc = $doc])+ pub $field: $crate::cell::declare::field_type!($scope, $ty),)+
        }

        /// A key as a results file stores it; dimensions that file predates are absent.
        #[derive(serde::Deserialize)]
        struct StoredKey {
            $(#[serde(default)] $field: Option<$ty>,)+
        }

        impl TryFrom<StoredKey> for CellKey {
            type Error = $crate::input::InputError;
            fn try_from(stored: StoredKey) -> Result<CellKey, $crate::input::InputError> {
                CellKey::from_fn(|dim| match dim {
                    $(Dim::$variant => stored.$field.map($crate::cell::DimValue::value),)+
                })
            }
        }

        impl CellKey {
            /// This cell's value of `dim`; `None` for a serial cell's hand-off dimensions.
            pub fn get(&self, dim: Dim) -> Option<Value> {
                match dim {
                    $(Dim::$variant => <$crate::cell::declare::field_type!($scope, $ty)
                        as $crate::cell::declare::Slot<$ty>>::get(&self.$field)
                        .map($crate::cell::DimValue::value),)+
                }
            }

            /// Builds a key from each dimension's value; serial cells drop the hand-off
            /// dimensions and an absent value takes the dimension's quiet value.
            pub fn from_fn(
                mut value: impl FnMut(Dim) -> Option<Value>,
            ) -> Result<CellKey, $crate::input::InputError> {
                let serial = $crate::cell::is_serial(value(Dim::Mode));
                let mut resolve = |dim: Dim| -> Result<Option<Value>, $crate::input::InputError> {
                    if serial && !dim.in_serial_cells() {
                        return Ok(None);
                    }
                    value(dim)
                        .or(dim.quiet())
                        .map(Some)
                        .ok_or_else(|| $crate::input::InputError(
                            format!("missing field `{}`", $crate::named::Named::name(dim))))
                };
                Ok(CellKey {
                    $($field: {
                        let typed = match resolve(Dim::$variant)? {
                            Some(v) => Some(<$ty as $crate::cell::DimValue>::from_value(v).ok_or_else(|| {
                                $crate::input::InputError(format!(
                                    "{}: `{v}` is not a value of this dimension", stringify!($field)))
                            })?),
                            None => None,
                        };
                        <$crate::cell::declare::field_type!($scope, $ty)
                            as $crate::cell::declare::Slot<$ty>>::store(typed)
                            .expect("only serial cells lack a value, and only where the field is optional")
                    },)+
                })
            }
        }

        /// The lists a sweep crosses, one per dimension, under their config keys.
        #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(default)]
        pub struct Axes {
            $($(#[doc = $doc])+ pub $key: Vec<$ty>,)+
        }

        impl Default for Axes {
            fn default() -> Self {
                Axes { $($key: vec![$($default),+],)+ }
            }
        }

        impl Axes {
            /// The listed values of `dim`, in config order.
            pub fn values(&self, dim: Dim) -> Vec<Value> {
                match dim {
                    $(Dim::$variant => self.$key.iter().map(|v| $crate::cell::DimValue::value(*v)).collect(),)+
                }
            }

            /// Replaces the list of `dim` with `values`; an error names a value of another
            /// dimension.
            pub fn set(&mut self, dim: Dim, values: &[Value]) -> Result<(), $crate::input::InputError> {
                match dim {
                    $(Dim::$variant => {
                        self.$key = values
                            .iter()
                            .map(|&v| <$ty as $crate::cell::DimValue>::from_value(v)
                                .ok_or_else(|| $crate::input::InputError(format!(
                                    "{}: `{v}` is not a value of this dimension", stringify!($key)))))
                            .collect::<Result<_, _>>()?;
                    })+
                }
                Ok(())
            }

            /// Parses one config key's list alone, so an error names its place
            /// (`modes[1]: ...`); `None` when `key` is no dimension's.
            pub fn parse_key(
                key: &str,
                list: serde_json::Value,
            ) -> Option<Result<(), $crate::input::InputError>> {
                $(if key == stringify!($key) {
                    return Some(serde_path_to_error::deserialize::<_, Vec<$ty>>(list)
                        .map_err(|e| {
                            let at = e.path().to_string();
                            let msg = e.into_inner().to_string();
                            $crate::input::InputError(format!("{key}{}: {msg}", at.trim_start_matches('.')))
                        })
                        .and_then(|values| {
                            values.into_iter().enumerate().try_for_each(|(i, v)| {
                                $crate::cell::DimValue::check_known(v).map_err(|e| {
                                    $crate::input::InputError(format!("{key}[{i}]: {e}"))
                                })
                            })
                        }));
                })+
                None
            }

            /// Every list has a value, no value twice, and each passes its dimension's check.
            pub fn check(&self) -> Result<(), $crate::input::InputError> {
                $(
                    $crate::cell::check_list(stringify!($key), &self.$key,
                        $crate::cell::declare::check_fn!($($check)?))?;
                )+
                Ok(())
            }
        }
    };
}
pub(crate) use dimensions;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{CellKey, Dim, Mode, Threading};
    use crate::ocean::{Kernel, NormalMethod};
    use crate::sync::SyncMethod;

    /// The dimensions without a quiet value, at the paper's settings.
    fn loud(dim: Dim) -> Option<Value> {
        match dim {
            Dim::Threading => Some(Threading::Pool.value()),
            Dim::Normals => Some(NormalMethod::Neighbors.value()),
            Dim::Kernel => Some(Kernel::Reference.value()),
            _ => None,
        }
    }

    #[test]
    fn a_count_round_trips_and_has_no_fixed_names() {
        assert_eq!(<usize as DimValue>::from_value(Value::Count(96)), Some(96));
        assert_eq!(<usize as DimValue>::from_value(Value::Name("dp")), None);
        assert_eq!(<usize as DimValue>::parse("96"), Ok(96));
        let err = <usize as DimValue>::parse("-1").unwrap_err().0;
        assert_eq!(err, "`-1` is not a whole number >= 0");
        assert_eq!(<usize as DimValue>::names(), None);
        assert_eq!(Dim::Size.names(), None, "any size may be asked for");
        let modes = Dim::Mode.names().expect("modes are a fixed set");
        assert!(
            modes.contains(&"dp") && modes.contains(&"serial"),
            "{modes:?}"
        );
    }

    #[test]
    fn a_slot_keeps_what_it_stores() {
        assert_eq!(<usize as Slot<usize>>::get(&40), Some(40));
        assert_eq!(<usize as Slot<usize>>::store(Some(40)), Some(40));
        assert_eq!(
            <usize as Slot<usize>>::store(None),
            None,
            "a plain field needs a value"
        );
        assert_eq!(<Option<usize> as Slot<usize>>::get(&Some(2)), Some(2));
        assert_eq!(<Option<usize> as Slot<usize>>::get(&None), None);
        assert_eq!(
            <Option<usize> as Slot<usize>>::store(Some(2)),
            Some(Some(2))
        );
        assert_eq!(<Option<usize> as Slot<usize>>::store(None), Some(None));
    }

    #[test]
    fn a_key_gives_back_each_dimension_it_was_built_from() {
        let dp = CellKey::from_fn(|dim| match dim {
            Dim::Size => Some(Value::Count(96)),
            Dim::Workload => Some(Value::Count(2)),
            Dim::Mode => Some(Mode::Dp.value()),
            Dim::Sync => Some(SyncMethod::Condvar.value()),
            other => loud(other),
        })
        .expect("every other dimension has a quiet value");
        assert_eq!(dp.get(Dim::Size), Some(Value::Count(96)));
        assert_eq!(dp.get(Dim::Workload), Some(Value::Count(2)));
        assert_eq!(dp.get(Dim::Sync), Some(Value::Name("condvar")));
        assert_eq!(dp.sync, Some(SyncMethod::Condvar));
        let serial = CellKey::from_fn(|dim| match dim {
            Dim::Size => Some(Value::Count(40)),
            Dim::Workload => Some(Value::Count(0)),
            Dim::Mode => Some(Mode::Serial.value()),
            Dim::Sync => Some(SyncMethod::Condvar.value()),
            other => loud(other),
        })
        .expect("serial keys drop the hand-off");
        assert_eq!(serial.get(Dim::Sync), None, "a serial cell has no hand-off");
        assert_eq!(serial.get(Dim::Size), Some(Value::Count(40)));
    }
}
