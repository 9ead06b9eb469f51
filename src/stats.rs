//! The statistics every measurement uses, each with one definition: quantiles by nearest rank
//! (so the median is the lower middle value of an even count), the mean, the sample standard
//! deviation, and a seeded percentile bootstrap of the change between two means.

/// Values sorted ascending, for quantiles (NaN last, by `total_cmp`).
pub fn sorted(values: &[f64]) -> Vec<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v
}

/// The value at quantile `q` (0 to 1) of sorted values, by nearest rank: the smallest value
/// with at least q·n values at or below it; q = 0 gives the smallest. NaN for no values.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// The median by nearest rank of unsorted values (the lower middle one of an even count).
pub fn median(values: &[f64]) -> f64 {
    quantile(&sorted(values), 0.5)
}

/// The arithmetic mean; NaN for no values.
pub fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// The sample standard deviation (n − 1 in the denominator); 0 for fewer than two values.
pub fn stddev(values: &[f64]) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    let m = mean(values);
    let squares: f64 = values.iter().map(|v| (v - m).powi(2)).sum();
    (squares / (values.len() - 1) as f64).sqrt()
}

/// The smallest and largest value; (∞, −∞) for none.
pub fn min_max(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// The 95% percentile interval of the change of mean(`new`) against mean(`base`), in percent,
/// from `resamples` bootstrap resamples of each side drawn with a generator seeded by `seed`:
/// the same inputs always give the same interval.
pub fn bootstrap_change_pct(base: &[f64], new: &[f64], resamples: usize, seed: u64) -> (f64, f64) {
    let mut rng = SplitMix64(seed);
    let mut resample = |xs: &[f64]| {
        let sum: f64 = (0..xs.len()).map(|_| xs[rng.below(xs.len())]).sum();
        sum / xs.len() as f64
    };
    let changes: Vec<f64> = (0..resamples)
        .map(|_| {
            let b = resample(base);
            let n = resample(new);
            (n / b - 1.0) * 100.0
        })
        .collect();
    let changes = sorted(&changes);
    (
        quantile(&changes, INTERVAL_TAILS.0),
        quantile(&changes, INTERVAL_TAILS.1),
    )
}

/// The quantiles that bound a 95 % percentile bootstrap interval.
pub const INTERVAL_TAILS: (f64, f64) = (0.025, 0.975);

/// SplitMix64: a tiny, well-mixed generator, for resampling that must repeat exactly.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` by multiply-shift; the bias is far below anything a 95% interval shows.
    pub fn below(&mut self, n: usize) -> usize {
        ((u128::from(self.next_u64()) * n as u128) >> 64) as usize
    }
}

/// FNV-1a of `s`: a seed derived from a name, so a result does not depend on what ran before.
pub fn seed_from(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_by_nearest_rank() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 0.25), 1.0);
        assert_eq!(quantile(&v, 0.26), 2.0);
        assert_eq!(quantile(&v, 0.5), 2.0, "the lower middle of an even count");
        assert_eq!(quantile(&v, 0.99), 4.0);
        assert_eq!(quantile(&v, 1.0), 4.0);
        assert!(quantile(&[], 0.5).is_nan());
        assert_eq!(quantile(&[7.0], 0.5), 7.0);
    }

    #[test]
    fn median_sorts_and_takes_the_middle() {
        assert_eq!(median(&[5.0, 1.0, 3.0]), 3.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.0);
        assert_eq!(median(&[2.0, 2.0, 2.0, 2.0]), 2.0);
    }

    #[test]
    fn mean_spread_and_extremes() {
        let v = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0];
        assert_eq!(mean(&v), 5.0);
        assert!((stddev(&v) - (32.0f64 / 7.0).sqrt()).abs() < 1e-12);
        assert_eq!(stddev(&[3.0]), 0.0);
        assert_eq!(stddev(&[1.0, 3.0]), 2f64.sqrt(), "two values have a spread");
        assert_eq!(min_max(&v), (2.0, 9.0));
        assert!(mean(&[]).is_nan());
    }

    #[test]
    fn the_bootstrap_repeats_and_brackets_the_change() {
        let base = [100.0, 102.0, 98.0, 101.0, 99.0];
        let new = [110.0, 112.0, 108.0, 111.0, 109.0];
        let a = bootstrap_change_pct(&base, &new, 2000, 7);
        assert_eq!(a, bootstrap_change_pct(&base, &new, 2000, 7), "seeded");
        assert!(a.0 < 10.0 && 10.0 < a.1 && a.0 > 5.0 && a.1 < 15.0, "{a:?}");
        let same = bootstrap_change_pct(&base, &base, 2000, 7);
        assert!(same.0 < 0.0 && same.1 > 0.0, "{same:?}");
    }

    /// Hand-computed bounds: against a constant base, resampled means of four 100s and four 200s
    /// change by 12.5·k % with k ~ Binomial(8, ½), whose CDF is 0.0352 at k = 1 and 0.9648 at
    /// k = 6. The 2.5 % point is therefore k = 1 and the 97.5 % point k = 7; a 5 %/95 %
    /// interval would give k = 2 and 6.
    #[test]
    fn the_bootstrap_takes_the_2_5_and_97_5_percent_points() {
        let base = [100.0; 8];
        let new = [100.0, 100.0, 100.0, 100.0, 200.0, 200.0, 200.0, 200.0];
        assert_eq!(bootstrap_change_pct(&base, &new, 10_000, 3), (12.5, 87.5));
        // Equal values on sides of different lengths change by nothing at all.
        assert_eq!(
            bootstrap_change_pct(&[100.0; 3], &[100.0; 7], 1_000, 3),
            (0.0, 0.0)
        );
    }

    /// SplitMix64's published first output for seed 0 (Vigna's reference implementation):
    /// the committed intervals can be reproduced only with this exact generator.
    #[test]
    fn the_generator_is_splitmix64() {
        assert_eq!(SplitMix64(0).next_u64(), 0xE220_A839_7B1D_CDAF);
    }

    #[test]
    fn the_generator_is_uniform_enough_and_seeds_differ_by_name() {
        let mut rng = SplitMix64(1);
        let mut counts = [0usize; 4];
        for _ in 0..40_000 {
            counts[rng.below(4)] += 1;
        }
        assert!(
            counts.iter().all(|&c| (9_000..11_000).contains(&c)),
            "{counts:?}"
        );
        assert_ne!(seed_from("256 w2 dp"), seed_from("256 w2 up"));
    }

    /// FNV-1a's published 64-bit values (the offset basis for "", and "a", "foobar"): the
    /// committed intervals are seeded by cell names through exactly this hash.
    #[test]
    fn the_seed_is_fnv_1a() {
        assert_eq!(seed_from(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(seed_from("a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(seed_from("foobar"), 0x8594_4171_f739_67e8);
    }
}
