//! Records the compiler version, and the git commit and state of the tree the binary was built
//! from, for results files.
use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .unwrap_or_default();
    println!("cargo:rustc-env=OCEANBENCH_RUSTC={}", version.trim());

    let commit = git(&["rev-parse", "--short=12", "HEAD"])
        .map(|out| String::from_utf8_lossy(&out).trim().to_string())
        .unwrap_or_default();
    // Plumbing rather than `git diff HEAD`: the porcelain refreshes and rewrites the index, which
    // is watched below, so every build would rerun this script and recompile the crate twice.
    // Its output is the same patch, and it ignores the user's diff config.
    let diff = git(&["diff-index", "-p", "--binary", "HEAD"]);
    let dirty = diff
        .as_ref()
        .map_or("", |d| if d.is_empty() { "false" } else { "true" });
    let diff_hash = diff
        .filter(|d| !d.is_empty())
        .map(|d| format!("{:016x}", fnv1a(&d)))
        .unwrap_or_default();
    println!("cargo:rustc-env=OCEANBENCH_GIT_COMMIT={commit}");
    println!("cargo:rustc-env=OCEANBENCH_GIT_DIRTY={dirty}");
    println!("cargo:rustc-env=OCEANBENCH_GIT_DIFF_HASH={diff_hash}");

    // Without git, no list is printed and Cargo reruns this script when any package file changes.
    let Some(files) = git(&["ls-files", "-z"]) else {
        return;
    };
    // Every tracked file, so an edit without a commit reruns the script. A tracked file deleted
    // without `git rm` stays listed: Cargo then reruns on every build, and rightly, since the
    // tree stays dirty until it is restored or removed from the index.
    for file in files.split(|&b| b == 0).filter(|f| !f.is_empty()) {
        let file = String::from_utf8_lossy(file);
        if !file.contains('\n') {
            println!("cargo:rerun-if-changed={file}");
        }
    }
    // HEAD catches a checkout, the index a file staged or unstaged, and the branch's ref a
    // commit: its own file rather than all of refs/, which a fetch or a commit in another
    // worktree would touch. `--git-path` rather than `.git/`: in a worktree `.git` is a file,
    // HEAD and the index live in the worktree's git dir and the refs in the common one.
    let mut watched: Vec<PathBuf> = ["HEAD", "index", "packed-refs"].map(git_path).into();
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"]) {
        let branch = git_path(String::from_utf8_lossy(&branch).trim());
        // A packed ref has no file until the next commit writes one, in this directory.
        if branch.exists() {
            watched.push(branch);
        } else {
            watched.extend(branch.parent().map(Path::to_path_buf));
        }
    }
    // Cargo counts a path it cannot find as changed on every build: packed-refs may not exist.
    for path in watched.iter().filter(|p| p.exists()) {
        println!("cargo:rerun-if-changed={}", path.display());
    }
}

/// Runs git with `args` in the package's directory; `None` when git is missing or fails (no
/// checkout, or no commit yet).
fn git(args: &[&str]) -> Option<Vec<u8>> {
    Command::new("git")
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| o.stdout)
}

/// Where git keeps `name` (`.git/name`, or a worktree's own or common git dir); empty outside a
/// checkout.
fn git_path(name: &str) -> PathBuf {
    git(&["rev-parse", "--git-path", name])
        .map(|p| PathBuf::from(String::from_utf8_lossy(&p).trim()))
        .unwrap_or_default()
}

/// FNV-1a, 64 bits: enough to tell two diffs apart in a results file, without a dependency.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}
