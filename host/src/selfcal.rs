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
//! outputs. At rest the modes are uncoupled, so every response the gateware
//! can observe carries a_k g_k together: the differential drive gain cannot
//! be told from an ADC gain, and the cycle at rest uses the board's design
//! ratio (`Knowns::force_full_scale`). Its drift is the one converter drift
//! the cycle at rest cannot correct (measured in `tests/field.rs`).
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

use crate::board::Board;
use crate::device::GyroParams;
use crate::drive_ratio::DriveRatio;
use crate::error::Error;
use crate::identify::{self, Identified, readout_word};
use crate::knowns::Knowns;
use crate::sampling::part_means;
use crate::stats::linear_fit;
use crate::theory::{self, Device, envelope_lead_rad, hold_gain};
use gyrocal_regs::datapath::calibration_word;
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// Amplitude time constants waited after leaving the identification (the
/// resonators' state changes completely; the first staircase point must
/// settle to 1e-4 of a calibration signal some 1e3 times smaller).
pub const FIRST_SETTLE_TAUS: f64 = 30.0;

/// Fewest ripple periods in a staircase window: two, so that the spread of
/// the period means estimates the window's noise (`staircase`).
pub const MIN_RIPPLE_PERIODS: usize = 2;

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
}

/// Readout and calibration ratio predictions per output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ratio {
    /// Exact theory, fitted at the measurement points (z LSB units).
    pub exact: [f64; 2],
    /// Eqs. (5)/(6), small signal (z LSB units).
    pub eq56: [f64; 2],
}

/// Relative 1-sigma uncertainties of the self-calibrated scale factors,
/// per output, by source, and their quadrature sum.
///
/// Not included: a drive-gain ratio that drifted unobserved (without
/// `[drive_probe]` the design ratio is used as exact).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SfUncertainty {
    /// The staircase slope's noise (`staircase`).
    pub staircase: [f64; 2],
    /// The predicted ratio's, from the identified f1, f2, Q1, Q2, group
    /// delay and loop phase (each moved by its uncertainty through the
    /// exact theory).
    pub identified: [f64; 2],
    /// The measured drive-gain ratio's (0 without one).
    pub drive_ratio: [f64; 2],
    /// All three in quadrature.
    pub total: [f64; 2],
}

impl SfUncertainty {
    fn with_total(mut self) -> Self {
        self.total = std::array::from_fn(|k| {
            self.staircase[k]
                .hypot(self.identified[k])
                .hypot(self.drive_ratio[k])
        });
        self
    }
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
    /// Clocks of the whole cycle.
    pub clocks: u64,
}

/// The operating point for an identification: carrier at identified f1 plus
/// the configured offset, reference lagged by the identified loop phase.
pub fn operating(knowns: &Knowns, id: &Identified) -> Result<Operating, Error> {
    let asked = id.modes[0].f_hz.value + knowns.carrier_offset_hz;
    let lag = id.loop_phase_deg.value;
    let (_, real) = knowns.registers(asked, None, knowns.amplitude, lag)?;
    Ok(Operating {
        carrier_hz: real.carrier_hz,
        ref_lag_deg: lag,
        envelope_delay_s: id.group_delay_s.value,
    })
}

/// A measured staircase.
#[derive(Clone, Debug, PartialEq)]
pub struct Staircase {
    /// Realized calibration frequencies (Hz).
    pub cal_hz: Vec<f64>,
    /// Window means (z LSB).
    pub z: Vec<[f64; 2]>,
    /// Least-squares slopes against 360 f_cal (z LSB per deg/s).
    pub sf_per_dps: [f64; 2],
    /// Their 1-sigma uncertainties (z LSB per deg/s): `staircase`.
    pub sf_uncertainty: [f64; 2],
    /// Clocks it took.
    pub clocks: u64,
}

/// The calibration staircase at `op`: each f_cal settles, then is averaged
/// over a whole number (at least `MIN_RIPPLE_PERIODS`) of ripple periods
/// 1 / (2 f_cal) spanning at least the first window.
///
/// Uncertainty: each period's mean cancels the ripple's shape, so the
/// spread of a window's period means is its noise; pooled over the windows
/// (one variance per output, sum of (M_i - 1) degrees of freedom) it gives
/// each window mean's variance s^2 / M_i, propagated through the
/// least-squares slope, sum of c_i^2 s^2 / M_i with c_i = (x_i - mean x) /
/// Sxx.
pub fn staircase(
    board: &mut dyn Board,
    knowns: &Knowns,
    op: &Operating,
) -> Result<Staircase, Error> {
    let clock = knowns.clock_hz;
    let r = knowns.filter.decimation;
    let mut cal_hz = vec![];
    let mut parts = vec![];
    let mut clocks = 0;
    for (i, &f) in knowns.cal_freqs_hz.iter().enumerate() {
        let (regs, real) =
            knowns.registers(op.carrier_hz, Some(f), knowns.amplitude, op.ref_lag_deg)?;
        board.program(&regs)?;
        let taus = if i == 0 {
            FIRST_SETTLE_TAUS
        } else {
            identify::SETTLE_TAUS
        };
        let settle = knowns.settle_clocks(taus);
        board.wait_clocks(settle)?;
        let period = clock / (2.0 * real.cal_hz);
        let periods = (knowns.filter.min_window_s * 2.0 * real.cal_hz)
            .ceil()
            .max(MIN_RIPPLE_PERIODS as f64);
        let length = periods * period;
        parts.push(part_means(
            board,
            r,
            f64::from(r),
            length,
            periods as usize,
        )?);
        clocks += settle + length as u64 + 2 * u64::from(r);
        cal_hz.push(real.cal_hz);
    }
    let means: Vec<[f64; 2]> = parts
        .iter()
        .map(|p| std::array::from_fn(|k| p.iter().map(|m| m[k]).sum::<f64>() / p.len() as f64))
        .collect();
    let x: Vec<f64> = cal_hz.iter().map(|f| 360.0 * f).collect();
    let sf = std::array::from_fn(|k| {
        let y: Vec<f64> = means.iter().map(|m| m[k]).collect();
        linear_fit(&x, &y).0
    });
    Ok(Staircase {
        cal_hz,
        sf_per_dps: sf,
        sf_uncertainty: std::array::from_fn(|k| pooled_slope_uncertainty(&x, &parts, &means, k)),
        z: means,
        clocks,
    })
}

/// The least-squares slope's 1-sigma uncertainty on output `k` from the
/// windows' period means `parts` (`staircase`).
fn pooled_slope_uncertainty(
    x: &[f64],
    parts: &[Vec<[f64; 2]>],
    means: &[[f64; 2]],
    k: usize,
) -> f64 {
    let (mut ss, mut dof) = (0.0, 0usize);
    for (p, m) in parts.iter().zip(means) {
        ss += p.iter().map(|v| (v[k] - m[k]).powi(2)).sum::<f64>();
        dof += p.len() - 1;
    }
    let s2 = ss / dof as f64;
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let var: f64 = x
        .iter()
        .zip(parts)
        .map(|(xi, p)| ((xi - mx) / sxx).powi(2) * s2 / p.len() as f64)
        .sum();
    var.sqrt()
}

/// The predicted readout over calibration ratio in z LSB (module header)
/// for a device `gyro` operated at `op`, with calibration frequencies
/// `cal_hz` (realized).
pub fn predicted_ratio(
    knowns: &Knowns,
    gyro: &GyroParams,
    op: &Operating,
    cal_hz: &[f64],
) -> Result<Ratio, Error> {
    predicted_ratio_lagged(knowns, gyro, op, cal_hz, 0.0)
}

/// [`predicted_ratio`] with a residual loop phase error `lag_rad` left by
/// the correction (the responses lag their references by that much more).
fn predicted_ratio_lagged(
    knowns: &Knowns,
    gyro: &GyroParams,
    op: &Operating,
    cal_hz: &[f64],
    lag_rad: f64,
) -> Result<Ratio, Error> {
    let clock = knowns.clock_hz;
    let (regs, _) = knowns.registers(op.carrier_hz, None, knowns.amplitude, 0.0)?;
    let amp = [regs.amp.0, regs.amp.1];
    let per_lsb = knowns.force_full_scale.map(|f| f / 32768.0);
    let read_words = amp.map(readout_word);
    let cal_words = amp.map(|a| calibration_word(a).abs());
    let device = |words: [f64; 2]| Device {
        f1_hz: gyro.f1_hz,
        f2_hz: gyro.f2_hz,
        q1: gyro.q1,
        q2: gyro.q2,
        angular_gain: gyro.angular_gain,
        quadrature_dps: gyro.quadrature_dps,
        damping_coupling_dps: gyro.damping_coupling_dps,
        carrier_hz: op.carrier_hz,
        f1_force: words[0] * per_lsb[0],
        f2_force: words[1] * per_lsb[1],
    };
    let (dev_read, dev_cal) = (device(read_words), device(cal_words));
    let rad = PI / 180.0;
    let rates = &knowns.rates_dps;
    let read_z: Vec<[f64; 2]> = rates
        .iter()
        .map(|r| theory::readout_z_lagged(&dev_read, r * rad, lag_rad))
        .collect();
    let hold = hold_gain(op.carrier_hz, clock);
    let cal_z: Vec<[f64; 2]> = cal_hz
        .iter()
        .map(|&f| {
            let sidebands = [-1.0, 1.0].map(|s| hold_gain(op.carrier_hz + s * f, clock) / hold);
            // The response's envelope comes late by the group delay: the
            // references' envelope leads it by that much more.
            let lead = envelope_lead_rad(f, clock) + TAU * f * op.envelope_delay_s;
            theory::calibration_z_lagged(&dev_cal, f, lead, sidebands, lag_rad)
        })
        .collect();
    let virtual_dps: Vec<f64> = cal_hz.iter().map(|f| 360.0 * f).collect();
    let slope = |x: &[f64], z: &[[f64; 2]], k: usize| {
        let y: Vec<f64> = z.iter().map(|v| v[k]).collect();
        linear_fit(x, &y).0
    };
    // z LSB: readout output k divides by g_k, calibration output k by g_(1-k).
    let to_lsb = |k: usize| per_lsb[1 - k] / per_lsb[k];
    let exact = std::array::from_fn(|k| {
        slope(rates, &read_z, k) / slope(&virtual_dps, &cal_z, k) * to_lsb(k)
    });
    let eq5 = theory::eq5_sf_read_per_rad_s(&dev_read);
    let eq6 = theory::eq6_sf_cal_per_rad_s(&dev_cal);
    let eq56 = std::array::from_fn(|k| eq5 / eq6[k] * to_lsb(k));
    Ok(Ratio { exact, eq56 })
}

/// One self-calibration cycle from a starting guess of the device.
pub fn self_calibrate(
    board: &mut dyn Board,
    knowns: &Knowns,
    guess: &GyroParams,
) -> Result<SelfCal, Error> {
    let identified = identify::identify(board, knowns, guess)?;
    let op = operating(knowns, &identified)?;
    let Staircase {
        cal_hz,
        z: cal_z,
        sf_per_dps: sf_cal,
        sf_uncertainty: sf_cal_sd,
        clocks,
    } = staircase(board, knowns, &op)?;
    let gyro = identified.gyro(&knowns.nominal);
    let ratio = predicted_ratio(knowns, &gyro, &op, &cal_hz)?;
    let uncertainty = SfUncertainty {
        staircase: std::array::from_fn(|k| (sf_cal_sd[k] / sf_cal[k]).abs()),
        identified: identified_uncertainty(knowns, &identified, &op, &cal_hz, &ratio)?,
        drive_ratio: [0.0; 2],
        total: [0.0; 2],
    }
    .with_total();
    let sf_selfcal_per_dps = std::array::from_fn(|k| sf_cal[k] * ratio.exact[k]);
    let sf_eq56_per_dps = std::array::from_fn(|k| sf_cal[k] * ratio.eq56[k]);
    Ok(SelfCal {
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
    })
}

/// The predicted ratio's relative 1-sigma uncertainty per output from the
/// identified parameters: each of f1, Q1, f2, Q2, the group delay and the
/// loop phase (as a residual error of the correction) moved by its
/// uncertainty (independent fits), the changes added in quadrature.
fn identified_uncertainty(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    cal_hz: &[f64],
    ratio: &Ratio,
) -> Result<[f64; 2], Error> {
    let gyro = id.gyro(&knowns.nominal);
    let [m1, m2] = &id.modes;
    let mut moved = vec![];
    for (i, sd) in [m1.f_hz, m1.q, m2.f_hz, m2.q]
        .map(|e| e.uncertainty)
        .into_iter()
        .enumerate()
    {
        let mut g = gyro.clone();
        *[&mut g.f1_hz, &mut g.q1, &mut g.f2_hz, &mut g.q2][i] += sd;
        moved.push(predicted_ratio(knowns, &g, op, cal_hz)?);
    }
    if id.group_delay_s.uncertainty.is_finite() {
        let mut o = op.clone();
        o.envelope_delay_s += id.group_delay_s.uncertainty;
        moved.push(predicted_ratio(knowns, &gyro, &o, cal_hz)?);
    }
    let lag = id.loop_phase_deg.uncertainty.to_radians();
    moved.push(predicted_ratio_lagged(knowns, &gyro, op, cal_hz, lag)?);
    Ok(std::array::from_fn(|k| {
        moved
            .iter()
            .map(|m| (m.exact[k] / ratio.exact[k] - 1.0).powi(2))
            .sum::<f64>()
            .sqrt()
    }))
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
    cal.sf_selfcal_uncertainty = cal.sf_selfcal_uncertainty.with_total();
    cal.sf_selfcal_per_dps = std::array::from_fn(|k| cal.sf_cal_per_dps[k] * ratio.exact[k]);
    cal.sf_eq56_per_dps = std::array::from_fn(|k| cal.sf_cal_per_dps[k] * ratio.eq56[k]);
    cal.ratio = ratio;
    cal.drive_ratio = Some(measured);
    Ok(())
}
