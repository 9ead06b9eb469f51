//! Published numbers: README.md and docs/ agree with the committed runs their blocks name, a
//! changed value in a run fails the check, and bad blocks are refused with their file and line.

mod common;

use common::{assert_input_error, assert_success, oceanbench, oceanbench_in, refuses, FIXTURE};

#[test]
fn every_published_block_matches_its_committed_run() {
    assert_success(&oceanbench(&["docs", "--check"]));
}

/// A checkout of one run (the quick fixture) and a README citing it.
fn checkout(readme: &str) -> tempfile::TempDir {
    let root = tempfile::tempdir().unwrap();
    let run = root.path().join("results/quick-fixture");
    std::fs::create_dir_all(&run).unwrap();
    std::fs::create_dir_all(root.path().join("docs")).unwrap();
    std::fs::copy(FIXTURE, run.join("results.json")).unwrap();
    std::fs::write(root.path().join("README.md"), readme).unwrap();
    root
}

const README: &str = "# x\n\nSerial runs <!-- ob:value run=quick-fixture cell=\"16 w0 serial neighbors reference\" -->0<!-- /ob --> FPS, <!-- ob:value run=quick-fixture cell=\"16 w0 serial neighbors reference\" over=\"16 w0 serial neighbors reference\" -->0<!-- /ob --> × itself.\n\n<!-- ob:table run=quick-fixture slice=\"sync=atomic,threading=pool\" -->\n<!-- /ob -->\n";

#[test]
fn a_changed_value_in_a_run_fails_the_check() {
    let root = checkout(README);
    let dir = root.path();
    assert_success(&oceanbench_in(dir, &["docs", "--write"]));
    let written = std::fs::read_to_string(dir.join("README.md")).unwrap();
    assert!(
        !written.contains("-->0<!--"),
        "the value was generated: {written}"
    );
    assert!(
        written.contains("| mesh | workload | serial | UP | DP |"),
        "{written}"
    );
    assert!(
        written.contains("tree unknown"),
        "an old run says so: {written}"
    );
    assert!(
        written.contains("-->1.00 (tree unknown"),
        "a cell over itself: {written}"
    );
    assert_success(&oceanbench_in(dir, &["docs", "--check"]));

    // One FPS of the run changes: the check names the block's file and line.
    let path = dir.join("results/quick-fixture/results.json");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let cell = json["cells"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|c| c["mode"] == "serial" && c["size"] == 16 && c["workload"] == 0)
        .unwrap();
    let fps = cell["fps"].as_f64().unwrap();
    cell["fps"] = (fps * 1.1).into();
    std::fs::write(&path, serde_json::to_string(&json).unwrap()).unwrap();
    let out = oceanbench_in(dir, &["docs", "--check"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("README.md:3: the block differs"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("README.md")).unwrap(),
        written,
        "--check writes nothing"
    );
}

#[test]
fn bad_blocks_are_refused_with_their_file_and_line() {
    let cases = [
        ("<!-- ob:value run=nowhere cell=x -->1<!-- /ob -->", "run `nowhere` does not exist"),
        (
            "<!-- ob:value run=quick-fixture cell=\"999 w0 serial\" -->1<!-- /ob -->",
            "no cell `999 w0 serial`",
        ),
        (
            "<!-- ob:value run=quick-fixture cell=\"16 w0 serial neighbors reference\" stat=speed -->1<!-- /ob -->",
            "stat: unknown `speed`",
        ),
        ("<!-- ob:chart run=quick-fixture -->1<!-- /ob -->", "unknown block kind `chart`"),
        ("<!-- ob:table run=quick-fixture -->\n", "no closing"),
        (
            "<!-- ob:table run=quick-fixture slice=sync=nothing -->\n<!-- /ob -->",
            "matches 0 tables",
        ),
        ("<!-- ob:const name=nothing -->1<!-- /ob -->", "const: unknown name"),
        (
            "<!-- ob:value run=quick-fixture cell=\"16 w0 serial neighbors reference\" over=\"a;b\" -->1<!-- /ob -->",
            "over= names 2 cell(s) and cell= 1",
        ),
        (
            "<!-- ob:grid run=quick-fixture rows=\"atomic\" cols=\"DP=16 w0 dp {} nowhere@fps\" -->\n<!-- /ob -->",
            "row `atomic`, column `DP`: the run has no cell `16 w0 dp atomic nowhere`",
        ),
        (
            "<!-- ob:grid run=quick-fixture rows=\"atomic;spin\" cols=\"DP=16 w0 dp {} nowhere@fps\" gaps=yes -->\n<!-- /ob -->",
            "column `DP`: no row has a cell",
        ),
        (
            "<!-- ob:config file=configs/none.json key=sizes -->1<!-- /ob -->",
            "config file `configs/none.json`",
        ),
        ("<!-- ob:ref name=nothing -->1<!-- /ob -->", "docs/references.json"),
    ];
    for (block, needle) in cases {
        let text = format!("# x\n\n{block}\n");
        let root = checkout(&text);
        for mode in ["--check", "--write"] {
            let out = oceanbench_in(root.path(), &["docs", mode]);
            assert_input_error(&out, &["README.md:3:", needle]);
        }
        assert_eq!(
            std::fs::read_to_string(root.path().join("README.md")).unwrap(),
            text,
            "a bad block leaves the file as it was"
        );
    }
}

#[test]
fn findings_of_a_folder_without_results_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    refuses(
        &["findings", dir.path().to_str().unwrap()],
        &["results.json"],
    );
}

#[test]
fn findings_are_computed_from_the_results_file_alone() {
    let out = oceanbench(&["findings", FIXTURE, "--json"]);
    assert_success(&out);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let findings = json["findings"].as_array().unwrap();
    let ids: Vec<&str> = findings.iter().map(|f| f["id"].as_str().unwrap()).collect();
    for id in [
        "peak-dp-over-up",
        "peak-dp-over-serial",
        "marks",
        "handoffs",
    ] {
        assert!(ids.contains(&id), "{id} missing from {ids:?}");
    }
    // The fixture sweeps hand-off methods and threading: a slice is one of each.
    assert_eq!(json["slice_dims"], serde_json::json!(["sync", "threading"]));
    let again = oceanbench(&["findings", FIXTURE, "--json"]);
    assert_eq!(
        out.stdout, again.stdout,
        "the same file gives the same findings"
    );
    let text = oceanbench(&["findings", FIXTURE]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.starts_with("## Findings"), "{text}");
    assert!(text.contains("**sync atomic, threading pool**"), "{text}");
}

#[test]
fn a_grid_reads_one_stat_of_each_row_and_column_cell() {
    let readme = "# x\n\n<!-- ob:grid run=quick-fixture head=method rows=\"atomic;the spin=spin\" cols=\"UP=16 w0 up {} pool neighbors reference@fps;DP ÷ UP=16 w0 dp {} pool neighbors reference@dp_over_up\" -->\n<!-- /ob -->\n";
    let root = checkout(readme);
    let out = oceanbench_in(root.path(), &["docs", "--write"]);
    assert_success(&out);
    let written = std::fs::read_to_string(root.path().join("README.md")).unwrap();
    let results =
        oceanbench::results::Results::load(&root.path().join("results/quick-fixture/results.json"))
            .unwrap();
    let fps = |label: &str| {
        let c = results
            .cells
            .iter()
            .find(|c| c.key.label() == label)
            .unwrap();
        c.summary.as_ref().unwrap().fps
    };
    let up = format!("{:.0}", fps("16 w0 up spin pool neighbors reference"));
    let row = written
        .lines()
        .find(|l| l.starts_with("| the spin |"))
        .unwrap_or_else(|| panic!("no row labelled `the spin`: {written}"));
    assert!(row.starts_with(&format!("| the spin | {up}")), "{row}");
    assert!(written.contains("| method | UP | DP ÷ UP |"), "{written}");
    assert!(
        written.contains("Every number in this table: tree unknown"),
        "{written}"
    );
}

#[test]
fn a_number_outside_the_blocks_fails_the_check_unless_the_code_checks_it() {
    let root = checkout("# x\n\nDP ran 1.74 × UP at 128×128 on workload 2 (Figure 5-1).\n");
    let out = oceanbench_in(root.path(), &["docs", "--check"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let named: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("outside generated blocks"))
        .collect();
    assert_eq!(named.len(), 1, "only 1.74 is unchecked: {stderr}");
    assert!(named[0].contains("README.md:3: 1.74"), "{stderr}");

    let out = oceanbench_in(root.path(), &["docs", "--numbers"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("128 (mesh size"), "{stdout}");
    assert!(stdout.contains("2 (workload level"), "{stdout}");
    assert!(stdout.contains("1.74 (UNCHECKED)"), "{stdout}");
}

/// A `compare` block states `oceanbench compare`'s counts and exit status for two committed runs,
/// within one placement when asked, and refuses a run that is not there.
#[test]
fn compare_blocks_state_the_verdict_counts_of_two_runs() {
    use oceanbench::publish::blocks::{self, Block};
    use oceanbench::publish::Context;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut context = Context::new(root);
    let file = root.join("docs/trace.md");
    let run = "trace-overhead-20261127T220001Z";
    let block = |attrs: &str| -> Block {
        let text = format!("<!-- ob:compare {attrs} -->x<!-- /ob -->");
        blocks::parse(&text).unwrap().remove(0)
    };
    let near = context
        .render(
            &file,
            &block(&format!("run={run}/base1 new={run}/head1 placement=near")),
        )
        .unwrap();
    assert!(
        near.ends_with(", exit 0") && near.contains("16 within noise"),
        "{near}"
    );
    let pair = format!("run={run}/base1 new={run}/base2");
    let all = context.render(&file, &block(&pair)).unwrap();
    let near = context
        .render(&file, &block(&format!("{pair} placement=near")))
        .unwrap();
    assert_ne!(near, all, "--placement near cuts the trials compared");
    let missing = context.render(&file, &block(&format!("run={run}/base1 new={run}/none")));
    assert!(missing.is_err_and(|e| e.contains("does not exist")));
}

/// A `bench` block gives one estimate, its time per element (`per=element`) or the ratio of
/// two, and refuses what does not fit.
#[test]
fn bench_blocks_give_an_estimate_its_time_per_element_or_a_ratio() {
    use oceanbench::publish::blocks::{self, Block};
    use oceanbench::publish::Context;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut context = Context::new(root);
    let file = root.join("docs/fog.md");
    let run = "run=bench-fog-coefficients-20261128T211049Z/head-1";
    let id = "id=fog-coefficients/fill/256";
    let block = |attrs: &str| -> Block {
        let text = format!("<!-- ob:bench {attrs} -->x<!-- /ob -->");
        blocks::parse(&text).unwrap().remove(0)
    };
    let render = |context: &mut Context, attrs: &str| context.render(&file, &block(attrs));
    let whole = render(&mut context, &format!("{run} {id}")).unwrap();
    let each = render(&mut context, &format!("{run} {id} per=element")).unwrap();
    // 65,536 vertices an iteration: the whole in µs, each vertex in ns.
    let value = |text: &str, unit: &str| -> f64 {
        text.strip_suffix(unit).unwrap().trim().parse().unwrap()
    };
    let (whole, each) = (value(&whole, "µs"), value(&each, "ns"));
    assert!(
        (whole * 1e3 / 65_536.0 - each).abs() < 0.01,
        "{whole} µs, {each} ns"
    );
    for (attrs, why) in [
        (
            format!("{run} {id} per=vertex"),
            "allowed value is `element`",
        ),
        (
            format!("{run} {id} per=element over=fog-coefficients/fill/512"),
            "do not go together",
        ),
        (format!("{run} per=element"), "per= needs id="),
    ] {
        let err = render(&mut context, &attrs).unwrap_err();
        assert!(err.contains(why), "{attrs}: {err}");
    }
}
