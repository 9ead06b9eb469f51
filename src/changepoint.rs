//! Change points in a series of runs, by binary segmentation with a permutation test, as
//! E-Divisive means (Matteson and James, as MongoDB uses it) finds them, with the difference of
//! means in place of the energy distance: in a segment, the split whose two sides' means differ
//! most (weighted by √(k(m−k)/m), so a split near an end needs a larger step) is a change when
//! fewer than [`ALPHA`] of the segment's seeded shuffles give a split as strong; each side is
//! then searched again.

use crate::stats::{self, SplitMix64};

/// The share of shuffles that may match a split for it still to count as a change.
pub const ALPHA: f64 = 0.01;

/// Shuffles per test: enough to resolve [`ALPHA`].
pub const PERMUTATIONS: usize = 999;

/// The fewest values each side of a change must hold.
pub const MIN_SEGMENT: usize = 2;

/// A change: the index of the first value after it, and the means of the segments either side.
#[derive(Clone, Debug, PartialEq)]
pub struct ChangePoint {
    /// The first index of the segment the change starts.
    pub at: usize,
    /// The mean of the segment before.
    pub before: f64,
    /// The mean of the segment it starts.
    pub after: f64,
}

impl ChangePoint {
    /// The change in percent of the mean before.
    pub fn percent(&self) -> f64 {
        100.0 * (self.after - self.before) / self.before
    }
}

/// The strongest split of `values` and its strength; `None` when too short to split.
fn best_split(values: &[f64]) -> Option<(usize, f64)> {
    let m = values.len();
    if m < 2 * MIN_SEGMENT {
        return None;
    }
    let total: f64 = values.iter().sum();
    let mut left = 0.0;
    let mut best: Option<(usize, f64)> = None;
    for (i, &v) in values[..m - MIN_SEGMENT].iter().enumerate() {
        left += v;
        // k values lie before the split.
        let k = i + 1;
        if k < MIN_SEGMENT {
            continue;
        }
        let (kf, mf) = (k as f64, m as f64);
        let diff = left / kf - (total - left) / (mf - kf);
        let strength = diff.abs() * (kf * (mf - kf) / mf).sqrt();
        if best.is_none_or(|(_, s)| strength > s) {
            best = Some((k, strength));
        }
    }
    best
}

/// Whether the split of strength `observed` in `values` beats all but [`ALPHA`] of its shuffles.
fn significant(values: &[f64], observed: f64, rng: &mut SplitMix64) -> bool {
    let mut shuffled = values.to_vec();
    let mut as_strong = 0;
    for _ in 0..PERMUTATIONS {
        for i in (1..shuffled.len()).rev() {
            shuffled.swap(i, rng.below(i + 1));
        }
        if best_split(&shuffled).is_some_and(|(_, s)| s >= observed) {
            as_strong += 1;
        }
    }
    (as_strong + 1) as f64 / (PERMUTATIONS + 1) as f64 <= ALPHA
}

/// The change points of `values`, in order; the shuffles are drawn from `seed`, so the same
/// series always gives the same changes.
pub fn detect(values: &[f64], seed: u64) -> Vec<ChangePoint> {
    let mut rng = SplitMix64(seed);
    let mut cuts = Vec::new();
    let mut segments = vec![(0, values.len())];
    while let Some((a, b)) = segments.pop() {
        let Some((k, strength)) = best_split(&values[a..b]) else {
            continue;
        };
        if significant(&values[a..b], strength, &mut rng) {
            cuts.push(a + k);
            segments.push((a, a + k));
            segments.push((a + k, b));
        }
    }
    cuts.sort_unstable();
    let bounds: Vec<usize> = std::iter::once(0)
        .chain(cuts.iter().copied())
        .chain(std::iter::once(values.len()))
        .collect();
    bounds
        .windows(3)
        .map(|w| ChangePoint {
            at: w[1],
            before: stats::mean(&values[w[0]..w[1]]),
            after: stats::mean(&values[w[1]..w[2]]),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values around 100 with a spread of about 1 %, from a seeded generator.
    fn noisy(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = SplitMix64(seed);
        (0..n)
            .map(|_| 100.0 + (rng.below(2001) as f64 - 1000.0) / 1000.0)
            .collect()
    }

    #[test]
    fn a_ten_percent_drop_at_run_6_is_found_there() {
        let mut values = noisy(10, 1);
        values[5..].iter_mut().for_each(|v| *v *= 0.9);
        let found = detect(&values, 7);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].at, 5);
        assert!((found[0].percent() + 10.0).abs() < 2.0, "{found:?}");
    }

    #[test]
    fn unchanged_series_give_at_most_one_false_change_in_five() {
        let found: usize = (0..5).map(|s| detect(&noisy(10, 100 + s), s).len()).sum();
        assert!(found <= 1, "{found} false changes");
    }

    #[test]
    fn the_same_series_gives_the_same_changes() {
        let mut values = noisy(12, 3);
        values[4..].iter_mut().for_each(|v| *v *= 1.1);
        assert_eq!(detect(&values, 9), detect(&values, 9));
    }
}
