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

    /// The same problems with each config field that a command-line flag set named as that flag
    /// (`min_seconds: …` becomes `--seconds: …`): the user typed the flag, not the field.
    /// `flags` pairs a field's path as errors name it with its flag.
    pub fn naming_flags(&self, flags: &[(&str, String)]) -> InputError {
        let lines: Vec<String> = self
            .0
            .lines()
            .map(|line| {
                flags.iter().fold(line.to_string(), |line, (field, flag)| {
                    let line = match line.strip_prefix(field) {
                        Some(rest) if rest.starts_with(':') => format!("{flag}{rest}"),
                        _ => line,
                    };
                    // Inside the text, only names no prose uses (`min_seconds`, not `helpers`).
                    if field.contains('_') {
                        rename_word(&line, field, flag)
                    } else {
                        line
                    }
                })
            })
            .collect();
        InputError(lines.join("\n"))
    }

    /// The same problems with `prefix` (such as the file they were found in) before each line.
    pub fn prefixed(&self, prefix: &str) -> InputError {
        let lines: Vec<String> = self.0.lines().map(|l| format!("{prefix}{l}")).collect();
        InputError(lines.join("\n"))
    }
}

/// `text` with every whole-word `word` (not part of a longer identifier or path) replaced.
fn rename_word(text: &str, word: &str, with: &str) -> String {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '-';
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(word) {
        let before = rest[..at].chars().last().or_else(|| out.chars().last());
        let after = rest[at + word.len()..].chars().next();
        out.push_str(&rest[..at]);
        if before.is_some_and(ident) || after.is_some_and(|c| ident(c) && c != '.') {
            out.push_str(word);
        } else {
            out.push_str(with);
        }
        rest = &rest[at + word.len()..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_set_by_flags_are_named_as_the_flags() {
        let flags = [
            ("min_seconds", "--seconds".to_string()),
            ("max_seconds", "--max-seconds".to_string()),
            ("sizes", "--size".to_string()),
            ("camera.pitch_degrees", "--pitch".to_string()),
        ];
        let e = InputError(
            "max_seconds: must be > 0 and >= min_seconds (1), got 0\n\
             sizes: 1 is not allowed; sizes are 2 to 4096\n\
             camera.pitch_degrees: must be above 0 and at most 90, got 400\n\
             trials: must be 1 to 1000, got 0\n\
             min_seconds_x: min_seconds."
                .into(),
        );
        assert_eq!(
            e.naming_flags(&flags).0,
            "--max-seconds: must be > 0 and >= --seconds (1), got 0\n\
             --size: 1 is not allowed; sizes are 2 to 4096\n\
             --pitch: must be above 0 and at most 90, got 400\n\
             trials: must be 1 to 1000, got 0\n\
             min_seconds_x: --seconds."
        );
    }
}
