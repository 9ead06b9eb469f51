//! Names of enum values from one source. A named enum is declared through `named!`, which
//! derives strum's `IntoStaticStr` (its names), `VariantArray` (its values in order) and
//! `EnumMessage` (its doc comments) and builds serde, clap and `Display` on top of them, so
//! configs, flags, results files and tables can never spell a value two ways.

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

/// Declares a named enum: derives its names, values and docs from strum (kebab-case names unless
/// a `case` is given) and implements `name()`, `Serialize`, `Deserialize`, `Display` and
/// `clap::ValueEnum` from them.
#[macro_export]
macro_rules! named {
    (case = $case:literal; $(#[$attr:meta])* $vis:vis enum $name:ident {
        $($(#[$vattr:meta])* $variant:ident),+ $(,)?
    }) => {
        $(#[$attr])*
        #[derive(
            Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord,
            strum::IntoStaticStr, strum::VariantArray, strum::EnumMessage,
        )]
        #[strum(serialize_all = $case)]
        $vis enum $name {
            $($(#[$vattr])* $variant,)+
        }

        impl $name {
            /// The value's name in configs, flags, results and tables.
            pub fn name(self) -> &'static str {
                self.into()
            }
        }

        impl ::std::fmt::Display for $name {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::serde::Serialize for $name {
            fn serialize<S: ::serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $name {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <String as ::serde::Deserialize>::deserialize(d)?;
                <$name as $crate::named::Named>::parse(&text).map_err(::serde::de::Error::custom)
            }
        }

        impl ::clap::ValueEnum for $name {
            fn value_variants<'a>() -> &'a [Self] {
                <$name as ::strum::VariantArray>::VARIANTS
            }

            fn to_possible_value(&self) -> Option<::clap::builder::PossibleValue> {
                let value = ::clap::builder::PossibleValue::new(self.name());
                Some(match $crate::named::Named::doc(*self) {
                    Some(doc) => value.help(doc),
                    None => value,
                })
            }
        }
    };
    ($(#[$attr:meta])* $vis:vis enum $name:ident { $($body:tt)* }) => {
        $crate::named!(case = "kebab-case"; $(#[$attr])* $vis enum $name { $($body)* });
    };
}
