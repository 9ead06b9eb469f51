//! Names of enum values from one source. Each named enum derives strum's `IntoStaticStr` (its
//! names), `VariantArray` (its values in order) and `EnumMessage` (its doc comments); `named!`
//! builds serde, clap and `Display` on top of them, so configs, flags, results files and tables
//! can never spell a value two ways.

use crate::suggest;
use strum::{EnumMessage, VariantArray};

/// An enum whose values are known by name in configs, flags and results.
pub trait Named:
    Copy + PartialEq + 'static + VariantArray + Into<&'static str> + EnumMessage
{
    /// The value's name.
    fn name(self) -> &'static str {
        self.into()
    }

    /// Every value's name, in declaration order.
    fn names() -> Vec<&'static str> {
        Self::VARIANTS.iter().map(|v| v.name()).collect()
    }

    /// The value called `text`, or an error listing the names (with the closest one).
    fn parse(text: &str) -> Result<Self, UnknownName> {
        Self::VARIANTS
            .iter()
            .copied()
            .find(|v| v.name() == text)
            .ok_or_else(|| UnknownName(suggest::unknown("value", text, &Self::names())))
    }

    /// The value's doc comment, for `--help`.
    fn doc(self) -> Option<&'static str> {
        self.get_documentation().map(str::trim)
    }
}

impl<T> Named for T where
    T: Copy + PartialEq + 'static + VariantArray + Into<&'static str> + EnumMessage
{
}

/// A name that is not one of the enum's values; the message lists them.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct UnknownName(pub String);

/// Implements `name()`, `Serialize`, `Deserialize`, `Display` and `clap::ValueEnum` from the
/// enum's strum names.
#[macro_export]
macro_rules! named {
    ($($t:ty),+ $(,)?) => {$(
        impl $t {
            /// The value's name in configs, flags, results and tables.
            pub fn name(self) -> &'static str {
                self.into()
            }
        }

        impl ::std::fmt::Display for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::named::Named::name(*self))
            }
        }

        impl ::serde::Serialize for $t {
            fn serialize<S: ::serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str($crate::named::Named::name(*self))
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $t {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <String as ::serde::Deserialize>::deserialize(d)?;
                <$t as $crate::named::Named>::parse(&text).map_err(::serde::de::Error::custom)
            }
        }

        impl ::clap::ValueEnum for $t {
            fn value_variants<'a>() -> &'a [Self] {
                <$t as ::strum::VariantArray>::VARIANTS
            }

            fn to_possible_value(&self) -> Option<::clap::builder::PossibleValue> {
                let value = ::clap::builder::PossibleValue::new($crate::named::Named::name(*self));
                Some(match $crate::named::Named::doc(*self) {
                    Some(doc) => value.help(doc),
                    None => value,
                })
            }
        }
    )+};
}
