//! A sweep's summary: the yield at the tolerance, the error percentiles and
//! how often the reported sigma covered the error.
//!
//! - **Yield** (per output, and both): the fraction of *all* devices whose
//!   every step finished with |error| within the tolerance. A device that
//!   failed (its identification found no resonance, its drive would clip)
//!   counts against the yield, as a part that cannot be calibrated does.
//! - **Percentiles** of each finished device's worst |error| (over its
//!   steps), per output, by nearest rank: the smallest value with at least
//!   p of the devices at or below it.
//! - **Coverage**: over every finished step and output, the fraction of
//!   |error| within 2 of its reported sigmas (`selfcal_error_uncertainty`),
//!   and how many lie beyond 3.

use super::DeviceResult;
use serde::{Deserialize, Serialize};

/// The percentiles reported, in percent.
pub const PERCENTILES: [f64; 4] = [50.0, 90.0, 95.0, 99.0];

/// A sweep's figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Devices in the report.
    pub devices: u32,
    /// Devices with a failed step (or that could not start).
    pub failed: u32,
    /// The tolerance on |self-cal error| (relative).
    pub tolerance: f64,
    /// Fraction of the devices within the tolerance, per output.
    pub yield_per_output: [f64; 2],
    /// Fraction within the tolerance at both outputs.
    pub yield_both: f64,
    /// `PERCENTILES` of the worst |error| per output: `[p, output 1,
    /// output 2]` rows; empty when no device finished.
    pub error_percentiles: Vec<[f64; 3]>,
    /// Largest |error| per output (null when no device finished).
    pub max_error: Option<[f64; 2]>,
    /// Fraction of |error| within 2 reported sigmas (null when none).
    pub within_2_sigma: Option<f64>,
    /// How many |error| lie beyond 3 reported sigmas.
    pub beyond_3_sigma: u32,
}

/// Nearest-rank percentile `p` (0 < p <= 100) of sorted values.
fn nearest_rank(sorted: &[f64], p: f64) -> f64 {
    let rank = ((p / 100.0) * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

impl Summary {
    /// The summary of `devices` at `tolerance`.
    pub fn of(devices: &[DeviceResult], tolerance: f64) -> Self {
        let n = devices.len().max(1) as f64;
        let finished: Vec<&DeviceResult> = devices.iter().filter(|d| d.failed.is_empty()).collect();
        let worst = |k: usize| -> Vec<f64> {
            let mut v: Vec<f64> = finished.iter().map(|d| d.worst_error(k)).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let sorted = [worst(0), worst(1)];
        let within = |k: usize| sorted[k].iter().filter(|&&e| e <= tolerance).count() as f64 / n;
        let t: Vec<f64> = devices
            .iter()
            .flat_map(|d| &d.steps)
            .flat_map(|s| {
                (0..2).map(|k| (s.sf_selfcal_error[k] / s.selfcal_error_uncertainty[k]).abs())
            })
            .collect();
        let has = !sorted[0].is_empty();
        Self {
            devices: devices.len() as u32,
            failed: (devices.len() - finished.len()) as u32,
            tolerance,
            yield_per_output: [within(0), within(1)],
            yield_both: devices.iter().filter(|d| d.within_tolerance).count() as f64 / n,
            error_percentiles: if has {
                PERCENTILES
                    .iter()
                    .map(|&p| [p, nearest_rank(&sorted[0], p), nearest_rank(&sorted[1], p)])
                    .collect()
            } else {
                vec![]
            },
            max_error: has.then(|| {
                [
                    sorted[0][sorted[0].len() - 1],
                    sorted[1][sorted[1].len() - 1],
                ]
            }),
            within_2_sigma: (!t.is_empty())
                .then(|| t.iter().filter(|&&t| t <= 2.0).count() as f64 / t.len() as f64),
            beyond_3_sigma: t.iter().filter(|&&t| t > 3.0).count() as u32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_is_the_smallest_value_with_p_at_or_below() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        assert_eq!(nearest_rank(&v, 50.0), 5.0);
        assert_eq!(nearest_rank(&v, 90.0), 9.0);
        assert_eq!(nearest_rank(&v, 95.0), 10.0);
        assert_eq!(nearest_rank(&v, 100.0), 10.0);
        assert_eq!(nearest_rank(&[3.0], 50.0), 3.0);
    }
}
