//! The error every check of user input returns: one line naming the field and what is allowed,
//! which the binary prints and exits 2 on.

/// A problem with user input: printed as one line, exit status 2.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

impl From<String> for InputError {
    fn from(s: String) -> Self {
        InputError(s)
    }
}
