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
