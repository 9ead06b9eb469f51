//! Which source a run measured: the tree's state read from the machine record, a file from before
//! the dirty flag read as unknown, and every report saying a dirty or unknown run is one.
//! (scripts/provenance-check.sh checks the build end to end: an edit makes the next run dirty.)

mod common;

use common::fixture;
use oceanbench::machine::{Machine, Tree};
use oceanbench::report::{html, markdown};

/// The fixture's machine with the tree recorded as `dirty` and `diff_hash`.
fn machine(dirty: Option<bool>, diff_hash: Option<&str>) -> Machine {
    Machine {
        git_commit: Some("d061b6d1e2f3".into()),
        git_dirty: dirty,
        git_diff_hash: diff_hash.map(String::from),
        ..fixture().machine
    }
}

#[test]
fn the_tree_and_its_line_follow_the_flag() {
    let clean = machine(Some(false), None);
    assert_eq!(clean.tree(), Tree::Clean);
    assert_eq!(clean.provenance_line(), "commit d061b6d1e2f3, clean tree");

    let dirty = machine(Some(true), Some("0123456789abcdef"));
    assert_eq!(
        dirty.tree(),
        Tree::Dirty {
            diff_hash: "0123456789abcdef".into()
        }
    );
    assert_eq!(
        dirty.provenance_line(),
        "commit d061b6d1e2f3, DIRTY tree (uncommitted changes, diff 0123456789abcdef)"
    );

    let unknown = machine(None, None);
    assert_eq!(unknown.tree(), Tree::Unknown);
    assert_eq!(
        unknown.provenance_line(),
        "commit d061b6d1e2f3, tree unknown (recorded before the dirty flag)"
    );

    let outside = Machine {
        git_commit: None,
        ..unknown
    };
    assert_eq!(outside.provenance_line(), "no commit recorded");
}

#[test]
fn a_file_from_before_the_flag_loads_as_unknown_and_the_flag_round_trips() {
    let r = fixture();
    assert!(
        r.machine.git_commit.is_some(),
        "the fixture records a commit"
    );
    assert_eq!(r.machine.tree(), Tree::Unknown);

    let dirty = machine(Some(true), Some("0123456789abcdef"));
    let json = serde_json::to_value(&dirty).unwrap();
    assert_eq!(json["git_dirty"], true);
    assert_eq!(json["git_diff_hash"], "0123456789abcdef");
    assert_eq!(serde_json::from_value::<Machine>(json).unwrap(), dirty);
    // Unknown stays absent rather than written as null, as the file it was read from had it.
    let json = serde_json::to_value(machine(None, None)).unwrap();
    assert!(json.get("git_dirty").is_none() && json.get("git_diff_hash").is_none());
}

#[test]
fn markdown_and_html_say_a_run_is_dirty_or_unknown() {
    let mut r = fixture();
    let unknown = "tree unknown (recorded before the dirty flag)";
    assert!(markdown::preamble(&r).contains(unknown));
    assert!(html::page(&r, "fixture", None).unwrap().contains(unknown));

    r.machine = machine(Some(true), Some("0123456789abcdef"));
    let line = r.machine.provenance_line();
    let preamble = markdown::preamble(&r);
    let at = |s: &str| preamble.lines().position(|l| l.starts_with(s)).unwrap();
    assert_eq!(at("Source: "), at("Machine: ") + 1, "{preamble}");
    assert!(preamble.contains(&line), "{preamble}");
    let page = html::page(&r, "fixture", None).unwrap();
    assert!(
        page.contains(&format!("<strong>{line}</strong>")),
        "a dirty run stands out"
    );
}
