//! The rate profile of a field scenario (`[profile]`) and the calibrated
//! rate output it gives over time.
//!
//! At every temperature step the rate table of the simulation applies the
//! same profile: `rate_points` are `[time_s, rate_dps]` pairs, the rate
//! linear between them (two points at one time make a step) and held after
//! the last, for `duration_s` seconds. The board runs in readout; its z
//! samples (one per R clocks) are averaged over records of `record_s`
//! (default `duration_s / DEFAULT_RECORDS`), and each record's mean is
//! turned into a rate in deg/s as a user of the board would:
//!
//! ```text
//! rate_k = (z_k - null_k) / SF_k        (deg/s; z, null in z LSB, SF in z LSB per deg/s)
//! ```
//!
//! with the self-calibration's null (the readout at rest right after the
//! cycle) and SF_selfcal, and, beside it, the factory's null and scale
//! factor at the factory's carrier and phase (the baseline). The true rate
//! of a record is the mean of the rates applied over its samples.
//!
//! A record is *settled* when no point of the profile falls within
//! `settle_s` (default 0) before it or inside it: the RMS errors are over
//! the settled records, so that the output's own step response (its
//! bandwidth, not its calibration) does not swamp them; the time series
//! keeps every record. Nor is a record settled when an ADC clipped during
//! it or during the `settle_s` before it (`ADC_CLIP`, read once a record):
//! its z holds the converter's rail, not the rate. The report says so in
//! one line ([`ProfileRun::clipped`]).
//!
//! ```toml
//! [profile]
//! duration_s = 0.2                                    # required
//! rate_points = [[0, 0], [0.02, 0], [0.02, 10], [0.1, -10], [0.15, -10]]
//! record_s = 0.002                                    # optional
//! settle_s = 0.01                                     # optional
//! ```

use super::board::SimBoard;
use crate::config::MAX_RATE_DPS;
use crate::error::ConfigError;
pub use gyrocal_host::rate::{calibrated, readout_null, rms_error};
use serde::{Deserialize, Serialize};

/// Records of a profile when `record_s` is not given.
pub const DEFAULT_RECORDS: f64 = 100.0;
/// Longest profile per step (s): 100 s is 5e9 clocks at 50 MHz.
pub const MAX_DURATION_S: f64 = 100.0;
/// Most points in `rate_points`.
pub const MAX_POINTS: usize = 1000;
/// Most records per step (rows of the time series).
pub const MAX_RECORDS: f64 = 1.0e5;

/// The `[profile]` section.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Profile {
    /// Length of the profile at each temperature step (s).
    pub duration_s: f64,
    /// `[time_s, rate_dps]` points: times from 0, non-decreasing; the rate
    /// is linear between points and held after the last.
    /// (A list of lists, not of pairs: serde's pair silently drops a
    /// third element, which `validate` refuses.)
    pub rate_points: Vec<Vec<f64>>,
    /// Length of one record of the output (s); `duration_s /
    /// DEFAULT_RECORDS` when absent.
    #[serde(default)]
    pub record_s: Option<f64>,
    /// Time after each point of the profile left out of the RMS errors (s).
    #[serde(default)]
    pub settle_s: f64,
}

fn profile_error(key: &str, value: impl std::fmt::Display, allowed: &str) -> ConfigError {
    ConfigError::key("profile", key, value, allowed)
}

impl Profile {
    /// Checks every key; errors are one line naming the key. `sample_s` is
    /// the board's z sample period (R / f_clk): a record holds at least one.
    pub fn validate(&self, sample_s: f64) -> Result<(), ConfigError> {
        let d = self.duration_s;
        if !(d.is_finite() && d > 0.0 && d <= MAX_DURATION_S) {
            return Err(profile_error(
                "duration_s",
                d,
                &format!("allowed > 0 and <= {MAX_DURATION_S} s"),
            ));
        }
        let n = self.rate_points.len();
        if n == 0 || n > MAX_POINTS {
            return Err(profile_error(
                "rate_points",
                format!("a list of {n} points"),
                &format!("allowed 1..={MAX_POINTS} [time_s, rate_dps] points"),
            ));
        }
        if let Some(p) = self.rate_points.iter().find(|p| p.len() != 2) {
            return Err(profile_error(
                "rate_points",
                format!("{p:?}"),
                "each point must be [time_s, rate_dps] (length 2)",
            ));
        }
        if self.rate_points[0][0] != 0.0 {
            return Err(profile_error(
                "rate_points",
                format!("[{}, ...] first", self.rate_points[0][0]),
                "the first point's time must be 0 s",
            ));
        }
        for pair in self.rate_points.windows(2) {
            let (t0, t1) = (pair[0][0], pair[1][0]);
            if !(t1.is_finite() && t1 >= t0) {
                return Err(profile_error(
                    "rate_points",
                    format!("time {t1} after {t0}"),
                    "times must be finite and non-decreasing",
                ));
            }
        }
        if let Some(p) = self
            .rate_points
            .iter()
            .find(|p| !(p[1].is_finite() && p[1].abs() <= MAX_RATE_DPS))
        {
            return Err(profile_error(
                "rate_points",
                format!("rate {}", p[1]),
                &format!("allowed -{MAX_RATE_DPS}..={MAX_RATE_DPS} deg/s"),
            ));
        }
        if !(self.settle_s.is_finite() && self.settle_s >= 0.0 && self.settle_s < d) {
            return Err(profile_error(
                "settle_s",
                self.settle_s,
                "allowed >= 0 and below duration_s",
            ));
        }
        let r = self.record_length_s();
        if !(r.is_finite() && r >= sample_s && r <= d && d / r <= MAX_RECORDS) {
            return Err(profile_error(
                "record_s",
                r,
                &format!(
                    "allowed from one z sample ({sample_s:e} s) to duration_s, \
                     at most {MAX_RECORDS} records"
                ),
            ));
        }
        Ok(())
    }

    /// Length of one record (s).
    pub fn record_length_s(&self) -> f64 {
        self.record_s.unwrap_or(self.duration_s / DEFAULT_RECORDS)
    }

    /// True when no point's time lies in (`t0_s` - settle_s, `t1_s`).
    pub fn is_settled(&self, t0_s: f64, t1_s: f64) -> bool {
        !self
            .rate_points
            .iter()
            .any(|p| p[0] > t0_s - self.settle_s && p[0] < t1_s)
    }

    /// The rate at `t_s` (deg/s): linear between points, held after the
    /// last (at a step, the later point's rate).
    pub fn rate_dps_at(&self, t_s: f64) -> f64 {
        let p = &self.rate_points;
        let after = p.partition_point(|q| q[0] <= t_s);
        if after == p.len() {
            return p[p.len() - 1][1];
        }
        let (a, b) = (&p[after - 1], &p[after]);
        a[1] + (b[1] - a[1]) * (t_s - a[0]) / (b[0] - a[0])
    }

    /// One line when the profile's rate leaves the interval its scale
    /// factors were fitted over: the rate table's rates `table_dps`
    /// (`[experiment] readout_rates_dps`) and 0, where the null is
    /// measured. Beyond it the profile's error holds the readout's
    /// departure from the fitted line (on a detuned output mostly its
    /// quadratic term), which no sigma bounds. The rate is linear between
    /// points, so its extremes are at the points within the profile or at
    /// its end.
    pub fn beyond_the_table(&self, table_dps: &[f64]) -> Option<String> {
        let (lo, hi) = table_dps
            .iter()
            .fold((0.0f64, 0.0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
        let reached = self
            .rate_points
            .iter()
            .filter(|p| p[0] <= self.duration_s)
            .map(|p| p[1])
            .chain([self.rate_dps_at(self.duration_s)]);
        let farthest = reached
            .filter(|&r| r < lo || r > hi)
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))?;
        Some(format!(
            "warning: [profile] reaches {farthest} deg/s, outside the {lo} to {hi} deg/s over which the scale factors were fitted ([experiment] readout_rates_dps, and 0 where the null is measured): the profile's error there holds the readout's departure from its fitted line, which no sigma bounds"
        ))
    }
}

/// The readout of one board under the profile, record by record.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProfileRun {
    /// Mid time of each record from the profile's start (s).
    pub time_s: Vec<f64>,
    /// Mean applied rate over each record (deg/s).
    pub true_rate_dps: Vec<f64>,
    /// Mean z over each record (z LSB).
    pub z: Vec<[f64; 2]>,
    /// Whether each record is settled (module header).
    pub settled: Vec<bool>,
    /// Clocks on which ADC 1 and ADC 2 clipped, per record
    /// (`gyrocal_host::rate::Record`).
    pub clip_clocks: Vec<[u32; 2]>,
    /// Clocks it took.
    #[serde(skip)]
    pub clocks: u64,
}

impl ProfileRun {
    /// Records during which an ADC clipped: (per ADC, how many; the
    /// largest |applied rate| among them, deg/s), or None when none did.
    pub fn clipped(&self) -> Option<([usize; 2], f64)> {
        let records: [usize; 2] =
            std::array::from_fn(|k| self.clip_clocks.iter().filter(|c| c[k] > 0).count());
        let peak = self
            .clip_clocks
            .iter()
            .zip(&self.true_rate_dps)
            .filter(|(c, _)| c.iter().any(|&n| n > 0))
            .map(|(_, r)| r.abs())
            .fold(0.0, f64::max);
        (records != [0, 0]).then_some((records, peak))
    }
}

/// Whether each record is settled: no point of `profile` within settle_s
/// before it or inside it, and no record whose ADCs clipped (`clip`) ending
/// within settle_s before it or being it. `record_s` is a record's length.
fn settled_records(profile: &Profile, clip: &[[u32; 2]], record_s: f64) -> Vec<bool> {
    let mut last_clip_end: Option<f64> = None;
    (0..clip.len())
        .map(|i| {
            let (t0, t1) = (i as f64 * record_s, (i + 1) as f64 * record_s);
            if clip[i].iter().any(|&n| n > 0) {
                last_clip_end = Some(t1);
            }
            let after_clip = last_clip_end.is_some_and(|end| end > t0 - profile.settle_s);
            profile.is_settled(t0, t1) && !after_clip
        })
        .collect()
}

/// Apply `profile` through the rate table of `board` (already programmed
/// and settled in readout), the rate updated once per z sample at the
/// sample period's midpoint, and record block means
/// (`gyrocal_host::rate::read_records`).
pub fn run_profile(
    board: &mut SimBoard,
    profile: &Profile,
    decimation: u32,
    clock_hz: f64,
) -> Result<ProfileRun, gyrocal_host::Error> {
    let sample_s = f64::from(decimation) / clock_hz;
    let per_record = (profile.record_length_s() / sample_s).round().max(1.0) as usize;
    let records = ((profile.duration_s / (per_record as f64 * sample_s)).floor() as usize).max(1);
    let start = board.cycle();
    let mut applied = Vec::with_capacity(records * per_record);
    let read = gyrocal_host::rate::read_records(board, per_record, records, |b, sample| {
        let rate = profile.rate_dps_at((sample as f64 + 0.5) * sample_s);
        b.set_rate(rate.to_radians());
        applied.push(rate);
    })?;
    board.set_rate(0.0);
    let n = per_record as f64;
    let time_s: Vec<f64> = (0..records)
        .map(|i| (i as f64 + 0.5) * n * sample_s)
        .collect();
    let clip_clocks: Vec<[u32; 2]> = read.iter().map(|r| r.clip_clocks).collect();
    Ok(ProfileRun {
        true_rate_dps: applied
            .chunks(per_record)
            .map(|c| c.iter().sum::<f64>() / n)
            .collect(),
        settled: settled_records(profile, &clip_clocks, n * sample_s),
        time_s,
        z: read.iter().map(|r| r.z).collect(),
        clip_clocks,
        clocks: board.cycle() - start,
    })
}

/// The record length of a trace from its records' mid times (s): their
/// spacing, 0 for fewer than two records.
pub fn record_spacing_s(time_s: &[f64]) -> f64 {
    match time_s {
        [a, b, ..] => b - a,
        _ => 0.0,
    }
}

/// The rate output of one step under the profile, self-calibrated and
/// factory baseline, beside the truth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RateTrace {
    /// Mid time of each record from the profile's start (s).
    pub time_s: Vec<f64>,
    /// Applied rate (deg/s).
    pub true_rate_dps: Vec<f64>,
    /// (z - null_selfcal) / SF_selfcal per output (deg/s).
    pub selfcal_rate_dps: Vec<[f64; 2]>,
    /// (z - null_factory) / SF_factory at the factory's settings (deg/s);
    /// null without a baseline.
    pub baseline_rate_dps: Option<Vec<[f64; 2]>>,
    /// Whether each record is settled (module header).
    pub settled: Vec<bool>,
    /// The self-calibration's null (z LSB).
    pub null_selfcal_z: [f64; 2],
    /// RMS of selfcal_rate - true_rate over the settled records (deg/s).
    pub selfcal_rms_error_dps: [f64; 2],
    /// RMS of baseline_rate - true_rate over the settled records (deg/s);
    /// null without a baseline.
    pub baseline_rms_error_dps: Option<[f64; 2]>,
    /// The records during which an ADC clipped, if any did: left out of
    /// the RMS errors with the settle_s after them (module header).
    pub clipped: Option<ClippedRecords>,
    /// Clocks on which ADC 1 and ADC 2 clipped during each record of the
    /// self-calibrated run.
    pub clip_clocks: Vec<[u32; 2]>,
    /// On the table core, the bound on the rate's RMS ripple from the
    /// carrier's spurs (`gyrocal_host::selfcal::spurs`) over these
    /// records (each line through its record's average): against
    /// `selfcal_rms_error_dps`, how much of it the carrier tables can be.
    pub spur_bound_dps: Option<[f64; 2]>,
}

/// The records of a step's profile runs during which an ADC clipped.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClippedRecords {
    /// Records in a run.
    pub records: usize,
    /// Clipped records of the self-calibrated run, per ADC.
    pub selfcal: [usize; 2],
    /// Clipped records of the baseline's run at the factory's settings,
    /// per ADC; null where that run is the self-calibrated one or absent.
    pub baseline: Option<[usize; 2]>,
    /// Largest |applied rate| over the clipped records of either run (deg/s).
    pub peak_rate_dps: f64,
}

impl ClippedRecords {
    /// Of the self-calibrated run and the baseline's (None where it is
    /// the same run); None when no ADC clipped in either.
    pub fn of(run: &ProfileRun, baseline: Option<&ProfileRun>) -> Option<Self> {
        let own = run.clipped();
        let base = baseline.and_then(ProfileRun::clipped);
        if own.is_none() && base.is_none() {
            return None;
        }
        Some(Self {
            records: run.z.len(),
            selfcal: own.map_or([0; 2], |c| c.0),
            baseline: baseline.map(|_| base.map_or([0; 2], |c| c.0)),
            peak_rate_dps: own.map_or(0.0, |c| c.1).max(base.map_or(0.0, |c| c.1)),
        })
    }

    /// `at 25 deg C (ADC 2 in 40 of 150 records (baseline run: 40); the
    /// profile there up to 100000 deg/s)`: a step's part of the report's
    /// line.
    pub fn describe(&self, temperature_c: f64) -> String {
        let adcs: Vec<String> = (0..2)
            .filter(|&k| self.selfcal[k] > 0 || self.baseline.is_some_and(|b| b[k] > 0))
            .map(|k| {
                let base = self
                    .baseline
                    .map_or(String::new(), |b| format!(" (baseline run: {})", b[k]));
                format!(
                    "ADC {} in {} of {} records{base}",
                    k + 1,
                    self.selfcal[k],
                    self.records
                )
            })
            .collect();
        format!(
            "at {temperature_c} deg C ({}; the profile there up to {} deg/s)",
            adcs.join(", "),
            self.peak_rate_dps
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn profile(text: &str) -> Result<Profile, ConfigError> {
        let p: Profile =
            toml::from_str(text).map_err(|e| ConfigError::Syntax(e.message().to_string()))?;
        p.validate(2e-5)?;
        Ok(p)
    }

    #[test]
    fn a_profile_beyond_the_rate_table_is_said_and_one_within_it_is_not() {
        let p =
            |points: &str| profile(&format!("duration_s = 3.0\nrate_points = {points}\n")).unwrap();
        let table = [50.0, 100.0, 150.0, 200.0];
        let within = p("[[0, 0], [0.3, 0], [0.3, 100], [2.0, 200], [2.5, 50], [3.0, 50]]");
        assert_eq!(within.beyond_the_table(&table), None);
        // A point after the profile's end is never applied.
        let late = p("[[0, 0], [3.0, 200], [4.0, 900]]");
        assert_eq!(late.beyond_the_table(&table), None);
        let line = p("[[0, 0], [0.3, 3000], [1.0, 6000], [2.5, 50]]")
            .beyond_the_table(&table)
            .unwrap();
        assert!(
            line.starts_with(
                "warning: [profile] reaches 6000 deg/s, outside the 0 to 200 deg/s over which"
            ),
            "{line}"
        );
        // Below the table, and held past the last point.
        let line = p("[[0, 0], [1.0, -80]]").beyond_the_table(&table).unwrap();
        assert!(
            line.contains("reaches -80 deg/s, outside the 0 to 200 deg/s"),
            "{line}"
        );
        assert_eq!(
            p("[[0, 0], [1.0, -80]]").beyond_the_table(&[-100.0, 100.0]),
            None
        );
    }

    #[test]
    fn the_rate_is_linear_between_points_stepped_at_repeated_times_and_held() {
        let p = profile("duration_s = 1\nrate_points = [[0, 0], [0.2, 10], [0.2, -4], [0.6, 4]]\n")
            .unwrap();
        assert_eq!(p.rate_dps_at(0.0), 0.0);
        assert!((p.rate_dps_at(0.1) - 5.0).abs() < 1e-12);
        assert_eq!(p.rate_dps_at(0.2), -4.0);
        assert!((p.rate_dps_at(0.4) - 0.0).abs() < 1e-12);
        assert_eq!(p.rate_dps_at(0.9), 4.0);
        assert!((p.record_length_s() - 0.01).abs() < 1e-15);
    }

    #[test]
    fn bad_sections_are_refused_in_one_line_naming_the_key() {
        let cases = [
            ("rate_points = [[0, 1]]\n", "duration_s"),
            ("duration_s = 0\nrate_points = [[0, 1]]\n", "duration_s"),
            ("duration_s = 1\nrate_points = []\n", "rate_points"),
            ("duration_s = 1\nrate_points = [[0.1, 1]]\n", "rate_points"),
            (
                "duration_s = 1\nrate_points = [[0, 1], [0.5, 1], [0.4, 2]]\n",
                "non-decreasing",
            ),
            ("duration_s = 1\nrate_points = [[0, 1e9]]\n", "rate_points"),
            (
                "duration_s = 1\nrate_points = [[0, 1]]\nrecord_s = 1e-6\n",
                "record_s",
            ),
            (
                "duration_s = 1\nrate_points = [[0, 1]]\nrecord_s = 2\n",
                "record_s",
            ),
            ("duration_s = 1\nrate_points = [[0, 1, 2]]\n", "length 2"),
            (
                "duration_s = 1\nrate_points = [[0, 1]]\nspeed = 2\n",
                "speed",
            ),
            (
                "duration_s = 1\nrate_points = [[0, 1]]\nsettle_s = 1\n",
                "settle_s",
            ),
        ];
        for (text, key) in cases {
            let err = profile(text).expect_err(key).to_string();
            assert!(err.contains(key), "{key}: {err}");
            assert!(!err.trim_end().contains('\n'), "{err}");
        }
    }

    #[test]
    fn calibrated_rate_removes_the_null_and_divides_by_the_scale_factor() {
        let z = [[110.0, -50.0], [130.0, -90.0]];
        let rate = calibrated(&z, [100.0, -10.0], [2.0, -4.0]);
        assert_eq!(rate, vec![[5.0, 10.0], [15.0, 20.0]]);
        let rms = rms_error(&rate, &[5.0, 15.0], &[true, true]);
        assert_eq!(rms[0], 0.0);
        assert!((rms[1] - 5.0f64.hypot(5.0) / 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(rms_error(&rate, &[5.0, 15.0], &[false, true])[1], 5.0);
    }

    #[test]
    fn records_that_clipped_and_the_settling_after_them_are_not_settled() {
        let p = profile("duration_s = 1\nrate_points = [[0, 0]]\nsettle_s = 0.025\n").unwrap();
        let mut clip = vec![[0u32; 2]; 10];
        clip[3] = [0, 7];
        clip[4] = [1, 0];
        let settled = settled_records(&p, &clip, 0.01);
        // Records 0 to 2 start within 25 ms of the point at 0 s; 3 and 4
        // clipped; 5 to 7 start within 25 ms of 4's end at 50 ms, 8 starts
        // 30 ms after it.
        let expected = [
            false, false, false, false, false, false, false, false, true, true,
        ];
        assert_eq!(settled, expected);
        let run = ProfileRun {
            time_s: (0..10).map(|i| (f64::from(i) + 0.5) * 0.01).collect(),
            true_rate_dps: (0..10).map(|i| 10.0 * f64::from(i) - 45.0).collect(),
            z: vec![[0.0; 2]; 10],
            settled,
            clip_clocks: clip,
            clocks: 0,
        };
        assert_eq!(run.clipped(), Some(([1, 1], 15.0)));
        let c = ClippedRecords::of(&run, None).unwrap();
        assert_eq!(
            c.describe(25.0),
            "at 25 deg C (ADC 1 in 1 of 10 records, ADC 2 in 1 of 10 records; the profile there up to 15 deg/s)"
        );
        let quiet = ProfileRun {
            clip_clocks: vec![[0; 2]; 10],
            ..run.clone()
        };
        assert_eq!(quiet.clipped(), None);
        assert_eq!(ClippedRecords::of(&quiet, Some(&quiet)), None);
        let c = ClippedRecords::of(&quiet, Some(&run)).unwrap();
        assert_eq!(
            c.describe(5.0),
            "at 5 deg C (ADC 1 in 0 of 10 records (baseline run: 1), ADC 2 in 0 of 10 records (baseline run: 1); the profile there up to 15 deg/s)"
        );
    }

    #[test]
    fn records_near_a_point_are_not_settled() {
        let p =
            profile("duration_s = 1\nrate_points = [[0, 0], [0.5, 10]]\nsettle_s = 0.1\n").unwrap();
        assert!(!p.is_settled(0.0, 0.01));
        assert!(p.is_settled(0.1, 0.11));
        assert!(!p.is_settled(0.49, 0.5 + 1e-9));
        assert!(!p.is_settled(0.59, 0.6));
        assert!(p.is_settled(0.6, 0.61));
    }
}
