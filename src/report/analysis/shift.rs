//! How balance points moved between two runs: the shift of the balance workload and of the
//! speed-up there, each with an interval from the two runs' own.

use crate::cell::Dim;
use crate::results::balance::BalanceEntry;
use crate::results::Results;
use serde::{Deserialize, Serialize};

/// One searched cell in both runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BalanceShift {
    /// The cell.
    pub label: String,
    /// Balance workload in the base run and in the new one (µs).
    pub base_us: f64,
    /// The new run's.
    pub new_us: f64,
    /// New minus base, with the interval the two brackets allow (µs).
    pub shift_us: [f64; 3],
    /// The same as a percentage of the base run's step.
    pub shift_percent_of_step: f64,
    /// DP ÷ serial at the balance point, base and new.
    pub base_peak: f64,
    /// The new run's.
    pub new_peak: f64,
    /// New ÷ base − 1 of the peak speed-up in percent, with the interval the two 95% intervals
    /// allow.
    pub peak_change_pct: [f64; 3],
}

impl BalanceShift {
    fn of(base: &BalanceEntry, new: &BalanceEntry) -> Option<BalanceShift> {
        let (b, bl, bh) = (
            base.balance_us?,
            base.balance_us_low?,
            base.balance_us_high?,
        );
        let (n, nl, nh) = (new.balance_us?, new.balance_us_low?, new.balance_us_high?);
        let (p, pl, ph) = (
            base.dp_over_serial?,
            base.dp_over_serial_low?,
            base.dp_over_serial_high?,
        );
        let (q, ql, qh) = (
            new.dp_over_serial?,
            new.dp_over_serial_low?,
            new.dp_over_serial_high?,
        );
        let pct = |v: f64| 100.0 * (v - 1.0);
        Some(BalanceShift {
            label: base.key.label_without(&[Dim::Workload]),
            base_us: b,
            new_us: n,
            shift_us: [n - b, nl - bh, nh - bl],
            shift_percent_of_step: 100.0 * (n - b) / base.step_us,
            base_peak: p,
            new_peak: q,
            peak_change_pct: [pct(q / p), pct(ql / ph), pct(qh / pl)],
        })
    }

    /// One line for a terminal or a list.
    pub fn line(&self) -> String {
        let [s, sl, sh] = self.shift_us;
        let [c, cl, ch] = self.peak_change_pct;
        format!(
            "{}: balance {:.0} → {:.0} µs ({s:+.0} µs [{sl:+.0}, {sh:+.0}], {:+.1}% of the step); DP ÷ serial there {:.2} → {:.2} ({c:+.1}% [{cl:+.1}, {ch:+.1}])",
            self.label,
            self.base_us,
            self.new_us,
            self.shift_percent_of_step,
            self.base_peak,
            self.new_peak
        )
    }
}

/// Every cell searched in both runs, matched by its key.
pub fn between(base: &Results, new: &Results) -> Vec<BalanceShift> {
    base.balance
        .iter()
        .filter_map(|b| {
            let n = new.balance.iter().find(|n| n.key == b.key)?;
            BalanceShift::of(b, n)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::CellKey;
    use std::path::Path;

    fn run(name: &str) -> Results {
        Results::load(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("results")
                .join(name),
        )
        .unwrap()
    }

    /// A searched cell of a committed run with its figures replaced: the step, the balance
    /// bracket (middle, low, high) and DP ÷ serial there (value, low, high).
    fn entry(like: &BalanceEntry, step: f64, balance: [f64; 3], peak: [f64; 3]) -> BalanceEntry {
        BalanceEntry {
            step_us: step,
            balance_us: Some(balance[0]),
            balance_us_low: Some(balance[1]),
            balance_us_high: Some(balance[2]),
            dp_over_serial: Some(peak[0]),
            dp_over_serial_low: Some(peak[1]),
            dp_over_serial_high: Some(peak[2]),
            ..like.clone()
        }
    }

    fn searched() -> BalanceEntry {
        let r = run("balance-256-run1-20261127T060957Z");
        r.balance
            .into_iter()
            .find(|e| e.balance_us.is_some())
            .expect("a cell with a balance point")
    }

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn a_shift_is_new_minus_base_with_the_intervals_crossed() {
        let like = searched();
        let base = entry(&like, 400.0, [500.0, 480.0, 520.0], [1.6, 1.5, 1.7]);
        // The new run's step is not the unit: the shift is a share of the base run's.
        let new = entry(&like, 999.0, [560.0, 550.0, 575.0], [1.8, 1.74, 1.9]);
        let s = BalanceShift::of(&base, &new).unwrap();
        assert_eq!(s.label, like.key.label_without(&[Dim::Workload]));
        assert!(!s.label.contains(" w"), "no workload in {}", s.label);
        assert_eq!((s.base_us, s.new_us), (500.0, 560.0));
        assert_eq!(s.shift_us, [60.0, 30.0, 95.0]);
        assert!(near(s.shift_percent_of_step, 15.0));
        assert_eq!((s.base_peak, s.new_peak), (1.6, 1.8));
        let [c, lo, hi] = s.peak_change_pct;
        assert!(near(c, 12.5), "{c}");
        assert!(near(lo, 100.0 * (1.74 / 1.7 - 1.0)), "{lo}");
        assert!(near(hi, 100.0 * (1.9 / 1.5 - 1.0)), "{hi}");
        assert!(lo < c && c < hi);
        assert_eq!(
            s.line(),
            format!(
                "{}: balance 500 → 560 µs (+60 µs [+30, +95], +15.0% of the step); DP ÷ serial there 1.60 → 1.80 (+12.5% [+2.4, +26.7])",
                s.label
            )
        );
    }

    #[test]
    fn a_cell_missing_any_figure_in_either_run_has_no_shift() {
        let like = searched();
        let full = entry(&like, 400.0, [500.0, 480.0, 520.0], [1.6, 1.5, 1.7]);
        let holes: [fn(&mut BalanceEntry); 6] = [
            |e| e.balance_us = None,
            |e| e.balance_us_low = None,
            |e| e.balance_us_high = None,
            |e| e.dp_over_serial = None,
            |e| e.dp_over_serial_low = None,
            |e| e.dp_over_serial_high = None,
        ];
        assert!(BalanceShift::of(&full, &full).is_some());
        for (k, hole) in holes.iter().enumerate() {
            let mut holed = full.clone();
            hole(&mut holed);
            assert_eq!(BalanceShift::of(&holed, &full), None, "base, hole {k}");
            assert_eq!(BalanceShift::of(&full, &holed), None, "new, hole {k}");
        }
    }

    #[test]
    fn runs_are_matched_cell_by_cell() {
        let (mut base, mut new) = (
            run("balance-256-run1-20261127T060957Z"),
            run("balance-256-run2-20261127T061038Z"),
        );
        let one = BalanceShift::of(&base.balance[0], &new.balance[0]).unwrap();
        assert_eq!(between(&base, &new), vec![one.clone()]);
        // A second cell searched in both, listed in a different order, and a third searched
        // in the base run alone.
        let like = base.balance[0].clone();
        let at = |size: usize, figures: f64| BalanceEntry {
            key: CellKey {
                size,
                ..like.key.clone()
            },
            ..entry(
                &like,
                400.0,
                [figures, figures - 10.0, figures + 10.0],
                [1.6, 1.5, 1.7],
            )
        };
        base.balance.insert(0, at(512, 500.0));
        base.balance.push(at(1024, 900.0));
        new.balance.push(at(512, 530.0));
        let shifts = between(&base, &new);
        assert_eq!(shifts.len(), 2, "{shifts:?}");
        assert_eq!((shifts[0].base_us, shifts[0].new_us), (500.0, 530.0));
        assert_eq!(shifts[1], one);
        // A run searched nowhere shifts nothing.
        let none = Results {
            balance: Vec::new(),
            ..new.clone()
        };
        assert!(between(&base, &none).is_empty() && between(&none, &new).is_empty());
    }
}
