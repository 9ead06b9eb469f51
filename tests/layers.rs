//! The crate's layers, read from its own source: every `crate::` path in src/ (outside comments
//! and test modules) is an import of one top-level module by another, a folder such as
//! src/report/ counting as one. The data types and rules sit at the bottom, the engine above
//! them and the reports above that: report/ imports no part of the engine, the graph has no
//! cycle, and it is at most `MAX_LAYERS` deep.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The deepest import chain allowed, counted in modules (a module that imports nothing is
/// layer 1).
const MAX_LAYERS: usize = 12;

/// What the reports may not import: the engine that runs and measures cells, and the commands.
const ENGINE: [&str; 7] = [
    "frame_loop",
    "sweep",
    "measure",
    "calibrate",
    "balance",
    "config",
    "commands",
];

type Graph = BTreeMap<String, BTreeSet<String>>;

/// The source a module's imports are read from: no comment lines, and nothing from a
/// `#[cfg(test)]` module on.
fn code(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let t = line.trim_start();
        if t.starts_with("#[cfg(test)]")
            && lines
                .peek()
                .is_some_and(|next| next.trim_start().starts_with("mod "))
        {
            break;
        }
        if !t.starts_with("//") {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// The top-level modules `code` names through `crate::` paths, braces included
/// (`crate::{a, b::C}` names a and b).
fn imports(code: &str, modules: &BTreeSet<String>) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (at, _) in code.match_indices("crate::") {
        if code[..at].ends_with('$') {
            continue;
        }
        let rest = &code[at + "crate::".len()..];
        let names: Vec<&str> = match rest.strip_prefix('{') {
            Some(group) => {
                let mut depth = 0;
                let end = group
                    .char_indices()
                    .find(|&(_, c)| {
                        depth += match c {
                            '{' => 1,
                            '}' => -1,
                            _ => 0,
                        };
                        depth < 0
                    })
                    .map_or(group.len(), |(i, _)| i);
                let mut names = Vec::new();
                let mut depth = 0;
                let mut start = 0;
                for (i, c) in group[..end].char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' => depth -= 1,
                        ',' if depth == 0 => {
                            names.push(group[start..i].trim());
                            start = i + 1;
                        }
                        _ => {}
                    }
                }
                names.push(group[start..end].trim());
                names
            }
            None => vec![rest],
        };
        for name in names {
            let first: String = name
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if modules.contains(&first) {
                out.insert(first);
            }
        }
    }
    out
}

/// The module graph of src/: each top-level module and the others it imports.
fn graph(src: &Path) -> Graph {
    let mut modules = BTreeSet::new();
    for entry in std::fs::read_dir(src).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.is_dir()
            || (path.extension().is_some_and(|e| e == "rs") && name != "lib" && name != "main")
        {
            modules.insert(name);
        }
    }
    let mut g = Graph::new();
    for module in &modules {
        let mut files = Vec::new();
        let file = src.join(format!("{module}.rs"));
        if file.is_file() {
            files.push(file);
        }
        let mut dirs = vec![src.join(module)];
        while let Some(dir) = dirs.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            for e in entries {
                let p = e.unwrap().path();
                if p.is_dir() {
                    dirs.push(p);
                } else if p.extension().is_some_and(|x| x == "rs")
                    && p.file_name().unwrap() != "tests.rs"
                {
                    files.push(p);
                }
            }
        }
        let mut deps = BTreeSet::new();
        for f in files {
            deps.extend(imports(
                &code(&std::fs::read_to_string(&f).unwrap()),
                &modules,
            ));
        }
        deps.remove(module);
        g.insert(module.clone(), deps);
    }
    g
}

/// Each module's layer (1 + the deepest layer it imports), or the modules of a cycle.
fn layers(g: &Graph) -> Result<BTreeMap<String, usize>, Vec<String>> {
    fn visit(
        m: &str,
        g: &Graph,
        done: &mut BTreeMap<String, usize>,
        path: &mut Vec<String>,
    ) -> Result<usize, Vec<String>> {
        if let Some(&l) = done.get(m) {
            return Ok(l);
        }
        if let Some(at) = path.iter().position(|p| p == m) {
            return Err(path[at..].to_vec());
        }
        path.push(m.to_string());
        let mut deepest = 0;
        for d in g.get(m).into_iter().flatten() {
            deepest = deepest.max(visit(d, g, done, path)?);
        }
        path.pop();
        done.insert(m.to_string(), deepest + 1);
        Ok(deepest + 1)
    }
    let mut done = BTreeMap::new();
    for m in g.keys() {
        visit(m, g, &mut done, &mut Vec::new())?;
    }
    Ok(done)
}

fn src_graph() -> Graph {
    graph(&common::root().join("src"))
}

#[test]
fn report_imports_no_part_of_the_engine() {
    let g = src_graph();
    let report = &g["report"];
    assert!(
        report.contains("results"),
        "the reader sees report's imports: {report:?}"
    );
    let engine: Vec<&String> = report
        .iter()
        .filter(|m| ENGINE.contains(&m.as_str()))
        .collect();
    assert!(engine.is_empty(), "report/ imports the engine: {engine:?}");
}

#[test]
fn the_module_graph_has_no_cycle_and_few_layers() {
    let g = src_graph();
    assert!(g.len() >= 30, "every module is read: {:?}", g.keys());
    let layers = layers(&g).unwrap_or_else(|cycle| panic!("import cycle: {}", cycle.join(" -> ")));
    let (top, deepest) = layers.iter().max_by_key(|(_, &l)| l).unwrap();
    assert!(
        *deepest <= MAX_LAYERS,
        "{top} sits at layer {deepest}, over {MAX_LAYERS}: {layers:?}"
    );
    // The data at the bottom stays below the engine.
    for (low, high) in [
        ("cell", "frame_loop"),
        ("summary", "measure"),
        ("results", "sweep"),
    ] {
        assert!(
            layers[low] < layers[high],
            "{low} at {} vs {high} at {}",
            layers[low],
            layers[high]
        );
    }
}

#[test]
fn the_reader_finds_imports_and_cycles() {
    let modules: BTreeSet<String> = ["a", "b", "c", "d"].map(String::from).into();
    let text = "use crate::a::X;\n// use crate::d;\nfn f() { crate::b::g(); $crate::c::h(); }\nuse crate::{c::{Y, Z}, a};\n#[cfg(test)]\nmod tests {\n    use crate::d;\n}\n";
    let found = imports(&code(text), &modules);
    assert_eq!(found, ["a", "b", "c"].map(String::from).into());

    let mut g = Graph::new();
    g.insert("a".into(), ["b".to_string()].into());
    g.insert("b".into(), ["c".to_string()].into());
    g.insert("c".into(), BTreeSet::new());
    assert_eq!(layers(&g).unwrap()["a"], 3);
    g.get_mut("c").unwrap().insert("a".into());
    let cycle = layers(&g).unwrap_err();
    assert_eq!(cycle.len(), 3, "{cycle:?}");
}
