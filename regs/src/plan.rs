//! Run-time settings of `GyroInterface` from a frequency plan in Hz.
//!
//! Phase steps are rounded to the nearest integer, and everything
//! downstream uses the realized frequencies (`Realized`), never the asked
//! ones: the carrier is step * f_clk / 2^32, the calibration rate
//! step * f_clk / 2^48 (0.18 uHz resolution at 50 MHz).
//!
//! # Reference alignment
//!
//! Let the DAC output the word of cycle k over the clock period that starts
//! L_dac clocks later (zero-order hold), and let the ADC present during
//! cycle m the sample taken at the edge of cycle m - L_adc. The hold's
//! fundamental is the word sequence delayed by L_dac + 1/2 clocks (and
//! scaled by sinc(f T)), so the sample reaching the mixer at cycle n
//! (`gyrocal_hdl::demod_mux` uses adc(n - 2)) responds to drive word number
//! n - 2 - L_adc - L_dac - 1/2. The reference used at cycle n is
//! ref(n - 3 - ref_delay) (`demod_mux` 2 clocks, `reference_alignment`
//! ref_delay + 1), advanced in phase by ref_phase / carrier_step words.
//! Equating the two:
//!
//! ```text
//!   ref_delay = L_dac + L_adc,   ref_phase = carrier_step / 2
//! ```
//!
//! The modulation envelope is delayed with the carrier, so only half a
//! clock of it remains (Om T / 2, about 1e-6 rad: negligible).

use crate::PlanError;
use crate::datapath::DELAY_BITS;
use crate::filter_design::{self, FilterDesign};
use crate::registers::Registers;

/// Highest calibration rate as a fraction of the clock.
pub const MAX_CAL_RATIO: f64 = 1e-3;
/// Longest reference delay, L_dac + L_adc (clocks): the delay line's depth.
pub const MAX_REF_DELAY: u32 = (1 << DELAY_BITS) - 1;

/// What the user asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyPlan {
    /// FPGA clock in Hz.
    pub clock_hz: f64,
    /// Carrier (excitation) frequency in Hz.
    pub carrier_hz: f64,
    /// Calibration rate f_cal in Hz (used when `calibration` is true).
    pub cal_hz: f64,
    /// SELECT: false readout, true calibration.
    pub calibration: bool,
    /// Drive amplitudes F1, F2 as fractions of full scale, in [-1, 1).
    pub amplitude: (f64, f64),
    /// CIC decimation R.
    pub decimation: u32,
    /// Butterworth cut-off in Hz.
    pub butterworth_hz: f64,
    /// RC cut-off in Hz.
    pub rc_hz: f64,
    /// DAC latency in clocks.
    pub dac_latency: u32,
    /// ADC latency in clocks.
    pub adc_latency: u32,
}

/// The frequencies and gains the registers actually produce.
#[derive(Clone, Debug, PartialEq)]
pub struct Realized {
    /// Carrier frequency in Hz.
    pub carrier_hz: f64,
    /// Calibration rate in Hz (0 in readout).
    pub cal_hz: f64,
    /// The output filter.
    pub filter: FilterDesign,
}

/// Registers and realized values for a plan; a one-line error names the
/// setting that is out of range and what is allowed.
pub fn registers(plan: &FrequencyPlan) -> Result<(Registers, Realized), PlanError> {
    let clock = plan.clock_hz;
    if !(clock.is_finite() && clock > 0.0) {
        return Err(PlanError::out_of_range(
            "clock_hz",
            clock,
            "must be a positive number of Hz",
        ));
    }
    let nyquist = clock / 2.0;
    if !(plan.carrier_hz.is_finite() && plan.carrier_hz > 0.0 && plan.carrier_hz < nyquist) {
        return Err(PlanError::out_of_range(
            "carrier_hz",
            plan.carrier_hz,
            format!("must be above 0 and below clock_hz / 2 = {nyquist}"),
        ));
    }
    let carrier_step = (plan.carrier_hz / clock * 2f64.powi(32)).round() as u32;
    let mod_step = if plan.calibration {
        let max = clock * MAX_CAL_RATIO;
        if !(plan.cal_hz.is_finite() && plan.cal_hz >= 0.0 && plan.cal_hz <= max) {
            return Err(PlanError::out_of_range(
                "cal_hz",
                plan.cal_hz,
                format!("allowed 0 to clock_hz x {MAX_CAL_RATIO} = {max}"),
            ));
        }
        (plan.cal_hz / clock * 2f64.powi(48)).round() as u64
    } else {
        0
    };
    let mut amp = [0i16; 2];
    for (k, a) in [plan.amplitude.0, plan.amplitude.1].into_iter().enumerate() {
        if !(a.is_finite() && (-1.0..1.0).contains(&a)) {
            return Err(PlanError::out_of_range(
                format!("amplitude of drive {}", k + 1),
                a,
                "allowed -1 <= a < 1",
            ));
        }
        // Q1.15, nearest: just below 1.0 saturates to 32767.
        amp[k] = fixed::types::I1F15::saturating_from_num(a).to_bits();
    }
    let delay = plan.dac_latency + plan.adc_latency;
    if delay > MAX_REF_DELAY {
        return Err(PlanError::out_of_range(
            "dac_latency + adc_latency",
            format!("{delay} clocks"),
            format!("at most {MAX_REF_DELAY}"),
        ));
    }
    let filter = filter_design::design(clock, plan.decimation, plan.butterworth_hz, plan.rc_hz)?;
    let regs = Registers {
        select: plan.calibration,
        carrier_step,
        ref_phase: carrier_step.div_ceil(2),
        ref_delay: delay as u8,
        mod_step,
        amp: (amp[0], amp[1]),
        cic_decimation: filter.decimation as u16,
        cic_shift: filter.cic_shift as u8,
        iir: filter.coefficients,
    };
    let realized = Realized {
        carrier_hz: carrier_step as f64 * clock / 2f64.powi(32),
        cal_hz: mod_step as f64 * clock / 2f64.powi(48),
        filter,
    };
    Ok((regs, realized))
}

/// If the carrier is within 1e-9 of a ratio p/q of the clock with q <= 1000,
/// return q: the DAC and ADC then see only about q distinct phases, and
/// their quantization errors no longer average out (a 16-bit loop with a
/// 1 MHz carrier on a 10 MHz clock is off by about 1-3%).
pub fn commensurate_period(carrier_hz: f64, clock_hz: f64) -> Option<u64> {
    let r = carrier_hz / clock_hz;
    (1..=1000u64).find(|&q| {
        let x = r * q as f64;
        (x - x.round()).abs() < 1e-9 * q as f64
    })
}

/// Longest period [`nearest_fold`] looks at. With the carrier r = fc /
/// fclk near n / q, the DAC and ADC see the carrier's q sample phases
/// drifting slowly, and their quantization errors (the carrier tables',
/// 16 bits) come back as harmonics q +- 1 of the carrier folded to
/// eps = fclk |q r - n| from it; in the output's passband, a ripple on the
/// rate. On the paper device (`tests/data/field_paper.toml`) the two steps
/// whose calibrated rate ripples are the two that fold in the passband
/// (30 deg C: q = 83, eps = 18.2 Hz and its multiples, 0.25 deg/s RMS;
/// 25 deg C: q = 1250, eps = 4.8 Hz, 0.47 deg/s RMS), the three others
/// (0.02 to 0.08 deg/s) fold nowhere below 1 kHz for q up to 5000. The
/// error's power spreads over q harmonics, so long periods matter less.
pub const MAX_FOLD_PERIOD: u64 = 4096;

/// The nearest fold of `carrier_hz` on `clock_hz` among periods up to
/// [`MAX_FOLD_PERIOD`]: (q, eps in Hz), the period whose harmonics land
/// closest to the carrier.
pub fn nearest_fold(carrier_hz: f64, clock_hz: f64) -> (u64, f64) {
    nearest_fold_within(carrier_hz, clock_hz, MAX_FOLD_PERIOD)
}

/// Periods up to which a fold slower than a measurement window is a
/// static bias: the bound of [`commensurate_period`], below which the
/// converters' and tables' errors over the q phases do not average out.
pub const STATIC_FOLD_PERIOD: u64 = 1000;

/// Beats a measurement window (`min_window_s`) below which a fold of
/// period up to [`STATIC_FOLD_PERIOD`] is static: its error is the same
/// in every batch, so the batches' spread cannot see it. The host's
/// operating point moves the carrier off such a fold where it cannot clear
/// the passband (`gyrocal_host::selfcal::operating`), and a field step
/// that still has one names it (`gyrocal_sim::field::scenario::CarrierFold`).
///
/// On an unseen device (15 kHz on a 1.2 MHz clock, q = 80, 0.4 s windows)
/// a fold 0.04 Hz off left the measured couplings 10.7 and 16.7 of their
/// sigmas off. With the fold at 2.4 Hz (0.96 beats a window) or 8 Hz
/// (3.2) every figure lay within 0.5 sigma, so one beat is on the safe
/// side. The paper device's 30 deg C fold, period 83, beats 1.8 times a
/// 0.1 s window.
pub const STATIC_FOLD_BEATS: f64 = 1.0;

/// Beats a measurement window at which a fold of period up to
/// [`STATIC_FOLD_PERIOD`] leaves no bias that a figure's sigma misses,
/// where one beat still leaves some: the host first tries to move the
/// carrier this far, then [`STATIC_FOLD_BEATS`].
///
/// A ripple of frequency eps averaged over a window T keeps
/// |sin(pi eps T) / (pi eps T)| <= 1 / (pi eps T) of its amplitude. The
/// staircase's windows are whole periods of the calibration ripple, not
/// of the fold's beat, so over eps T = 1 to 2 beats up to a third of the
/// beat stays in a window's mean, and it is the same in every batch: it
/// starts from power-up at the same phase. At 4 beats at most 8% stays.
/// Measured on an unseen device (4.1 MHz modes on a 40 MHz clock, the
/// fine core, its 25 deg C carrier exactly 41 / 400 of the clock; 20
/// noise seeds): moved to one beat a 37.6 ms window, the self-cal errors
/// against the rate table were +7.8e-5 and +1.19e-4 on average (standard
/// errors 1.7e-5 and 1.6e-5), and only 85% of the 40 figures lay within
/// 2 sigma; moved to four beats, +5.7e-5 and +6.0e-5, no different from
/// the same device on a clock with no fold near (+4.5e-5 and +4.9e-5),
/// an offset that was the calibration envelope's rounding
/// (`datapath::calibration_word`). With both, -1.6e-5 and -1.4e-5 and
/// 100% within 2 sigma (docs/field.md).
pub const SETTLED_FOLD_BEATS: f64 = 4.0;

/// [`nearest_fold`] among periods up to `max_period`.
pub fn nearest_fold_within(carrier_hz: f64, clock_hz: f64, max_period: u64) -> (u64, f64) {
    fold_distances(carrier_hz, clock_hz, max_period).fold((0, f64::INFINITY), |best, c| {
        if c.1 < best.1 { c } else { best }
    })
}

/// Folds closer to the carrier than this many Butterworth corners of the
/// output filter put a ripple on the rate (at two corners the biquad and
/// the RC pole still pass a fifth of it): [`fold_clear_carrier`] keeps the
/// operating carrier out of them, and a field step whose carrier lands in
/// one anyway says so.
pub const FOLD_CLEAR_CORNERS: f64 = 2.0;

/// Most grid points a side [`fold_clear_carrier`] tries. At 50 MHz the
/// grid is 12 mHz and 2048 points reach 24 Hz; at a 123 kHz clock
/// (2.9e-5 Hz) a 20 Hz reach is tried in steps of 4.9 mHz, over which a
/// fold of period 4096 moves 20 Hz.
pub const FOLD_SEARCH_POINTS: i64 = 2048;

/// The carrier on the NCO's grid (step f_clk / 2^32) nearest to
/// `carrier_hz` whose [`nearest_fold`] lies at least `clear_hz` from it,
/// within `max_shift_hz`: the grid points are tried outwards, nearest
/// first, at most [`FOLD_SEARCH_POINTS`] a side (with more within reach,
/// every m-th). `None` when every point tried folds closer.
///
/// A fold of period q moves q times as fast as the carrier (eps = f_clk
/// |q r - n|), so a ripple at a few Hz goes out of a passband of some ten
/// Hz for a shift of a fraction of a Hz: nothing beside a mode's bandwidth.
///
/// ```
/// use gyrocal_regs::plan::{fold_clear_carrier, nearest_fold};
/// // The paper device at 25 deg C folds 4.8 Hz from a 9.64 MHz carrier.
/// let clock = 50e6;
/// let moved = fold_clear_carrier(9_640_000.0039, clock, 40.0, 1.0).unwrap();
/// assert!(nearest_fold(moved, clock).1 >= 40.0);
/// assert!((moved - 9_640_000.0039).abs() < 0.1);
/// ```
pub fn fold_clear_carrier(
    carrier_hz: f64,
    clock_hz: f64,
    clear_hz: f64,
    max_shift_hz: f64,
) -> Option<f64> {
    fold_clear_carrier_within(
        carrier_hz,
        clock_hz,
        clear_hz,
        max_shift_hz,
        MAX_FOLD_PERIOD,
    )
}

/// [`fold_clear_carrier`] for the folds of periods up to `max_period`.
pub fn fold_clear_carrier_within(
    carrier_hz: f64,
    clock_hz: f64,
    clear_hz: f64,
    max_shift_hz: f64,
    max_period: u64,
) -> Option<f64> {
    let grid = clock_hz / 2f64.powi(32);
    let nearest = (carrier_hz / grid).round();
    let reach = (max_shift_hz / grid).floor().clamp(0.0, 1e12) as i64;
    // At most FOLD_SEARCH_POINTS points a side, each nearest_fold's 4096
    // periods: a slow clock's fine grid is strided.
    let stride = (reach / FOLD_SEARCH_POINTS).max(1);
    (0..=reach / stride)
        .flat_map(|k| [k * stride, -k * stride])
        .map(|k| (nearest + k as f64) * grid)
        .filter(|f| (f - carrier_hz).abs() <= max_shift_hz && *f > 0.0 && *f < clock_hz / 2.0)
        .find(|&f| clear_of_folds(f, clock_hz, clear_hz, max_period))
}

/// `nearest_fold_within(carrier_hz, clock_hz, max_period).1 >= clear_hz`,
/// stopping at the first period whose fold is nearer: the same distances,
/// compared one at a time instead of through their minimum (a NaN distance
/// is passed over by both, and a NaN `clear_hz` clears nothing in either).
/// A carrier search on a slow clock rejects most points it tries, each
/// after 4096 periods before.
fn clear_of_folds(carrier_hz: f64, clock_hz: f64, clear_hz: f64, max_period: u64) -> bool {
    !clear_hz.is_nan()
        && !fold_distances(carrier_hz, clock_hz, max_period).any(|(_, eps)| eps < clear_hz)
}

/// Each period q up to `max_period` with the distance (Hz) from the
/// carrier of its fold: q f_c lies that far from a multiple of the clock.
fn fold_distances(
    carrier_hz: f64,
    clock_hz: f64,
    max_period: u64,
) -> impl Iterator<Item = (u64, f64)> {
    let r = carrier_hz / clock_hz;
    (1..=max_period).map(move |q| {
        let x = r * q as f64;
        (q, clock_hz * (x - x.round()).abs())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan() -> FrequencyPlan {
        FrequencyPlan {
            clock_hz: 50e6,
            carrier_hz: 9.64e6,
            cal_hz: 10.0,
            calibration: true,
            amplitude: (0.9, 0.9),
            decimation: 1000,
            butterworth_hz: 500.0,
            rc_hz: 2000.0,
            dac_latency: 1,
            adc_latency: 2,
        }
    }

    /// `clear_of_folds` is the minimum's comparison it replaces: random
    /// carriers and clocks (a carrier near a fold of a short period half
    /// the time), clearances around the nearest fold's distance.
    #[test]
    fn clear_of_folds_is_the_nearest_folds_comparison() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / 2f64.powi(53)
        };
        let (mut clear, mut near) = (0, 0);
        for i in 0..20_000 {
            let clock = 1e5 * 500f64.powf(uniform());
            let carrier = if i % 2 == 0 {
                let q = 1 + (uniform() * 64.0) as u64;
                let p = (uniform() * q as f64 / 2.0).floor();
                clock * p / q as f64 + 50.0 * (uniform() - 0.5)
            } else {
                clock * 0.5 * uniform()
            };
            let max_period = 1 + (uniform() * 4096.0) as u64;
            let (_, eps) = nearest_fold_within(carrier, clock, max_period);
            let clear_hz = eps * (0.5 + uniform());
            let expected = eps >= clear_hz;
            assert_eq!(
                clear_of_folds(carrier, clock, clear_hz, max_period),
                expected,
                "carrier {carrier}, clock {clock}, clear {clear_hz}, periods {max_period}"
            );
            assert!(clear_of_folds(carrier, clock, eps, max_period));
            if expected {
                clear += 1;
            } else {
                near += 1;
            }
        }
        assert!(clear > 5_000 && near > 5_000, "{clear} clear, {near} near");
        assert!(!clear_of_folds(1e6, 5e7, f64::NAN, 16));
    }

    #[test]
    fn realized_frequencies_are_within_half_a_step() {
        let (regs, real) = registers(&plan()).unwrap();
        assert!((real.carrier_hz - 9.64e6).abs() <= 50e6 / 2f64.powi(33));
        assert!((real.cal_hz - 10.0).abs() <= 50e6 / 2f64.powi(49));
        assert_eq!(regs.ref_delay, 3);
        assert_eq!(regs.ref_phase, regs.carrier_step.div_ceil(2));
    }

    #[test]
    fn bad_plans_name_the_setting() {
        let mut p = plan();
        p.carrier_hz = 25e6;
        assert!(
            registers(&p)
                .unwrap_err()
                .to_string()
                .starts_with("carrier_hz = 25000000")
        );
        let mut p = plan();
        p.amplitude.1 = 1.0;
        assert!(
            registers(&p)
                .unwrap_err()
                .to_string()
                .starts_with("amplitude of drive 2")
        );
        let mut p = plan();
        p.dac_latency = 60;
        p.adc_latency = 4;
        assert!(
            registers(&p)
                .unwrap_err()
                .to_string()
                .starts_with("dac_latency + adc_latency = 64")
        );
    }

    #[test]
    fn commensurate_plans_are_flagged() {
        assert_eq!(commensurate_period(1e6, 10e6), Some(10));
        assert_eq!(commensurate_period(1.0123e6, 10e6), None);
    }

    /// The paper device's carriers at 30 and 25 deg C of
    /// `tests/data/field_paper.toml` fold at 18.2 and 4.8 Hz; at 15 deg C
    /// the nearest fold is 342 Hz away (period 40968 is beyond the search).
    #[test]
    fn the_paper_devices_folds_are_found() {
        let clock = 50e6;
        let (q, eps) = nearest_fold(9_638_553.997_5, clock);
        assert_eq!(q, 83);
        assert!((eps - 18.2).abs() < 0.1, "{eps}");
        let (q, eps) = nearest_fold(9_640_000.003_9, clock);
        assert_eq!(q, 1250);
        assert!((eps - 4.8).abs() < 0.1, "{eps}");
        assert!(nearest_fold(9_642_892.004_9, clock).1 > 1000.0);
        assert_eq!(commensurate_period(9.64e6, 50e6), None); // 241/1250
    }

    /// The nearest clear point on the grid, whichever side, and none
    /// within a reach too short: at 30 deg C the fold of period 83 moves
    /// 83 Hz per Hz of carrier, so clearing 1 kHz from 18.2 Hz takes 11.8 Hz.
    #[test]
    fn the_nearest_clear_carrier_is_found_on_the_grid() {
        let clock = 50e6;
        let grid = clock / 2f64.powi(32);
        let start = 9_638_553.997_5;
        let moved = fold_clear_carrier(start, clock, 1000.0, 20.0).unwrap();
        assert!(nearest_fold(moved, clock).1 >= 1000.0);
        assert!(((moved / grid) - (moved / grid).round()).abs() < 1e-6);
        assert!(
            (moved - start).abs() > 11.0 && (moved - start).abs() < 12.5,
            "{moved}"
        );
        // Every grid point nearer is folded.
        let steps = ((moved - start).abs() / grid).floor() as i64;
        for k in -steps + 1..steps {
            let f = ((start / grid).round() + k as f64) * grid;
            if (f - start).abs() < (moved - start).abs() {
                assert!(nearest_fold(f, clock).1 < 1000.0, "{f}");
            }
        }
        assert_eq!(fold_clear_carrier(start, clock, 1000.0, 5.0), None);
        // A clear carrier stays where it is (to the grid).
        let clear = 9_642_892.004_9;
        let kept = fold_clear_carrier(clear, clock, 1000.0, 1.0).unwrap();
        assert!((kept - clear).abs() <= grid / 2.0);
    }
}
