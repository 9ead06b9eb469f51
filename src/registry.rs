//! A process-wide list of named entries (workload kinds, ocean models): the built-in ones, then
//! those a library user registers, and the names read from results files that nothing here
//! has, kept once each so that any name reads back as a `'static` string.

use crate::input::InputError;
use parking_lot::RwLock;

/// Something a registry holds: it has a name.
pub trait Entry: Send + Sync {
    /// Its name in configs, flags, cells and results.
    fn entry_name(&self) -> &'static str;
}

/// The built-in entries of one kind of thing, and the ones registered at run time.
pub struct Registry<T: ?Sized + Entry + 'static> {
    what: &'static str,
    built_in: &'static [&'static T],
    registered: RwLock<Vec<&'static T>>,
    strangers: RwLock<Vec<&'static str>>,
}

impl<T: ?Sized + Entry + 'static> Registry<T> {
    /// A registry of `built_in` entries; `what` names them in messages ("workload kind").
    pub const fn new(what: &'static str, built_in: &'static [&'static T]) -> Self {
        Registry {
            what,
            built_in,
            registered: RwLock::new(Vec::new()),
            strangers: RwLock::new(Vec::new()),
        }
    }

    /// Adds `entry`; refuses a name already taken or one that is not letters, digits, '-'
    /// and '_'.
    pub fn register(&self, entry: &'static T) -> Result<&'static str, InputError> {
        let name = entry.entry_name();
        let what = self.what;
        let mut registered = self.registered.write();
        if self
            .built_in
            .iter()
            .chain(registered.iter())
            .any(|e| e.entry_name() == name)
        {
            return Err(InputError(format!("{what} `{name}` is registered already")));
        }
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(InputError(format!(
                "{what} `{name}`: a name is letters, digits, '-' and '_'"
            )));
        }
        registered.push(entry);
        Ok(name)
    }

    /// Every entry, the built-in ones first.
    pub fn all(&self) -> Vec<&'static T> {
        self.built_in
            .iter()
            .copied()
            .chain(self.registered.read().iter().copied())
            .collect()
    }

    /// The entry called `name`.
    pub fn lookup(&self, name: &str) -> Option<&'static T> {
        self.all().into_iter().find(|e| e.entry_name() == name)
    }

    /// Every entry's name.
    pub fn names(&self) -> Vec<&'static str> {
        self.all().iter().map(|e| e.entry_name()).collect()
    }

    /// `name` as a `'static` string: an entry's own, or one kept for the process.
    pub fn intern(&self, name: &str) -> &'static str {
        if let Some(e) = self.lookup(name) {
            return e.entry_name();
        }
        let mut strangers = self.strangers.write();
        if let Some(&s) = strangers.iter().find(|&&s| s == name) {
            return s;
        }
        let kept: &'static str = Box::leak(name.to_owned().into_boxed_str());
        strangers.push(kept);
        kept
    }
}

/// Gives an interned name type (a tuple struct of one `&'static str` with a `named`
/// constructor) its `Display` (the name), `Debug` (`Type(name)`) and serde as a plain string:
/// a name another program registered reads back as itself.
#[macro_export]
macro_rules! registered_name {
    ($t:ident) => {
        impl ::std::fmt::Display for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.0)
            }
        }

        impl ::std::fmt::Debug for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                write!(f, "{}({})", stringify!($t), self.0)
            }
        }

        impl ::serde::Serialize for $t {
            fn serialize<S: ::serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.0)
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $t {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                Ok($t::named(&<String as ::serde::Deserialize>::deserialize(
                    d,
                )?))
            }
        }
    };
}
