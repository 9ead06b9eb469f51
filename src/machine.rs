//! A description of the machine a run was measured on, recorded next to every result.

use crate::affinity;
use serde::{Deserialize, Serialize};

/// The machine line of a results file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// CPU model name from /proc/cpuinfo.
    pub cpu_model: String,
    /// Logical cores the OS reports.
    pub logical_cores: usize,
    /// Cores this process may run on.
    pub allowed_cores: Vec<usize>,
    /// Operating system name and version.
    pub os: String,
    /// Kernel release.
    pub kernel: String,
    /// The compiler the binary was built with.
    pub rustc: String,
    /// oceanbench's version.
    pub oceanbench_version: String,
    /// `release` or `debug`.
    pub build_profile: String,
    /// Git commit of the source, when it was built from a checkout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub git_commit: Option<String>,
    /// Whether the source had uncommitted changes to tracked files; absent in files written
    /// before the flag, and for a build outside a checkout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub git_dirty: Option<bool>,
    /// FNV-1a 64 of the uncommitted diff (`git diff HEAD --binary`), as 16 hex digits, when the
    /// tree was dirty: two dirty runs with the same hash measured the same source.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub git_diff_hash: Option<String>,
}

/// The state of the source tree a run was built from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Tree {
    /// The build matched its commit.
    Clean,
    /// The build had uncommitted changes, so the commit alone does not name what was measured.
    Dirty {
        /// The hash of the uncommitted diff (empty if it was not recorded).
        diff_hash: String,
    },
    /// Not recorded: a file from before the flag, or a build outside a checkout.
    Unknown,
}

impl Machine {
    /// Reads the running machine.
    pub fn current() -> Machine {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let cpu_model = cpuinfo
            .lines()
            .find(|l| l.starts_with("model name"))
            .and_then(|l| l.split(':').nth(1))
            .map(|s| s.trim().to_string())
            .unwrap_or_else(|| std::env::consts::ARCH.to_string());
        let os = std::fs::read_to_string("/etc/os-release")
            .ok()
            .and_then(|t| {
                t.lines()
                    .find(|l| l.starts_with("PRETTY_NAME="))
                    .map(|l| l["PRETTY_NAME=".len()..].trim_matches('"').to_string())
            })
            .unwrap_or_else(|| std::env::consts::OS.to_string());
        let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease")
            .map(|s| s.trim().to_string())
            .unwrap_or_default();
        let commit = env!("OCEANBENCH_GIT_COMMIT");
        let diff_hash = env!("OCEANBENCH_GIT_DIFF_HASH");
        Machine {
            cpu_model,
            logical_cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            allowed_cores: affinity::allowed_cores().to_vec(),
            os,
            kernel,
            rustc: env!("OCEANBENCH_RUSTC").to_string(),
            oceanbench_version: env!("CARGO_PKG_VERSION").to_string(),
            build_profile: if cfg!(debug_assertions) {
                "debug".into()
            } else {
                "release".into()
            },
            git_commit: (!commit.is_empty()).then(|| commit.to_string()),
            git_dirty: match env!("OCEANBENCH_GIT_DIRTY") {
                "true" => Some(true),
                "false" => Some(false),
                _ => None,
            },
            git_diff_hash: (!diff_hash.is_empty()).then(|| diff_hash.to_string()),
        }
    }

    /// Whether the source was committed, dirty or not recorded.
    pub fn tree(&self) -> Tree {
        match self.git_dirty {
            Some(false) => Tree::Clean,
            Some(true) => Tree::Dirty {
                diff_hash: self.git_diff_hash.clone().unwrap_or_default(),
            },
            None => Tree::Unknown,
        }
    }

    /// One line saying which source was measured: the commit and whether the tree matched it.
    pub fn provenance_line(&self) -> String {
        let Some(commit) = &self.git_commit else {
            return "no commit recorded".into();
        };
        match self.tree() {
            Tree::Clean => format!("commit {commit}, clean tree"),
            Tree::Dirty { diff_hash } => {
                let diff = match diff_hash.as_str() {
                    "" => String::new(),
                    hash => format!(", diff {hash}"),
                };
                format!("commit {commit}, DIRTY tree (uncommitted changes{diff})")
            }
            Tree::Unknown => {
                format!("commit {commit}, tree unknown (recorded before the dirty flag)")
            }
        }
    }

    /// One line naming the machine, for tables and charts.
    pub fn line(&self) -> String {
        format!(
            "{}, {} logical cores (allowed {}), {}, {} build",
            self.cpu_model,
            self.logical_cores,
            affinity::list(&self.allowed_cores),
            self.os,
            self.build_profile
        )
    }
}

/// MemAvailable from /proc/meminfo, in bytes (None where it cannot be read).
pub fn available_memory() -> Option<u64> {
    meminfo_kib("MemAvailable:").map(|kib| kib * 1024)
}

/// MemTotal from /proc/meminfo, in kB as the file gives it (None where it cannot be read).
pub fn total_memory_kib() -> Option<u64> {
    meminfo_kib("MemTotal:")
}

/// The kB figure of the /proc/meminfo line starting with `key`.
fn meminfo_kib(key: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}
