//! The error every check of user input returns: one line naming the field and what is allowed,
//! which the binary prints and exits 2 on. A check that finds several problems returns them all,
//! one line each.

/// A problem with user input: printed as one line per problem, exit status 2.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

impl From<String> for InputError {
    fn from(s: String) -> Self {
        InputError(s)
    }
}

impl InputError {
    /// `Ok` when nothing was found, else one error holding every problem, one line each.
    pub fn all(found: Vec<InputError>) -> Result<(), InputError> {
        if found.is_empty() {
            return Ok(());
        }
        let lines: Vec<String> = found.into_iter().map(|e| e.0).collect();
        Err(InputError(lines.join("\n")))
    }

    /// The same problems with `prefix` (such as the file they were found in) before each line.
    pub fn prefixed(&self, prefix: &str) -> InputError {
        let lines: Vec<String> = self.0.lines().map(|l| format!("{prefix}{l}")).collect();
        InputError(lines.join("\n"))
    }
}
