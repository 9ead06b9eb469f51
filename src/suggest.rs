//! "Did you mean" for serde's unknown field and unknown variant messages.

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
    let closest = allowed
        .iter()
        .map(|a| (strsim::levenshtein(given, a), a))
        .min()
        .filter(|(d, a)| *d <= 2.max(a.len() / 3));
    let kind = if msg.starts_with("unknown field") {
        "field"
    } else {
        "value"
    };
    match closest {
        Some((_, a)) => format!(
            "unknown {kind} `{given}`; did you mean `{a}`? (allowed: {})",
            allowed.join(", ")
        ),
        None => format!("unknown {kind} `{given}` (allowed: {})", allowed.join(", ")),
    }
}
