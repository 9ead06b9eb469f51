//! What a workload kind counts per frame and records of its work, keyed by names the kind
//! chooses, so that JSON, CSV, markdown, HTML and the terminal show them without knowing the
//! kind: a results file written by a program that registered its own kind reads back and
//! renders in the stock binary.

use crate::stats;
use serde::de::{MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// Most values one frame may count.
pub const MAX_COUNTS: usize = 4;

/// What one frame's work counted (spray: its live, emitted and recycled particles), under the
/// kind's keys. `Copy` and fixed in size, so that recording it costs the frame nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WorkCounts {
    keys: &'static [&'static str],
    values: [u64; MAX_COUNTS],
}

impl WorkCounts {
    /// `values[i]` counted under `keys[i]`. A kind gives the same keys every frame.
    ///
    /// # Panics
    /// When the lengths differ or pass [`MAX_COUNTS`]: a kind's mistake, met at its first frame.
    pub fn new(keys: &'static [&'static str], values: &[u64]) -> WorkCounts {
        assert!(
            keys.len() == values.len() && keys.len() <= MAX_COUNTS,
            "a frame counts at most {MAX_COUNTS} values, one per key"
        );
        let mut v = [0; MAX_COUNTS];
        v[..values.len()].copy_from_slice(values);
        WorkCounts { keys, values: v }
    }

    /// Each key with its count, in the kind's order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, u64)> + '_ {
        self.keys.iter().copied().zip(self.values)
    }

    /// The count under `key`.
    pub fn get(&self, key: &str) -> Option<u64> {
        self.iter().find(|(k, _)| *k == key).map(|(_, v)| v)
    }
}

/// One count over a trial's frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CountStats {
    /// The kind's key.
    pub key: String,
    /// Mean per frame.
    pub mean: f64,
    /// Least in a frame (absent from results written before counts were keyed, except `live`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<u64>,
    /// Most in a frame (likewise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<u64>,
}

/// One trial of a counting kind: its counts per frame, and the main thread's time in the work.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "TrialRepr")]
pub struct WorkTrial {
    /// Mean main-thread time of the work per frame (ms).
    pub main_ms: f64,
    /// Each count, in the kind's order.
    pub counts: Vec<CountStats>,
}

impl WorkTrial {
    /// The trial's statistics from its frames' counts and the work's time per frame (ms);
    /// `None` when no frame counted.
    pub fn of(counts: &[WorkCounts], main_ms: f64) -> Option<WorkTrial> {
        let first = counts.first()?;
        let counts = first
            .iter()
            .map(|(key, _)| {
                let all: Vec<u64> = counts.iter().filter_map(|c| c.get(key)).collect();
                CountStats {
                    key: key.to_string(),
                    mean: stats::mean(&all.iter().map(|&v| v as f64).collect::<Vec<_>>()),
                    min: all.iter().copied().min(),
                    max: all.iter().copied().max(),
                }
            })
            .collect();
        Some(WorkTrial { main_ms, counts })
    }

    /// The count under `key`.
    pub fn count(&self, key: &str) -> Option<&CountStats> {
        self.counts.iter().find(|c| c.key == key)
    }
}

/// A trial as results files hold it: keyed, or spray's particle record from before counts
/// were keyed (schema 6 and before), read back into the same keys spray counts under today.
#[derive(Deserialize)]
#[serde(untagged)]
enum TrialRepr {
    Keyed {
        main_ms: f64,
        counts: Vec<CountStats>,
    },
    Particles {
        live_mean: f64,
        live_min: u64,
        live_max: u64,
        emitted_per_frame: f64,
        recycled_per_frame: f64,
        main_ms: f64,
    },
}

impl From<TrialRepr> for WorkTrial {
    fn from(r: TrialRepr) -> WorkTrial {
        match r {
            TrialRepr::Keyed { main_ms, counts } => WorkTrial { main_ms, counts },
            TrialRepr::Particles {
                live_mean,
                live_min,
                live_max,
                emitted_per_frame,
                recycled_per_frame,
                main_ms,
            } => {
                let mean_only = |key: &str, mean| CountStats {
                    key: key.into(),
                    mean,
                    min: None,
                    max: None,
                };
                WorkTrial {
                    main_ms,
                    counts: vec![
                        CountStats {
                            key: "live".into(),
                            mean: live_mean,
                            min: Some(live_min),
                            max: Some(live_max),
                        },
                        mean_only("emitted", emitted_per_frame),
                        mean_only("recycled", recycled_per_frame),
                    ],
                }
            }
        }
    }
}

/// A kind's own record of its work in a loop or a cell (fog: its volume, octaves and the time
/// of each part of its pass): named numbers in the kind's order, a JSON object in results.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WorkRecord(Vec<(String, f64)>);

impl WorkRecord {
    /// The record with `value` under `key` added.
    pub fn with(mut self, key: &str, value: f64) -> WorkRecord {
        self.0.push((key.to_string(), value));
        self
    }

    /// Each key with its value, in the kind's order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> {
        self.0.iter().map(|(k, v)| (k.as_str(), *v))
    }

    /// The value under `key`.
    pub fn get(&self, key: &str) -> Option<f64> {
        self.iter().find(|(k, _)| *k == key).map(|(_, v)| v)
    }

    /// One record for a cell from its trials' records: each value's median over them, under
    /// the first record's keys.
    pub fn of_trials(records: &[WorkRecord]) -> Option<WorkRecord> {
        let first = records.first()?;
        Some(WorkRecord(
            first
                .iter()
                .map(|(key, _)| {
                    let all: Vec<f64> = records.iter().filter_map(|r| r.get(key)).collect();
                    (key.to_string(), stats::median(&all))
                })
                .collect(),
        ))
    }
}

impl Serialize for WorkRecord {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(self.iter())
    }
}

impl<'de> Deserialize<'de> for WorkRecord {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<WorkRecord, D::Error> {
        d.deserialize_map(RecordVisitor)
    }
}

/// Reads a record in its file order; a record from before records were keyed (schema 6 and before)
/// is one object under the kind's name (`{"fog": {...}}`) and reads back as that object.
struct RecordVisitor;

impl<'de> Visitor<'de> for RecordVisitor {
    type Value = WorkRecord;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an object of named numbers")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<WorkRecord, A::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Entry {
            Number(f64),
            Nested(WorkRecord),
        }
        let mut out = Vec::new();
        while let Some((key, entry)) = map.next_entry::<String, Entry>()? {
            match entry {
                Entry::Number(v) => out.push((key, v)),
                Entry::Nested(inner) => out.extend(inner.0),
            }
        }
        Ok(WorkRecord(out))
    }
}
