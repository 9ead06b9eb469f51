//! Where the two measured cores sat relative to each other. On a shared VM the hypervisor moves
//! the two vCPUs between pairs of physical cores mid-run: near (two hardware threads of one
//! core, or two cores sharing a cache) or far (two cores on different dies), and the cache-line
//! round trip between them tells the two apart. A DP trial on near cores is a different
//! experiment from one on far cores, so every trial and balance probe is classified from the
//! round trips measured around it, against the run's own distribution of round trips: one
//! cluster (one placement throughout), or two (near and far).
//!
//! This module holds the classes and the rules, below the results that carry them;
//! [`crate::findings::placement`] places a results file's trials and draws what the run shows
//! from them. Everything here is plain data in, facts out: no measuring, no I/O.

use crate::crosscore::PLACEMENT_CHANGE_RATIO;
use serde::{Deserialize, Serialize};

crate::named! {
    /// Where a trial (or probe) ran, from the round trips around it.
    pub enum Class {
        /// The run's round trips form one cluster: one placement throughout.
        One,
        /// The faster of the run's two clusters of round trips.
        Near,
        /// The slower of the two.
        Far,
        /// The round trips around it fell in different clusters: the cores moved during it.
        Moved,
    }
}

/// A run's round trips, as one cluster or two.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Split {
    /// Fastest and slowest round trip of the near cluster, or of the only one (ns).
    pub near_ns: [f64; 2],
    /// Round trips in it.
    pub near_count: usize,
    /// Fastest and slowest round trip of the far cluster, when there are two (ns).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub far_ns: Option<[f64; 2]>,
    /// Round trips in it.
    #[serde(default)]
    pub far_count: usize,
    /// Round trips in neither cluster (a ping-pong preempted while it was timed).
    #[serde(default)]
    pub outliers: usize,
}

/// A value belongs to a cluster when it lies within this factor of its span: half the gap
/// (in log terms) that separates two clusters.
fn margin() -> f64 {
    PLACEMENT_CHANGE_RATIO.sqrt()
}

impl Split {
    /// The clusters of `round_trips` (ns; non-positive and non-finite values are ignored):
    /// sorted values are cut wherever one is more than [`PLACEMENT_CHANGE_RATIO`] times the one
    /// before; groups of at least two values are clusters (every group when none is), and the
    /// two most populous are near and far. `None` without a round trip.
    pub fn of(round_trips: impl IntoIterator<Item = f64>) -> Option<Split> {
        let mut v: Vec<f64> = round_trips
            .into_iter()
            .filter(|x| x.is_finite() && *x > 0.0)
            .collect();
        v.sort_by(f64::total_cmp);
        let mut groups: Vec<&[f64]> = v
            .chunk_by(|a, b| b <= &(a * PLACEMENT_CHANGE_RATIO))
            .collect();
        if groups.is_empty() {
            return None;
        }
        if groups.iter().any(|g| g.len() >= 2) {
            groups.retain(|g| g.len() >= 2);
        }
        // The two most populous; among equals, the faster first (a stable sort keeps order).
        let mut ranked = groups.clone();
        ranked.sort_by_key(|g| std::cmp::Reverse(g.len()));
        ranked.truncate(2);
        ranked.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let span = |g: &[f64]| [g[0], g[g.len() - 1]];
        let clustered: usize = ranked.iter().map(|g| g.len()).sum();
        Some(Split {
            near_ns: span(ranked[0]),
            near_count: ranked[0].len(),
            far_ns: ranked.get(1).map(|g| span(g)),
            far_count: ranked.get(1).map_or(0, |g| g.len()),
            outliers: v.len() - clustered,
        })
    }

    /// Whether the round trips form two clusters.
    pub fn two(&self) -> bool {
        self.far_ns.is_some()
    }

    /// The class of one round trip; `None` for a value in neither cluster.
    pub fn class(&self, ns: f64) -> Option<Class> {
        let within = |[lo, hi]: [f64; 2]| ns >= lo / margin() && ns <= hi * margin();
        match self.far_ns {
            None => within(self.near_ns).then_some(Class::One),
            Some(far) if within(self.near_ns) => Some(Class::Near).filter(|_| !within(far)),
            Some(far) => within(far).then_some(Class::Far),
        }
    }

    /// The class of something measured between round trips `ns` (a trial's before and after, a
    /// probe's before every round and after the last): the one class all placed values share,
    /// [`Class::Moved`] when they differ, `None` when none is placed.
    pub fn class_of(&self, ns: &[f64]) -> Option<Class> {
        let mut classes = ns.iter().filter_map(|&x| self.class(x));
        let first = classes.next()?;
        Some(if classes.all(|c| c == first) {
            first
        } else {
            Class::Moved
        })
    }

    /// The round trips of `class`, fastest and slowest (ns).
    pub fn span(&self, class: Class) -> Option<[f64; 2]> {
        match class {
            Class::One | Class::Near => Some(self.near_ns),
            Class::Far => self.far_ns,
            Class::Moved => None,
        }
    }

    /// `one placement, round trip 41-64 ns` or `two placements: near 41-64 ns (N round
    /// trips), far 363-402 ns (M)`.
    pub fn describe(&self) -> String {
        let ns = |[lo, hi]: [f64; 2]| {
            if (hi - lo).abs() < 0.5 {
                format!("{lo:.0} ns")
            } else {
                format!("{lo:.0}-{hi:.0} ns")
            }
        };
        // A lone round trip far from the rest is no cluster, but it may be the only sign of a
        // move, so the line never drops it silently.
        let outliers = match self.outliers {
            0 => String::new(),
            1 => " (and 1 round trip in neither)".to_string(),
            n => format!(" (and {n} round trips in neither)"),
        };
        match self.far_ns {
            None => format!(
                "one placement, round trip {}{}",
                ns(self.near_ns),
                outliers.replace("in neither", "outside it")
            ),
            Some(far) => format!(
                "two placements: near {} ({} round trips), far {} ({}){outliers}",
                ns(self.near_ns),
                self.near_count,
                ns(far),
                self.far_count
            ),
        }
    }
}

/// Whether trials of these classes mixed placements: some near and some far, or one that moved.
pub fn mixed(classes: &[Option<Class>]) -> bool {
    let has = |c: Class| classes.contains(&Some(c));
    (has(Class::Near) && has(Class::Far)) || has(Class::Moved)
}

/// When trials of these classes mixed placements, the placement that holds `trials` of them.
pub fn settled(classes: &[Option<Class>], trials: usize) -> Option<Class> {
    if !mixed(classes) {
        return None;
    }
    [Class::Near, Class::Far]
        .into_iter()
        .find(|&c| classes.iter().filter(|&&x| x == Some(c)).count() >= trials)
}

/// Whether a cell whose trials have these classes needs another round: they mixed placements
/// and no placement holds `trials` of them yet.
pub fn needs_round(classes: &[Option<Class>], trials: usize) -> bool {
    mixed(classes) && settled(classes, trials).is_none()
}

/// Which trials a cell keeps: those of the placement that holds `trials` of them when they
/// mixed placements, else every one.
pub fn kept(classes: &[Option<Class>], trials: usize) -> Vec<bool> {
    match settled(classes, trials) {
        Some(class) => classes.iter().map(|&c| c == Some(class)).collect(),
        None => vec![true; classes.len()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_cluster_is_one_placement() {
        let s = Split::of([50.0, 52.0, 61.0, 48.0]).unwrap();
        assert!(!s.two());
        assert_eq!(s.near_ns, [48.0, 61.0]);
        assert_eq!(s.class(55.0), Some(Class::One));
        assert_eq!(
            s.class(5_000.0),
            None,
            "a preempted ping-pong is no placement"
        );
        assert_eq!(s.class_of(&[50.0, 60.0]), Some(Class::One));
        assert!(s
            .describe()
            .starts_with("one placement, round trip 48-61 ns"));
    }

    #[test]
    fn two_clusters_are_near_and_far() {
        let s = Split::of([41.0, 64.0, 50.0, 363.0, 402.0, 390.0, 52.0]).unwrap();
        assert_eq!(s.near_ns, [41.0, 64.0]);
        assert_eq!(s.far_ns, Some([363.0, 402.0]));
        assert_eq!((s.near_count, s.far_count, s.outliers), (4, 3, 0));
        assert_eq!(s.class(45.0), Some(Class::Near));
        assert_eq!(s.class(380.0), Some(Class::Far));
        assert_eq!(s.class_of(&[45.0, 380.0]), Some(Class::Moved));
        assert_eq!(
            s.class_of(&[45.0, 9_000.0]),
            Some(Class::Near),
            "an outlier says nothing"
        );
        assert_eq!(s.class_of(&[]), None);
    }

    #[test]
    fn a_lone_outlier_is_not_a_cluster() {
        let s = Split::of([50.0, 52.0, 55.0, 4_000.0]).unwrap();
        assert!(!s.two());
        assert_eq!(s.outliers, 1);
        // Two values alone, far apart, are two placements.
        let s = Split::of([50.0, 400.0]).unwrap();
        assert!(s.two());
        assert_eq!(Split::of([f64::NAN, 0.0]), None);
    }

    #[test]
    fn a_mixed_cell_keeps_the_placement_that_reached_its_trials() {
        let (n, f, m) = (Some(Class::Near), Some(Class::Far), Some(Class::Moved));
        assert!(!mixed(&[n, n, None]));
        assert!(mixed(&[n, f]) && mixed(&[n, m]));
        // Three trials: near, far, near. Not settled: it needs a round.
        assert!(needs_round(&[n, f, n], 3));
        assert_eq!(settled(&[n, f, n], 3), None);
        assert_eq!(
            kept(&[n, f, n], 3),
            [true; 3],
            "unsettled: every trial kept"
        );
        // A fourth, near: near holds three, the far one is set aside.
        assert_eq!(settled(&[n, f, n, n], 3), Some(Class::Near));
        assert!(!needs_round(&[n, f, n, n], 3));
        assert_eq!(kept(&[n, f, n, n], 3), [true, false, true, true]);
        // One placement throughout needs nothing.
        assert!(!needs_round(&[f, f], 3));
        assert_eq!(kept(&[f, f], 3), [true, true]);
    }

    #[test]
    fn a_ratio_just_under_the_rule_is_one_cluster() {
        let s = Split::of([100.0, 199.0]).unwrap();
        assert!(!s.two());
        let s = Split::of([100.0, 201.0, 100.0, 201.0]).unwrap();
        assert!(s.two());
    }
}
