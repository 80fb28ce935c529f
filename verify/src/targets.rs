//! The place-and-route targets of issue 8, as data, and the one function
//! that checks reports against them.
//!
//! A target is met when the design fits the part (every resource within
//! its capacity, and nextpnr placed and routed it) and the Fmax nextpnr
//! reports is at least the target frequency. Each target's frequency is
//! the `--freq` its part is run at ([`crate::pnr::Part::freq_mhz`]), so the
//! limit is defined once; the stretch goal is reported, never asserted.
//!
//! Which targets the test suite asserts is one line in `tests/verilog_pnr.rs`.

use crate::pnr::{ECP5_25F, ICE40_UP5K, PnrReport};
use std::fmt::Write as _;

/// A target for one part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// The part's key ([`crate::pnr::Part::key`]).
    pub part_key: &'static str,
    /// The least Fmax, MHz.
    pub min_fmax_mhz: f64,
    /// A stretch Fmax, MHz, reported beside the target.
    pub stretch_fmax_mhz: Option<f64>,
}

/// The targets: ECP5 25F at 100 MHz (stretch 125 MHz, the clock of common
/// 125 MS/s converter boards), iCE40 UP5K at 30 MHz.
pub const TARGETS: [Target; 2] = [
    Target {
        part_key: ICE40_UP5K.key,
        min_fmax_mhz: ICE40_UP5K.freq_mhz as f64,
        stretch_fmax_mhz: None,
    },
    Target {
        part_key: ECP5_25F.key,
        min_fmax_mhz: ECP5_25F.freq_mhz as f64,
        stretch_fmax_mhz: Some(125.0),
    },
];

/// The target of a part, if it has one.
pub fn target_of(part_key: &str) -> Option<&'static Target> {
    TARGETS.iter().find(|t| t.part_key == part_key)
}

/// Why `report` misses `target`: one line per reason, empty when met.
pub fn misses(report: &PnrReport, target: &Target) -> Vec<String> {
    let part = report.part.name;
    let mut why = Vec::new();
    for u in report.uses.iter().filter(|u| !u.fits()) {
        why.push(format!(
            "{part}: {} {} of {} does not fit",
            u.used, u.label, u.available
        ));
    }
    match report.fmax_mhz() {
        None => why.push(format!("{part}: not placed and routed, no Fmax")),
        Some(f) if f < target.min_fmax_mhz => why.push(format!(
            "{part}: Fmax {f:.2} MHz below the target {:.0} MHz",
            target.min_fmax_mhz
        )),
        Some(_) => {}
    }
    why
}

/// Every miss of `targets` among `reports`; a target whose part has no
/// report is a miss too. Empty when every target is met.
pub fn check(reports: &[PnrReport], targets: &[Target]) -> Vec<String> {
    let mut why = Vec::new();
    for t in targets {
        match reports.iter().find(|r| r.part.key == t.part_key) {
            Some(r) => why.extend(misses(r, t)),
            None => why.push(format!("{}: no place-and-route report", t.part_key)),
        }
    }
    why
}

/// "yes", or "no" with the reasons, for the report's table.
pub fn verdict(report: &PnrReport, target: &Target) -> String {
    let why = misses(report, target);
    let mut s = if why.is_empty() {
        "yes".to_owned()
    } else {
        "**no**".to_owned()
    };
    if let (Some(stretch), Some(f)) = (target.stretch_fmax_mhz, report.fmax_mhz()) {
        let met = if f >= stretch { "met" } else { "missed" };
        let _ = write!(s, " (stretch {stretch:.0} MHz {met})");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pnr::{ECP5_25F, Outcome, PnrReport, Use};
    use crate::pnr_log::Fmax;
    use std::time::Duration;

    fn report(mult: u64, fmax_mhz: Option<f64>) -> PnrReport {
        let outcome = match fmax_mhz {
            Some(mhz) => Outcome::Routed {
                fmax: Fmax {
                    clock: "clk".into(),
                    mhz,
                    constraint_mhz: 100.0,
                },
                critical_path: None,
            },
            None => Outcome::DoesNotFit("Unable to place cell".into()),
        };
        PnrReport {
            part: ECP5_25F,
            core_module: "gyro_interface".into(),
            core_files: vec!["gyro_interface.v".into()],
            yosys_version: "Yosys 0.70".into(),
            nextpnr_version: "nextpnr-0.11.1".into(),
            uses: vec![
                Use {
                    label: "LUT",
                    used: 9000,
                    available: 24288,
                },
                Use {
                    label: "MULT",
                    used: mult,
                    available: 28,
                },
            ],
            outcome,
            wrapper_chain_bits: 330,
            wrapper_flip_flops: 370,
            wrapper_luts: 40,
            wall: (Duration::ZERO, Duration::ZERO),
        }
    }

    #[test]
    fn a_report_that_meets_the_target() {
        let t = target_of("ecp5-25f").unwrap();
        assert_eq!(t.min_fmax_mhz, 100.0);
        let r = report(12, Some(100.0));
        assert!(misses(&r, t).is_empty());
        assert_eq!(
            check(std::slice::from_ref(&r), &TARGETS[1..]),
            Vec::<String>::new()
        );
        assert_eq!(verdict(&r, t), "yes (stretch 125 MHz missed)");
        assert_eq!(
            verdict(&report(12, Some(131.0)), t),
            "yes (stretch 125 MHz met)"
        );
    }

    #[test]
    fn reports_that_miss_the_target() {
        let t = target_of("ecp5-25f").unwrap();
        let slow = misses(&report(12, Some(99.99)), t);
        assert_eq!(
            slow,
            ["Lattice ECP5 LFE5U-25F (CABGA381): Fmax 99.99 MHz below the target 100 MHz"]
        );
        let big = misses(&report(30, None), t);
        assert_eq!(big.len(), 2, "{big:?}");
        assert!(big[0].contains("30 MULT of 28 does not fit"));
        assert!(big[1].contains("no Fmax"));
        assert!(verdict(&report(30, None), t).starts_with("**no**"));
        // A part with a target but no report is a miss as well.
        let missing = check(&[report(12, Some(120.0))], &TARGETS);
        assert_eq!(missing, ["ice40-up5k: no place-and-route report"]);
    }
}
