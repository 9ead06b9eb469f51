//! "Did you mean" for unknown names: config keys, enum values, dimensions.

/// The allowed name closest to `given`, when it is close enough to be a typo.
pub fn closest<'a>(given: &str, allowed: &[&'a str]) -> Option<&'a str> {
    allowed
        .iter()
        .map(|a| (strsim::levenshtein(given, a), *a))
        .min()
        .filter(|(d, a)| *d <= 2.max(a.len() / 3))
        .map(|(_, a)| a)
}

/// "unknown KIND `given`; did you mean `x`? (allowed: a, b)".
pub fn unknown(kind: &str, given: &str, allowed: &[&str]) -> String {
    match closest(given, allowed) {
        Some(a) => format!(
            "unknown {kind} `{given}`; did you mean `{a}`? (allowed: {})",
            allowed.join(", ")
        ),
        None => format!("unknown {kind} `{given}` (allowed: {})", allowed.join(", ")),
    }
}

/// Adds "did you mean" to serde's unknown field/variant messages, and shortens them.
pub fn with_suggestion(msg: &str) -> String {
    let quoted = |s: &str| -> Vec<String> {
        s.split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect()
    };
    let Some(rest) = msg
        .strip_prefix("unknown field ")
        .or_else(|| msg.strip_prefix("unknown variant "))
    else {
        return msg.to_string();
    };
    let names = quoted(rest);
    let Some((given, allowed)) = names.split_first() else {
        return msg.to_string();
    };
    let kind = if msg.starts_with("unknown field") {
        "field"
    } else {
        "value"
    };
    let allowed: Vec<&str> = allowed.iter().map(String::as_str).collect();
    unknown(kind, given, &allowed)
}
