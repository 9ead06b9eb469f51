//! Numbers left in README.md and docs/*.md outside generated blocks, fenced code and inline
//! code. Each is either a label the code accepts (a mesh size, a workload level, a list item's
//! number, a name the code uses) or unchecked: `docs --numbers` lists them, and `docs --check`
//! refuses an unchecked one, since prose outside the blocks carries no measured number.

use super::blocks;
use crate::config::SweepConfig;
use crate::ocean::mesh::MAX_SIZE;

/// Names with digits in them that docs write in prose, each with what it names; a test checks
/// that the code uses each name.
pub const NAMES: &[(&str, &str)] = &[
    (
        "Figure 5-1",
        "the paper's figure the default sweep reproduces",
    ),
    ("1 % low", "a frame-time statistic the report prints"),
    ("0.1 % low", "a frame-time statistic the report prints"),
];

/// What a number outside the blocks is, as the code checks it.
#[derive(Debug, Clone, PartialEq)]
pub enum Label {
    /// A mesh size written `N×N`, `N²` or `N³`, within the sizes a mesh accepts.
    Size(usize),
    /// A workload level after "workload" or "levels", within the default sweep's levels.
    Level(usize),
    /// The number of a numbered list item.
    ListItem,
    /// Part of one of [`NAMES`].
    Name(&'static str),
}

impl Label {
    /// The label as `docs --numbers` prints it, with the rule that checks it.
    pub fn describe(&self) -> String {
        match self {
            Label::Size(_) => format!("mesh size, 2 to {MAX_SIZE}"),
            Label::Level(_) => format!("workload level, 0 to {}", levels() - 1),
            Label::ListItem => "list item".into(),
            Label::Name(n) => format!("name `{n}`"),
        }
    }
}

/// One number outside the blocks.
#[derive(Debug, Clone)]
pub struct Loose {
    /// Its line, from 1.
    pub line: usize,
    /// The number as written.
    pub number: String,
    /// The whole line, trimmed.
    pub context: String,
    /// What it is, or `None`: a number nothing checks.
    pub label: Option<Label>,
}

fn levels() -> usize {
    SweepConfig::default().workload_levels.len()
}

/// Each number outside generated blocks, fenced code and inline code, in order.
pub fn numbers(text: &str) -> Vec<Loose> {
    let mut masked = text.to_string();
    if let Ok(blocks) = blocks::parse(text) {
        // Blank each block's text, keeping its newlines so line numbers hold.
        let mut bytes = masked.into_bytes();
        for b in &blocks {
            for i in b.body.clone() {
                if bytes[i] != b'\n' {
                    bytes[i] = b' ';
                }
            }
        }
        masked = String::from_utf8_lossy(&bytes).into_owned();
    }
    let mut out = Vec::new();
    let mut fenced = false;
    for (i, (line, original)) in masked.lines().zip(text.lines()).enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let prose: Vec<char> = strip_code_and_links(line).chars().collect();
        for (start, end) in spans(&prose) {
            out.push(Loose {
                line: i + 1,
                number: prose[start..end].iter().collect(),
                context: original.trim().to_string(),
                label: label(&prose, start, end),
            });
        }
    }
    out
}

/// The line without inline code, HTML comments, link targets and the opening comment of blocks.
fn strip_code_and_links(line: &str) -> String {
    let mut out = String::new();
    let mut rest = line;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix('`') {
            match r.find('`') {
                Some(end) => rest = &r[end + 1..],
                None => rest = "",
            }
        } else if let Some(r) = rest.strip_prefix("<!--") {
            rest = r.find("-->").map_or("", |end| &r[end + 3..]);
        } else if let Some(r) = rest.strip_prefix("](") {
            out.push(' ');
            rest = r.find(')').map_or("", |end| &r[end + 1..]);
        } else {
            let c = rest.chars().next().expect("not empty");
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// Where the numbers of a prose line are: digits with their decimal point and thousands
/// separators, not part of a word.
fn spans(chars: &[char]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = chars[i].is_ascii_digit()
            && (i == 0
                || !(chars[i - 1].is_alphanumeric() || matches!(chars[i - 1], '_' | '-' | '.')));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < chars.len()
            && (chars[j].is_ascii_digit()
                || ((chars[j] == '.' || chars[j] == ',')
                    && chars.get(j + 1).is_some_and(|c| c.is_ascii_digit())))
        {
            j += 1;
        }
        // A word with digits in it (x86_64, 2D, f32) is a name, not a number.
        if chars.get(j).is_some_and(|c| c.is_alphabetic() || *c == '_') {
            while j < chars.len() && (chars[j].is_alphanumeric() || chars[j] == '_') {
                j += 1;
            }
            i = j;
            continue;
        }
        out.push((i, j));
        i = j;
    }
    out
}

/// What the number at `chars[start..end]` is, when the code can check it.
fn label(chars: &[char], start: usize, end: usize) -> Option<Label> {
    let text: String = chars[start..end].iter().collect();
    let line: String = chars.iter().collect();
    let byte_start = chars[..start].iter().map(|c| c.len_utf8()).sum::<usize>();
    let byte_end = byte_start + text.len();
    for (name, _) in NAMES {
        let mut from = 0;
        while let Some(at) = line[from..].find(name) {
            let (s, e) = (from + at, from + at + name.len());
            if s <= byte_start && byte_end <= e {
                return Some(Label::Name(name));
            }
            from = e;
        }
    }
    let before: String = chars[..start].iter().collect();
    if before.trim().is_empty() && matches!(chars.get(end), Some('.' | ')')) {
        return Some(Label::ListItem);
    }
    let value: usize = text.parse().ok()?;
    let next = chars.get(end).copied();
    let size_after = matches!(next, Some('²' | '³'))
        || (next == Some('×') && chars.get(end + 1).is_some_and(|c| c.is_ascii_digit()));
    let size_before = start >= 2 && chars[start - 1] == '×' && chars[start - 2].is_ascii_digit();
    if size_after || size_before {
        return (2..=MAX_SIZE)
            .contains(&value)
            .then_some(Label::Size(value));
    }
    if after_level_word(&before) {
        return (value < levels()).then_some(Label::Level(value));
    }
    None
}

/// Whether `before` ends with "workload", "levels" and the like, perhaps followed by earlier
/// levels of a list or range ("workloads 1, 2 and ", "levels 0 to ").
fn after_level_word(before: &str) -> bool {
    let mut rest = before.trim_end();
    loop {
        let lower = rest.to_lowercase();
        if ["workload", "workloads", "level", "levels"]
            .iter()
            .any(|w| lower.ends_with(w))
        {
            return true;
        }
        let Some(sep) = [",", " and", " to", " or", "–", "-"]
            .iter()
            .find(|s| lower.ends_with(**s))
        else {
            return false;
        };
        rest = rest[..rest.len() - sep.len()].trim_end();
        let digits = rest.len() - rest.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        if digits == 0 {
            return false;
        }
        rest = rest[..rest.len() - digits].trim_end();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(text: &str) -> Vec<(String, Option<Label>)> {
        numbers(text)
            .into_iter()
            .map(|l| (l.number, l.label))
            .collect()
    }

    #[test]
    fn sizes_levels_items_and_names_are_labels() {
        let got = labels("1. at 40×40 and 256² on workloads 1, 2 and 3 (Figure 5-1's 1 % low)");
        let want = [
            ("1", Some(Label::ListItem)),
            ("40", Some(Label::Size(40))),
            ("40", Some(Label::Size(40))),
            ("256", Some(Label::Size(256))),
            ("1", Some(Label::Level(1))),
            ("2", Some(Label::Level(2))),
            ("3", Some(Label::Level(3))),
            ("5", Some(Label::Name("Figure 5-1"))),
            ("1", Some(Label::Name("1 % low"))),
        ];
        let want: Vec<_> = want
            .iter()
            .map(|(n, l)| (n.to_string(), l.clone()))
            .collect();
        assert_eq!(got, want);
    }

    #[test]
    fn measured_numbers_and_labels_out_of_range_are_unchecked() {
        let got = labels("DP runs 1.74 at 8192×8192, workload 7, levels 0, 65 and 1,400 µs");
        let unchecked: Vec<&str> = got
            .iter()
            .filter(|(_, l)| l.is_none())
            .map(|(n, _)| n.as_str())
            .collect();
        assert_eq!(unchecked, ["1.74", "8192", "8192", "7", "65", "1,400"]);
    }

    #[test]
    fn blocks_code_and_links_hide_their_numbers() {
        let text = "a <!-- ob:const name=x -->4<!-- /ob --> and `5 ms` [r](results/run-2026/)\n\
                    ```\n6\n```\n7 ms";
        let got = labels(text);
        assert_eq!(got, [("7".to_string(), None)]);
    }

    #[test]
    fn every_name_is_one_the_code_uses() {
        let mut code = String::new();
        let mut dirs = vec![std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")];
        while let Some(dir) = dirs.pop() {
            for e in std::fs::read_dir(dir).unwrap() {
                let p = e.unwrap().path();
                if p.is_dir() {
                    dirs.push(p);
                } else if p.extension().is_some_and(|x| x == "rs") && !p.ends_with("loose.rs") {
                    code.push_str(&std::fs::read_to_string(p).unwrap());
                }
            }
        }
        for (name, _) in NAMES {
            assert!(
                code.contains(name),
                "no code outside loose.rs says `{name}`"
            );
        }
    }
}
