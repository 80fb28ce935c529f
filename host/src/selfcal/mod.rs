//! The self-calibration cycle, host side: identify, retune the carrier,
//! correct the loop phase, run the calibration staircase, and predict the
//! readout scale factor in the gateware's own units (z LSB per deg/s).
//!
//! # The ratio in z LSB, and which converter gains cancel
//!
//! Let a_k be ADC k's gain (LSB per metre), g_k drive k's force per DAC
//! LSB, W_k the drive words' amplitudes (digital, known from AMP). Output k
//! in z LSB is the mean of ADC_k times a reference word, so
//!
//! ```text
//! readout     output k: ADC_k x drive k's word;  x_k's rate term is driven by drive (1-k)
//!             SF_read,k ~ a_k W_k W_(1-k) g_(1-k) S_read,k
//! calibration output k: ADC_k x drive (1-k)'s word;  x_k is driven by drive k
//!             SF_cal,k  ~ a_k W_(1-k) W_k g_k S_cal,k
//! ratio_k = SF_read,k / SF_cal,k = (S_read,k / S_cal,k) x g_(1-k) / g_k
//! ```
//!
//! with S the theory's scale factors per unit force product. The ADC gain
//! a_k and any gain common to both drives cancel exactly; the drive-gain
//! ratio g_(1-k) / g_k enters one for one, with opposite signs on the two
//! outputs. At rest, on a device without a quadrature coupling, the modes
//! are uncoupled, so every response the gateware can observe carries a_k
//! g_k together: the differential drive gain cannot be told from an ADC
//! gain, and the cycle at rest uses the board's design ratio
//! (`Knowns::force_full_scale`). Its drift is the one converter drift the
//! cycle at rest cannot correct (measured in `tests/field.rs`). A
//! quadrature coupling couples the modes at rest: the cycle measures it
//! ([`crate::coupling`]) and, when it is strong enough, the ratio with it
//! (`AT_REST_RATIO_SIGMA`).
//!
//! It becomes observable while the device turns, at any rate and without
//! knowing it. With H_jk the response at ADC j to drive k, H_jk = a_j g_k
//! M_jk. The Coriolis coupling is antisymmetric, M_12 = -M_21, and
//! M_22 / M_11 = G_2 / G_1, the resonators' responses known from the
//! identification (both exact: `drive_ratio` module header), so
//!
//! ```text
//! (H_12 / H_21) / (H_11 / H_22) = (g_2 / g_1)^2 x (M_12 M_22) / (M_21 M_11)
//!                               = -(g_2 / g_1)^2 x G_2 / G_1
//! ```
//!
//! holds the drive-gain ratio alone: the rate cancels. The cross responses
//! are lambda Omega / bandwidth of the direct ones, so it needs a rate well
//! above the noise: the cycle at rest cannot use it. When the device turns
//! at a steady rate, [`crate::drive_ratio`] measures it (the ratio is exact
//! at any rate, not only to first order) and [`apply_drive_ratio`] predicts
//! again with it.
//!
//! # The prediction
//!
//! `ratio` is the exact theory (phasor steady state, `crate::theory`) at
//! the identified parameters, fitted with the same least-squares lines at
//! the same rates and calibration frequencies as the measurements (the
//! paper's 10-15 Hz are not deep in the linear region), with the
//! datapath's known details: the hold's sinc at each sideband and the
//! envelope lead (`theory::calibration_z_of_datapath`), and the drive
//! words' realized amplitudes in each mode. Eqs. (5)/(6) at the same
//! parameters are given beside it.

//!
//! # Drive amplitudes and clipping
//!
//! The configured amplitudes (`[drive] amplitude1/2`) are the largest the
//! cycle uses. From the identified responses the host predicts each ADC's
//! peak over every readout rate and calibration frequency of its plan
//! (exact theory, [`predict::adc_peaks`]) and scales both drives by one
//! factor so that no peak exceeds `ADC_OPERATING` of full scale; the ratio
//! of the drives, which the prediction needs, is kept
//! ([`Operating::scaled_drives`]; below half the configured drives the
//! reports say so in one line, [`ScaledDrives`]). The carrier search
//! judges each carrier's spur bound at the drive it would run with. Every
//! window then watches the ADC_CLIP counts ([`crate::clip`]): a clipped
//! window is an error, never a figure.
//!
//! # The carrier's folds
//!
//! A carrier near n / q of the clock shows the DAC and ADC only its q
//! sample phases, drifting slowly: the carrier tables' quantization errors
//! come back folded eps = f_clk |q f_c / f_clk - n| from the carrier, and
//! inside the output's passband they ripple the rate
//! (`gyrocal_regs::plan::nearest_fold`; on the paper device 0.46 deg/s RMS
//! where the floor is 0.07). The fold moves q times as fast as the
//! carrier, so the operating point moves the carrier along the NCO's grid
//! to the nearest place whose folds lie `FOLD_CLEAR_CORNERS` Butterworth
//! corners out, if that moves neither readout scale factor by more than
//! `FOLD_SF_CHANGE` ([`Operating::fold_shift_hz`] says how far it moved).
//!
//! On the table core, where no such place is within the allowance, the
//! operating point moves the carrier to where the bound on the rate ripple
//! from the carrier table's folded harmonics (`spurs`) is lowest, within
//! the same reach and allowance ([`Operating::spur_move`]): a fold's lines
//! lie at multiples of eps, and a move that cannot clear the passband can
//! still send most of them through the output filter's skirt. On the
//! paper device at 30 deg C the rate's RMS error fell from 2.4 and 4.4
//! times the quietest step's to 0.75 and 1.57 times.
//!
//! A fold of short period (`plan::STATIC_FOLD_PERIOD`) that beats less
//! than once a measurement window is worse: its error is the same in every
//! batch, so it biases the figures where no sigma sees it. The spur move
//! keeps the short folds beating at least `plan::SETTLED_FOLD_BEATS` times
//! a window. Where neither move is made, the operating point still moves the carrier
//! so that the short folds beat at least `plan::SETTLED_FOLD_BEATS` times a
//! window (a beat's residual in a window's mean falls as the beats grow),
//! or, if that move is too far, `plan::STATIC_FOLD_BEATS` times, within
//! the same reach and `STATIC_FOLD_SF_CHANGE`.
mod at_rest;
mod budget;
mod predict;
pub(crate) mod spurs;
mod staircase;

pub use budget::SfUncertainty;
pub use predict::{Ratio, adc_peaks, predicted_ratio, readout_sf};
pub use spurs::{
    Depth, FULL, NAMED_LINES, SEARCH, SPUR_BAND_CORNERS, SpurLine, Spurs, spur_rms, spurs,
};
pub use staircase::{Staircase, staircase};

use crate::board::Board;
use crate::coupling;
use crate::device::GyroParams;
use crate::drive_ratio::{CrossWindows, DriveRatio};
use crate::error::Error;
use crate::identify::{self, CouplingFigure, Estimate, Identified};
use crate::knowns::Knowns;
use gyrocal_regs::datapath::CarrierProfile;
use gyrocal_regs::plan;
use serde::Serialize;

/// Amplitude time constants waited after leaving the identification (the
/// resonators' state changes completely; the first staircase point must
/// settle to 1e-4 of a calibration signal some 1e3 times smaller).
pub const FIRST_SETTLE_TAUS: f64 = 30.0;

/// Fewest ripple periods in a staircase window: two, so that the spread of
/// the period means estimates the window's noise (`staircase`).
pub const MIN_RIPPLE_PERIODS: usize = 2;

/// Fraction of ADC full scale the operating drives put the largest
/// predicted peak at, at most: 1600 LSB below the rail, far above the
/// converter's noise (1 LSB) and the prediction's error (the identified
/// gains to 1e-4), and above the 0.9 that the simulator's front end is
/// built for (`[frontend] adc_headroom`), so a board that is as planned
/// keeps its configured drives.
pub const ADC_OPERATING: f64 = 0.95;

/// Largest relative 1-sigma of a drive-gain ratio measured at rest for the
/// cycle to predict with it instead of the design ratio: at rest the ratio
/// is seen only through a quadrature coupling (`drive_ratio::from_windows`),
/// and without one the estimate is 0 / 0. A tenth of the 1% by which a
/// drive-gain drift of 0.5% moves a detuned output (`tests/field.rs`):
/// below it the measured ratio's sigma costs less than the drift it
/// removes. The 250 deg/s coupled device measures it to 4e-5.
pub const AT_REST_RATIO_SIGMA: f64 = 1e-3;

/// Where the cycle operates the gateware.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Operating {
    /// Realized carrier (Hz).
    pub carrier_hz: f64,
    /// Reference phase lag written on top of the aligned REF_PHASE (deg).
    pub ref_lag_deg: f64,
    /// The loop's group delay (s), which the references' envelope does not
    /// follow.
    pub envelope_delay_s: f64,
    /// Drive amplitudes (fractions of full scale): the configured ones
    /// scaled so that no ADC is predicted above `ADC_OPERATING`.
    pub amplitude: (f64, f64),
    /// Where that scaled them down, by how much ([`ScaledDrives`]'s line
    /// says what it costs).
    pub scaled_drives: Option<ScaledDrives>,
    /// How far the carrier was moved from its configured place against
    /// the modes to keep the carrier tables' folds out of the passband
    /// (Hz, on the NCO's grid; 0 when it was not: module header).
    pub fold_shift_hz: f64,
    /// A fold of short period that beats slower than a window, left
    /// where the carrier could not move off it ([`static_fold`]): the
    /// figures of this operating point may lie beyond their sigmas.
    pub static_fold: Option<StaticFold>,
    /// On the table core, where no move cleared the passband: the carrier
    /// moved to where its spur bound (`spurs`) is lowest within the
    /// allowance, and that bound before and after ([`SpurMove`]).
    pub spur_move: Option<SpurMove>,
    /// The rate the device turned at during the cycle (deg/s): the
    /// couplings' windows' reading ([`Identified::cycle_rate_dps`]) where
    /// it is seen, else 0 ([`predicted_rate`]). The calibration responses
    /// are predicted at it (`theory::calibration_z_turning`), since on a
    /// detuned output a rate during the staircase moves the calibration
    /// scale factor (`CYCLE_RATE_SEEN`).
    pub cycle_rate_dps: f64,
}

/// A table-core carrier moved to lower its spur bound (`operating`).
/// The bound where it moved is the cycle's own
/// ([`SelfCal::carrier_spurs`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpurMove {
    /// The bound on the rate's RMS ripple per output where the carrier
    /// was asked (deg/s).
    pub from_dps: [f64; 2],
}

/// A carrier fold of period at most `plan::STATIC_FOLD_PERIOD` clocks
/// that beats less than `plan::STATIC_FOLD_BEATS` times a measurement
/// window: its error is the same in every batch, so no sigma sees it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StaticFold {
    /// The period q in clocks (the carrier is near n / q of the clock).
    pub period: u64,
    /// Its distance from the carrier (Hz).
    pub offset_hz: f64,
}

impl std::fmt::Display for StaticFold {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the carrier is {:.3} Hz from a fold of period {} clocks, slower than a window: its converters' and tables' errors are the same in every batch, so the figures at this carrier may lie beyond their sigmas",
            self.offset_hz, self.period
        )
    }
}

/// The configured drives scaled down so that no ADC is predicted above
/// `ADC_OPERATING` of full scale ([`Operating::scaled_drives`]).
///
/// On an unseen device (3.3 MHz, Q 40000, table core, 27.3 MHz clock)
/// whose front end was set 0.2% off its resonance, the drives ran at
/// 0.66% of the configured ones: the table words lost 7.2 bits, a fold of
/// period 91 in the passband rippled the rate by 281 deg/s RMS (bound 564),
/// and the scale factors' sigma was 0.31%. With the ADC gain 150 times
/// lower the drives ran at 99%, and the same step gave 1.6 deg/s (bound
/// 2.1) and 0.016%; on the fine core 0.38 deg/s and 0.010%.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ScaledDrives {
    /// The drives' amplitudes (fractions of full scale).
    pub amplitude: (f64, f64),
    /// Their fraction of the configured ones (`[drive] amplitude1/2`).
    pub fraction: f64,
    /// On the table core: the carrier words' rounding error is fixed in
    /// LSB, so its spur bound (`spurs`) grows as the drive shrinks.
    pub table_core: bool,
}

/// Scale below which the drive words have lost a bit: the reports name
/// such a scaling (`ScaledDrives`'s line), and on the table core what it
/// costs.
pub const DRIVE_BIT_LOST: f64 = 0.5;

impl ScaledDrives {
    /// Whether the reports name this scaling in a line: below
    /// `DRIVE_BIT_LOST` of the configured drives.
    pub fn is_said(&self) -> bool {
        self.fraction < DRIVE_BIT_LOST
    }
}

impl std::fmt::Display for ScaledDrives {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the drives run at {:.4} / {:.4} of full scale, {:.3}% of [drive] amplitude1/2, so that no ADC is predicted above {:.0}% of full scale",
            self.amplitude.0,
            self.amplitude.1,
            100.0 * self.fraction,
            100.0 * ADC_OPERATING
        )?;
        if self.table_core && self.is_said() {
            write!(
                f,
                "; the table core's carrier words lose {:.1} bits and its spurs grow as much (a lower ADC or drive gain lets the drive rise; the fine core shapes its rounding away from the carrier)",
                -self.fraction.log2()
            )?;
        }
        Ok(())
    }
}

/// The static fold of `carrier_hz` under `knowns`' clock and window, if
/// it has one.
pub fn static_fold(knowns: &Knowns, carrier_hz: f64) -> Option<StaticFold> {
    let (period, offset_hz) =
        plan::nearest_fold_within(carrier_hz, knowns.clock_hz, plan::STATIC_FOLD_PERIOD);
    (offset_hz * knowns.filter.min_window_s < plan::STATIC_FOLD_BEATS)
        .then_some(StaticFold { period, offset_hz })
}

/// One cycle's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SelfCal {
    /// What identification found.
    pub identified: Identified,
    /// Carrier and phase correction used.
    pub operating: Operating,
    /// Realized calibration frequencies (Hz).
    pub cal_hz: Vec<f64>,
    /// Staircase window means (z LSB).
    pub cal_z: Vec<[f64; 2]>,
    /// Calibration scale factors (z LSB per deg/s of virtual rate).
    pub sf_cal_per_dps: [f64; 2],
    /// The predicted ratios.
    pub ratio: Ratio,
    /// SF_cal x ratio.exact (z LSB per deg/s).
    pub sf_selfcal_per_dps: [f64; 2],
    /// SF_cal x ratio.eq56 (z LSB per deg/s).
    pub sf_eq56_per_dps: [f64; 2],
    /// The drive-gain ratio measured while the device turned, when it
    /// was (`drive_ratio`); the prediction above then uses it instead of
    /// the design ratio.
    pub drive_ratio: Option<DriveRatio>,
    /// SF_cal x ratio.exact at the design drive-gain ratio (z LSB per
    /// deg/s): `sf_selfcal_per_dps` before the measured ratio replaced it.
    pub sf_design_ratio_per_dps: [f64; 2],
    /// Relative 1-sigma uncertainty of `sf_selfcal_per_dps`, by source.
    pub sf_selfcal_uncertainty: SfUncertainty,
    /// On the table core, the carrier words' harmonics that the clock
    /// folds into the passband at `operating` and the bound on the rate
    /// ripple they make ([`spurs()`]); `None` on the fine core.
    pub carrier_spurs: Option<Spurs>,
    /// Clocks of the whole cycle.
    pub clocks: u64,
    /// The couplings and the rate as the cycle's windows read them at the
    /// design ratio, which a measured ratio reads again
    /// ([`apply_drive_ratio`]).
    #[serde(skip)]
    pub(crate) at_rest_reading: at_rest::Figures,
}

impl SelfCal {
    /// Whether this cycle's scale factors rest on the design's drive-gain
    /// ratio g2/g1 with nothing to bound it: no coupling at rest measured
    /// the ratio within [`AT_REST_RATIO_SIGMA`] (`drive_ratio` is None) and
    /// `knowns` give it no uncertainty. A drive gain that drifted since the
    /// design then moves a detuned output's scale factor one for one, and
    /// no sigma holds it.
    pub fn rests_on_design_ratio(&self, knowns: &Knowns) -> bool {
        self.drive_ratio.is_none() && knowns.drive_gain_ratio_uncertainty == 0.0
    }

    /// One line each: a carrier configured off both modes
    /// ([`Knowns::carrier_off_the_modes`]), a datasheet beyond a part's
    /// spread (`Identified::datasheet_departures`), what this cycle's
    /// sigma leaves out ([`rests_on_design_ratio`](Self::rests_on_design_ratio)),
    /// an output it cannot calibrate ([`Operating::static_fold`]) and a
    /// device that turned during the cycle ([`cycle_rate_warning`](Self::cycle_rate_warning)).
    /// Empty when there is nothing to say.
    pub fn warnings(&self, knowns: &Knowns) -> Vec<String> {
        let mut lines: Vec<String> = knowns.carrier_off_the_modes().into_iter().collect();
        lines.extend(self.identified.datasheet_departures(&knowns.nominal));
        if self.rests_on_design_ratio(knowns) {
            lines.push(format!(
                "warning: the drive-gain ratio g2/g1 is the design's (no coupling at rest measured it within {AT_REST_RATIO_SIGMA:e}) and the datasheet gives no drive_gain_ratio_uncertainty: a drive gain that drifted is not in the sigma"
            ));
        }
        if let Some(fold) = &self.operating.static_fold {
            lines.push(format!("warning: {fold}"));
        }
        lines.extend(self.cycle_rate_warning());
        lines.extend(self.rest_warning(knowns));
        lines
    }

    /// One line when the user said the device rests (`[experiment]
    /// rest_bound_dps`) and the couplings' windows read it turning beyond
    /// that bound ([`rest_contradicted`]): the device did not rest or the
    /// bound is wrong, and the rate's sigma is the reading's alone.
    pub fn rest_warning(&self, knowns: &Knowns) -> Option<String> {
        let (t, b) = (self.identified.cycle_rate_dps?, knowns.rest_bound_dps?);
        rest_contradicted(t, b).then(|| {
            format!(
                "warning: [experiment] rest_bound_dps = {b} says the device rests, but its cross responses read it turning at {:.4} +- {:.4} deg/s during the cycle: it did not rest, or the bound is wrong; the rate's sigma is the reading's, not the bound's",
                t.value, t.uncertainty
            )
        })
    }

    /// One line when the couplings' windows read a rate beyond
    /// [`CYCLE_RATE_SEEN`] of its sigmas: the device turned during the
    /// cycle. The figures are predicted at that rate
    /// ([`Operating::cycle_rate_dps`]); a rate that changed between the
    /// windows and the staircase is in no sigma.
    pub fn cycle_rate_warning(&self) -> Option<String> {
        let t = self.identified.cycle_rate_dps?;
        rate_seen(t).then(|| {
            format!(
                "warning: the device turned during the cycle: its cross responses read a rate of {:.3} +- {:.3} deg/s (their Coriolis coupling); the scale factors are predicted at that rate, which holds if it stayed steady through the cycle: a rate that changed is in no sigma",
                t.value, t.uncertainty
            )
        })
    }
}

/// The operating point for an identification: carrier kept at its
/// configured place against the nearer mode (`Knowns::operating_carrier`),
/// reference lagged by the identified loop phase, drives scaled below
/// clipping (module header).
pub fn operating(knowns: &Knowns, id: &Identified) -> Result<Operating, Error> {
    let asked = knowns.operating_carrier(id.modes[0].f_hz.value, id.modes[1].f_hz.value);
    let lag = id.loop_phase_deg.value;
    let at = |carrier: f64| -> Result<Operating, Error> {
        let (_, real) = knowns.registers(carrier, None, knowns.amplitude, lag)?;
        Ok(Operating {
            carrier_hz: real.carrier_hz,
            ref_lag_deg: lag,
            envelope_delay_s: id.group_delay_s.value,
            amplitude: knowns.amplitude,
            fold_shift_hz: 0.0,
            static_fold: static_fold(knowns, real.carrier_hz),
            spur_move: None,
            scaled_drives: None,
            cycle_rate_dps: prediction_rate_dps(id),
        })
    };
    let mut op = at(asked)?;
    // The passband clear of every fold; else, on the table core, the
    // lowest spur bound; else the short folds beating `SETTLED_FOLD_BEATS`
    // times a window, else once; the first move the allowance admits.
    let bandwidth = nearer_bandwidth(id, asked);
    let reach = FOLD_SHIFT_BANDWIDTHS * bandwidth;
    let sf_asked = readout_sf(knowns, id, &op)?;
    let admitted = |moved: &Operating, allowance: f64| -> Result<bool, Error> {
        let sf = readout_sf(knowns, id, moved)?;
        Ok((0..2).all(|k| (sf[k] / sf_asked[k] - 1.0).abs() <= allowance))
    };
    let clear = |clear_hz: f64, max_period: u64, allowance: f64| -> Result<_, Error> {
        let Some(to) =
            plan::fold_clear_carrier_within(asked, knowns.clock_hz, clear_hz, reach, max_period)
        else {
            return Ok(None);
        };
        let moved = at(to)?;
        Ok(admitted(&moved, allowance)?.then_some(moved))
    };
    let window = knowns.filter.min_window_s;
    let mut moved = clear(
        plan::FOLD_CLEAR_CORNERS * knowns.filter.butterworth_hz,
        plan::MAX_FOLD_PERIOD,
        FOLD_SF_CHANGE,
    )?;
    if moved.is_none() {
        moved = quietest_spurs(knowns, id, &op, reach, &at, &admitted)?;
    }
    for beats in [plan::SETTLED_FOLD_BEATS, plan::STATIC_FOLD_BEATS] {
        if moved.is_none() {
            moved = clear(
                beats / window,
                plan::STATIC_FOLD_PERIOD,
                STATIC_FOLD_SF_CHANGE,
            )?;
        }
    }
    if let Some(m) = moved {
        op = Operating {
            fold_shift_hz: m.carrier_hz - op.carrier_hz,
            ..m
        };
    }
    within_adc(knowns, id, op)
}

/// `op` with the configured drives scaled by one factor so that no ADC
/// peak is predicted above `ADC_OPERATING` (module header), or as they
/// are where none is.
fn within_adc(knowns: &Knowns, id: &Identified, op: Operating) -> Result<Operating, Error> {
    let peak = adc_peaks(knowns, id, &op)?.into_iter().fold(0.0, f64::max);
    if peak <= ADC_OPERATING {
        return Ok(Operating {
            amplitude: knowns.amplitude,
            scaled_drives: None,
            ..op
        });
    }
    let fraction = ADC_OPERATING / peak;
    let amplitude = (fraction * knowns.amplitude.0, fraction * knowns.amplitude.1);
    Ok(Operating {
        amplitude,
        scaled_drives: Some(ScaledDrives {
            amplitude,
            fraction,
            table_core: knowns.carrier_profile == CarrierProfile::Table,
        }),
        ..op
    })
}

/// Carriers tried a side of the asked one by `quietest_spurs`, evenly
/// over the fold move's reach.
pub const SPUR_SEARCH_POINTS: u32 = 32;

/// Least factor by which a move must lower the larger output's spur
/// bound, relative to its own, for `quietest_spurs` to take it: the
/// bound is an amplitude sum (`spurs`), and a smaller gain may be none.
pub const SPUR_MOVE_GAIN: f64 = 1.5;

/// On the table core, where no carrier within reach clears the passband:
/// the carrier within reach whose spur bound (`spurs::spurs`) is lowest,
/// among those that move the readout scale factors by at most
/// `FOLD_SF_CHANGE` and leave the short folds beating at least
/// `plan::SETTLED_FOLD_BEATS` times a window, if it lowers the bound on
/// each output by `SPUR_MOVE_GAIN` at least. A fold of period q sends its
/// lines k eps from the carrier, and eps moves q times as fast as the
/// carrier: a move that cannot clear the passband still sends most lines
/// through the output filter's skirt.
///
/// On the paper device at 30 deg C (fold of period 83, 18 Hz from the
/// asked carrier) the move is -1.09 Hz (the fold 109 Hz away, the scale
/// factors some 4% off the asked point's): the bound falls from 0.77 / 0.39
/// deg/s RMS to 0.23 / 0.13, against 0.49 / 0.25 where four beats a window
/// would have put the carrier, and the rate's RMS error under the field
/// profile from 0.158 / 0.088 deg/s to 0.049 / 0.031 (`gyrocal field
/// --config tests/data/field_paper.toml`); 3 Hz would lower the bound
/// four times more but move the scale factors 12%.
fn quietest_spurs(
    knowns: &Knowns,
    id: &Identified,
    asked: &Operating,
    reach: f64,
    at: &dyn Fn(f64) -> Result<Operating, Error>,
    admitted: &dyn Fn(&Operating, f64) -> Result<bool, Error>,
) -> Result<Option<Operating>, Error> {
    // Each bound at the drives the carrier would run with: the table
    // words' rounding error is fixed in LSB, so a drive scaled down for
    // the ADCs (`within_adc`) raises the bound as much.
    let driven = |op: &Operating| within_adc(knowns, id, op.clone());
    let asked_driven = driven(asked)?;
    let Some(here) = spur_rms(knowns, id, &asked_driven, SEARCH)? else {
        return Ok(None);
    };
    let settled = plan::SETTLED_FOLD_BEATS / knowns.filter.min_window_s;
    let mut best: Option<(f64, Operating)> = None;
    for j in 1..=SPUR_SEARCH_POINTS {
        for side in [-1.0, 1.0] {
            let step = side * reach * f64::from(j) / f64::from(SPUR_SEARCH_POINTS);
            let moved = at(asked.carrier_hz + step)?;
            let (_, eps) = plan::nearest_fold_within(
                moved.carrier_hz,
                knowns.clock_hz,
                plan::STATIC_FOLD_PERIOD,
            );
            if eps < settled || !admitted(&moved, FOLD_SF_CHANGE)? {
                continue;
            }
            let Some(there) = spur_rms(knowns, id, &driven(&moved)?, SEARCH)? else {
                continue;
            };
            let score = (0..2).map(|k| there[k] / here[k]).fold(0.0, f64::max);
            if score * SPUR_MOVE_GAIN <= 1.0 && best.as_ref().is_none_or(|b| score < b.0) {
                best = Some((score, moved));
            }
        }
    }
    // The bound where the carrier was asked, in full, as the step reports
    // it (the cycle computes the one where it moved, `self_calibrate`).
    let Some((_, moved)) = best else {
        return Ok(None);
    };
    let from_dps = spur_rms(knowns, id, &asked_driven, FULL)?.unwrap_or_default();
    Ok(Some(Operating {
        spur_move: Some(SpurMove { from_dps }),
        ..moved
    }))
}

/// Farthest the carrier is looked for off its configured place to clear
/// the folds, as a fraction of the nearer mode's bandwidth f / Q.
pub const FOLD_SHIFT_BANDWIDTHS: f64 = 0.1;

/// Largest change of either output's readout scale factor (predicted at
/// the identified device, [`predict::readout_sf`]) a move that clears the
/// folds may make. The truth and the prediction are both taken where the
/// carrier is, so accuracy does not limit the move; the operating point
/// the user chose does. The scale factors drift by more over the field
/// scenarios' temperature steps (7% on the paper device). On the paper
/// device the 0.8 Hz that clears the 25 deg C fold moves them by 3%; the
/// 11.8 Hz for the 30 deg C fold would move them by 45%, and on the
/// consumer device an 8.7 mHz move changed output 2's by a third (its
/// readout term is the small real part of mode 1's response): those do
/// not clear their fold (they move at most to lower the spur bound,
/// `quietest_spurs`, or by the static fold's rule,
/// `plan::SETTLED_FOLD_BEATS`), and their field steps report it.
pub const FOLD_SF_CHANGE: f64 = 0.05;

/// [`FOLD_SF_CHANGE`] for a move off a static fold
/// (`plan::STATIC_FOLD_BEATS`), where more is at stake than a ripple: on
/// an unseen device (15 kHz on 1.2 MHz, carrier 0.004 Hz from a fold of
/// period 80) the measured couplings were 84 and 50 of their sigmas off
/// (before those carried their coverage factor; some 55 and 33 after),
/// and the 0.031 Hz that gives the fold one beat a window moves the
/// scale factors by 5.7%. The scale factors drift by 7% over the paper
/// field's steps; a move that would change them by more than 10% is not
/// the operating point the user chose, and the step names its fold.
pub const STATIC_FOLD_SF_CHANGE: f64 = 0.10;

/// The nearer mode's bandwidth f / Q to `asked` (Hz): the reach of a
/// fold move is `FOLD_SHIFT_BANDWIDTHS` of it.
fn nearer_bandwidth(id: &Identified, asked: f64) -> f64 {
    let nearer = id
        .modes
        .iter()
        .min_by(|a, b| {
            (a.f_hz.value - asked)
                .abs()
                .total_cmp(&(b.f_hz.value - asked).abs())
        })
        .expect("two modes");
    nearer.f_hz.value / nearer.q.value
}

/// One self-calibration cycle from a starting guess of the device:
/// [`identify::identify`], then [`self_calibrate_from`] what it found.
pub fn self_calibrate(
    board: &mut dyn Board,
    knowns: &Knowns,
    guess: &GyroParams,
) -> Result<SelfCal, Error> {
    let identified = identify::identify(board, knowns, guess)?;
    self_calibrate_from(board, knowns, identified)
}

/// The cycle after identification: the couplings at rest, the operating
/// point, the calibration staircase and the predicted ratio. Every wait
/// uses the identified modes, not the datasheet. A caller that keeps
/// `identified` (a clone) still has it when this fails: a board that
/// stops mid-staircase does not take the identification with it.
pub fn self_calibrate_from(
    board: &mut dyn Board,
    knowns: &Knowns,
    mut identified: Identified,
) -> Result<SelfCal, Error> {
    // The quadrature coupling at rest, at the operating point of the
    // uncoupled device; then the operating point again with it (its
    // cross responses move the predicted ADC peaks).
    let first = knowns.with_device(&identified.gyro(&knowns.nominal));
    let op = operating(&first, &identified)?;
    let windows = CrossWindows::measure(board, &first, &op)?;
    identified.clocks += windows.clocks;
    let spur_lines = coupling::spur_lines(&windows, &first, &op, &identified)?;
    let spur_lines = spur_lines.as_deref();
    let identified = uncoupled(
        &windows,
        &first,
        &op,
        identified,
        knowns.nominal.angular_gain,
        spur_lines,
    )?;
    // The same windows give the drive-gain ratio when the coupling makes
    // it observable (`drive_ratio::from_windows`), applied below, and the
    // couplings and the rate read again at it (`at_rest`).
    let (identified, at_rest, at_rest_reading) =
        at_rest::ratio_at_rest(&windows, &first, &op, identified, spur_lines);
    let gyro = identified.gyro(&knowns.nominal);
    let measured = knowns.with_device(&gyro);
    let op = operating(&measured, &identified)?;
    let peaks = adc_peaks(&measured, &identified, &op)?;
    let Staircase {
        cal_hz,
        z: cal_z,
        sf_per_dps: sf_cal,
        sf_uncertainty: sf_cal_sd,
        clocks,
    } = staircase(board, &measured, &op, peaks)?;
    let ratio = predicted_ratio(knowns, &gyro, &op, &cal_hz)?;
    let uncertainty = SfUncertainty {
        staircase: std::array::from_fn(|k| (sf_cal_sd[k] / sf_cal[k]).abs()),
        identified: budget::identified(knowns, &identified, &op, &cal_hz, &ratio)?,
        angular_gain: budget::angular_gain(knowns, &gyro, &op, &cal_hz, &ratio)?,
        // The design ratio's own; a measured ratio replaces it below.
        drive_ratio: budget::design_drive_ratio(knowns, &gyro, &op, &cal_hz, &ratio)?,
        cycle_rate: budget::cycle_rate(knowns, &identified, &op, &cal_hz, &ratio)?,
        clock: budget::clock(knowns, &gyro, &op, &cal_hz, &ratio)?,
        ..SfUncertainty::default()
    }
    .with_total();
    let sf_selfcal_per_dps = std::array::from_fn(|k| sf_cal[k] * ratio.exact[k]);
    let sf_eq56_per_dps = std::array::from_fn(|k| sf_cal[k] * ratio.eq56[k]);
    let mut cal = SelfCal {
        clocks: identified.clocks + clocks,
        identified,
        operating: op,
        cal_hz,
        cal_z,
        sf_cal_per_dps: sf_cal,
        ratio,
        sf_selfcal_per_dps,
        sf_eq56_per_dps,
        drive_ratio: None,
        sf_design_ratio_per_dps: sf_selfcal_per_dps,
        sf_selfcal_uncertainty: uncertainty,
        carrier_spurs: None,
        at_rest_reading,
    };
    if let Some(at_rest) = at_rest {
        apply_drive_ratio(knowns, &mut cal, at_rest)?;
    }
    cal.carrier_spurs = spurs(knowns, &cal.identified, &cal.operating)?;
    Ok(cal)
}

/// Rounds of estimating the coupling with the modes uncoupled by the last
/// estimate (the estimator needs the uncoupled resonators,
/// `coupling::uncouple` needs the coupling): on the consumer device at
/// 3,000 deg/s one round left -0.23 deg/s (23 sigma), at 10,000 deg/s
/// -129 deg/s; the fixed point contracts by about k^2 |G_1 G_2| a round.
const COUPLING_ROUNDS: usize = 8;

/// A damping coupling estimate within this many of its sigmas of zero is
/// taken as none (its sigma then the hypotenuse of the two): a detuned
/// output can be very sensitive to it (the consumer device's output 2
/// moves 4% per deg/s), and on a device without one the estimate sat at
/// 2.4 and 2.6 sigma (0.02 deg/s; the batch spread has 7 degrees of
/// freedom), which predicted with moved that output by 0.11%.
pub const DAMPING_SEEN: f64 = 4.0;

/// The identified modes uncoupled by the coupling measured in `windows`,
/// which they carry; `spur_lines`, the table core's lines in the windows
/// (`coupling::spur_lines`), in the couplings' sigmas.
fn uncoupled(
    windows: &CrossWindows,
    knowns: &Knowns,
    op: &Operating,
    apparent: Identified,
    angular_gain: f64,
    spur_lines: Option<&[coupling::TurningLine]>,
) -> Result<Identified, Error> {
    let mut id = apparent.clone();
    let mut c = coupling::from_windows(windows, knowns, op, &id, spur_lines)?;
    let uncouple = |c: &coupling::Coupling| {
        coupling::uncouple(&apparent, c, angular_gain, knowns.clock_hz, op.carrier_hz)
    };
    for _ in 0..COUPLING_ROUNDS {
        id = uncouple(&c)?;
        c = coupling::from_windows(windows, knowns, op, &id, spur_lines)?;
    }
    let damping = c.damping_dps;
    if damping.value.abs() < DAMPING_SEEN * damping.uncertainty {
        // Not seen: predict without it, and let its sigma say what an
        // unseen one could leave.
        c.damping_dps = damping.as_unseen();
    }
    id = uncouple(&c)?;
    // Figures in deg/s: lambda's 1-sigma is the datasheet's.
    let figure = |e| CouplingFigure::new(e, knowns.angular_gain_uncertainty);
    id.quadrature_dps = Some(figure(c.quadrature_dps));
    id.damping_coupling_dps = Some(figure(c.damping_dps));
    id.cycle_rate_dps = Some(c.rate_dps);
    Ok(id)
}

/// A rate read in the couplings' windows beyond this many of its sigmas
/// is seen: the calibration is predicted at it ([`predicted_rate`]) and
/// the run says the device turned (`SelfCal::warnings`). A rate during
/// the cycle moves a detuned output's calibration (the consumer device's
/// output 2 by 4.6% per deg/s: predicted at rest, -23% at 5 deg/s, +9.2%
/// at -2). At rest five devices (the paper's, the consumer, the coupled,
/// the high-Q and a 47 kHz one) read within 2.3 of their sigmas of 0; 5
/// deg/s and -2 deg/s read within 1.7% of the rate.
pub const CYCLE_RATE_SEEN: f64 = 5.0;

/// The windows' rate `reading` is beyond [`CYCLE_RATE_SEEN`] of its sigmas.
pub(crate) fn rate_seen(reading: Estimate) -> bool {
    reading.value.abs() > CYCLE_RATE_SEEN * reading.uncertainty
}

/// The rate the calibration is predicted at ([`Operating::cycle_rate_dps`])
/// and its sigma (`SfUncertainty::cycle_rate`), from the couplings'
/// windows' `reading`: the reading where it is seen; else 0, with the
/// reading's value and sigma in quadrature as its sigma (what an unseen
/// rate could leave), as an unseen damping coupling (`DAMPING_SEEN`).
/// Predicting at an unseen reading would put its noise into the figure:
/// the consumer device's output 2 moves by 4.6e-4 per 0.01 deg/s, and the
/// reading's rounding alone moved by that much when the converters' gains
/// did (`tests/field.rs`, `adc_and_common_drive_gains_cancel`).
///
/// Where the user says the device rests (`rest_bound_dps`, a bound b on
/// its rate) and the reading agrees ([`rest_contradicted`]), an unseen rate
/// lies within +-b, anywhere in it: its sigma is b / sqrt 3, the
/// rectangular distribution's (GUM 4.3.7), when that is the smaller.
///
/// ```
/// use gyrocal_host::identify::Estimate;
/// use gyrocal_host::selfcal::predicted_rate;
/// let reading = Estimate { value: 0.012, uncertainty: 0.015 };
/// // Unseen: 0, its sigma the reading's value and sigma together.
/// assert_eq!(predicted_rate(reading, None).uncertainty, 0.012f64.hypot(0.015));
/// // Resting on a fixture: Earth's rate at most.
/// let rest = predicted_rate(reading, Some(0.0042));
/// assert_eq!((rest.value, rest.uncertainty), (0.0, 0.0042 / 3f64.sqrt()));
/// // A reading that the bound cannot explain keeps its own sigma.
/// let turning = Estimate { value: 0.06, uncertainty: 0.015 };
/// assert_eq!(predicted_rate(turning, Some(0.0042)), predicted_rate(turning, None));
/// ```
pub fn predicted_rate(reading: Estimate, rest_bound_dps: Option<f64>) -> Estimate {
    if rate_seen(reading) {
        return reading;
    }
    let unseen = reading.as_unseen();
    match rest_bound_dps {
        Some(b) if !rest_contradicted(reading, b) => Estimate {
            value: 0.0,
            uncertainty: unseen.uncertainty.min(b / 3f64.sqrt()),
        },
        _ => unseen,
    }
}

/// A reading beyond the rest bound b by more than this many of its sigmas
/// says the device did not rest (or b is wrong): the bound is then not
/// used, and the run says so (`SelfCal::rest_warning`).
pub const REST_CONTRADICTED: f64 = 3.0;

/// The windows' rate `reading` lies farther from +-`bound_dps` than
/// [`REST_CONTRADICTED`] of its sigmas.
pub fn rest_contradicted(reading: Estimate, bound_dps: f64) -> bool {
    reading.value.abs() > bound_dps + REST_CONTRADICTED * reading.uncertainty
}

/// The rate the calibration is predicted at for the identification `id`
/// ([`predicted_rate`] of its windows' reading; 0 without one): what
/// [`Operating::cycle_rate_dps`] holds and the cross responses' Coriolis
/// term (`drive_ratio::cross_terms`) takes. A rest bound moves the
/// sigma alone, never the rate predicted at.
pub(crate) fn prediction_rate_dps(id: &Identified) -> f64 {
    id.cycle_rate_dps
        .map_or(0.0, |r| predicted_rate(r, None).value)
}

/// `knowns` with drive 2's force gain moved by `relative` (g_2 / g_1 over
/// the design ratio).
fn with_drive_ratio(knowns: &Knowns, relative: f64) -> Knowns {
    let mut moved = knowns.clone();
    moved.force_full_scale[1] *= relative;
    moved
}

/// Predict again with a measured drive-gain ratio (`drive_ratio`): the
/// exact theory at the same identified device, operating point and
/// staircase, with drive 2's force gain moved by the measured ratio; the
/// ratio's uncertainty is propagated to each scale factor.
pub fn apply_drive_ratio(
    knowns: &Knowns,
    cal: &mut SelfCal,
    measured: DriveRatio,
) -> Result<(), Error> {
    // The couplings and the rate the cycle's windows read, read again at
    // this ratio (`at_rest`): where the drives part, a damping coupling
    // reads as a rate -b d, at which the calibration would be predicted.
    let lambda = knowns.angular_gain_uncertainty;
    let reading = cal.at_rest_reading.at_ratio(measured.relative, lambda);
    reading.put(&mut cal.identified);
    cal.operating.cycle_rate_dps = prediction_rate_dps(&cal.identified);
    let gyro = cal.identified.gyro(&knowns.nominal);
    let predict = |relative: f64| {
        predicted_ratio(
            &with_drive_ratio(knowns, relative),
            &gyro,
            &cal.operating,
            &cal.cal_hz,
        )
    };
    let rho = measured.relative;
    let ratio = predict(rho.value)?;
    let moved = predict(rho.value + rho.uncertainty)?;
    cal.sf_selfcal_uncertainty.drive_ratio =
        std::array::from_fn(|k| (moved.exact[k] / ratio.exact[k] - 1.0).abs());
    // The terms of the figures read again, at the measured ratio.
    let at = with_drive_ratio(knowns, rho.value);
    let (id, op, cal_hz) = (&cal.identified, &cal.operating, &cal.cal_hz);
    cal.sf_selfcal_uncertainty.identified = budget::identified(&at, id, op, cal_hz, &ratio)?;
    cal.sf_selfcal_uncertainty.cycle_rate = budget::cycle_rate(&at, id, op, cal_hz, &ratio)?;
    cal.sf_selfcal_uncertainty.clock = budget::clock(&at, &gyro, op, cal_hz, &ratio)?;
    cal.sf_selfcal_uncertainty = cal.sf_selfcal_uncertainty.with_total();
    cal.sf_selfcal_per_dps = std::array::from_fn(|k| cal.sf_cal_per_dps[k] * ratio.exact[k]);
    cal.sf_eq56_per_dps = std::array::from_fn(|k| cal.sf_cal_per_dps[k] * ratio.eq56[k]);
    cal.ratio = ratio;
    cal.drive_ratio = Some(measured);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scaled drives' line names the table words' lost bits only on
    /// the table core, and only once a bit is lost.
    #[test]
    fn the_scaled_drives_line_names_the_table_cores_lost_bits() {
        let line = |fraction: f64, table_core: bool| {
            let amplitude = (0.9 * fraction, 0.9 * fraction);
            ScaledDrives {
                amplitude,
                fraction,
                table_core,
            }
            .to_string()
        };
        let small = line(1.0 / 150.0, true);
        assert!(
            small.contains("0.0060 / 0.0060 of full scale, 0.667%"),
            "{small}"
        );
        assert!(small.contains("lose 7.2 bits"), "{small}");
        assert!(!line(1.0 / 150.0, false).contains("bits"));
        assert!(!line(0.6, true).contains("bits"));
    }
}
