//! The sizes the FFT ocean runs at: even N from 16 to 4096 whose only prime factors are 2, 3
//! and 5, the lengths rustfft's mixed-radix plans take fastest (so 40, the paper's smallest
//! mesh, and 1536 work).

use crate::input::InputError;

/// The smallest N accepted.
pub const MIN: usize = 16;
/// The largest N accepted.
pub const MAX: usize = super::super::mesh::MAX_SIZE;

/// The only prime factors a size may have.
pub const PRIMES: [usize; 3] = [2, 3, 5];

/// Whether the FFT ocean runs at size `n`.
pub fn valid(n: usize) -> bool {
    n.is_multiple_of(2) && (MIN..=MAX).contains(&n) && {
        let mut m = n;
        for p in PRIMES {
            while m.is_multiple_of(p) {
                m /= p;
            }
        }
        m == 1
    }
}

/// Refuses a size that is not [`valid`], naming the rule and the nearest valid sizes.
pub fn check_size(n: usize) -> Result<(), InputError> {
    if valid(n) {
        return Ok(());
    }
    let below = (MIN..n.min(MAX + 1)).rev().find(|&m| valid(m));
    let above = (n.max(MIN - 1) + 1..=MAX).find(|&m| valid(m));
    let nearest: Vec<String> = [below, above]
        .into_iter()
        .flatten()
        .map(|m| m.to_string())
        .collect();
    Err(InputError(format!(
        "size: the fft ocean needs an even N from {MIN} to {MAX} whose only prime factors are 2, \
         3 and 5; got {n} (nearest: {})",
        nearest.join(", ")
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_and_the_nearest_sizes() {
        for n in [16, 40, 64, 128, 256, 512, 1536, 4096, 18, 30, 3840] {
            assert!(valid(n), "{n}");
        }
        for n in [0, 2, 8, 15, 97, 98, 14, 42, 4098, 5000, 1000 + 1] {
            assert!(!valid(n), "{n}");
        }
        let msg = |n| check_size(n).unwrap_err().0;
        assert!(
            msg(97).ends_with("got 97 (nearest: 96, 100)"),
            "{}",
            msg(97)
        );
        assert!(msg(0).ends_with("got 0 (nearest: 16)"), "{}", msg(0));
        assert!(
            msg(5000).ends_with("got 5000 (nearest: 4096)"),
            "{}",
            msg(5000)
        );
        assert!(msg(41).ends_with("(nearest: 40, 48)"), "{}", msg(41));
    }
}
