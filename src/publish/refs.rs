//! `ref` blocks: numbers quoted from outside the project (the paper, the slides, another
//! library's source, a published benchmark), each kept once in `docs/references.json` with its
//! source, so prose quotes it by name and a changed quote changes in one place.

use super::blocks::Block;
use serde::Deserialize;
use std::path::Path;

/// Where the quoted numbers are kept, under the checkout's root.
pub const FILE: &str = "docs/references.json";

/// One quoted number.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// The name a `ref` block gives.
    pub name: String,
    /// The number as docs write it.
    pub value: String,
    /// What it is.
    pub what: String,
    /// Where it is quoted from: a document and its section, or a URL.
    pub source: String,
}

/// Every reference of the checkout at `root`.
pub fn load(root: &Path) -> Result<Vec<Reference>, String> {
    let text = std::fs::read_to_string(root.join(FILE)).map_err(|e| format!("{FILE}: {e}"))?;
    serde_json::from_str(&text).map_err(|e| format!("{FILE}: {e}"))
}

/// The value a `ref name=NAME` block renders.
pub fn render(root: &Path, block: &Block) -> Result<String, String> {
    let name = block.attr("name").ok_or("`ref` needs name=NAME")?;
    let all = load(root)?;
    all.iter()
        .find(|r| r.name == name)
        .map(|r| r.value.clone())
        .ok_or_else(|| {
            format!(
                "ref: no `{name}` in {FILE} (it has: {})",
                all.iter()
                    .map(|r| r.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_committed_references_load_with_unique_names() {
        let all = load(Path::new(env!("CARGO_MANIFEST_DIR"))).expect("docs/references.json loads");
        let mut names: Vec<&str> = all.iter().map(|r| r.name.as_str()).collect();
        names.sort_unstable();
        let before = names.len();
        names.dedup();
        assert_eq!(names.len(), before, "a name appears twice in {FILE}");
        assert!(all
            .iter()
            .all(|r| !r.value.is_empty() && !r.source.is_empty()));
    }
}
