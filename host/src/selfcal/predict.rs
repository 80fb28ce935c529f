//! The prediction: the readout over calibration ratio in z LSB from the
//! exact theory at the identified device and the operating point, and
//! each ADC's predicted peak there (for the drive amplitudes).

use super::Operating;
use crate::device::GyroParams;
use crate::error::Error;
use crate::identify::{Identified, readout_word};
use crate::images;
use crate::knowns::Knowns;
use crate::stats::linear_fit;
use crate::theory::{self, Device, envelope_lead_rad, hold_gain};
use gyrocal_regs::datapath::{CONVERTER_FULL_SCALE, calibration_word};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// Readout and calibration ratio predictions per output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ratio {
    /// Exact theory, fitted at the measurement points (z LSB units).
    pub exact: [f64; 2],
    /// Eqs. (5)/(6), small signal (z LSB units).
    pub eq56: [f64; 2],
}

/// The theory's device at `op` in readout and in calibration: the drive
/// words' realized amplitudes as forces (design force per LSB).
pub(super) fn devices(
    knowns: &Knowns,
    gyro: &GyroParams,
    op: &Operating,
) -> Result<[Device; 2], Error> {
    let (regs, _) = knowns.registers(op.carrier_hz, None, op.amplitude, 0.0)?;
    let amp = [regs.amp.0, regs.amp.1];
    let per_lsb = knowns.force_full_scale.map(|f| f / 32768.0);
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
    Ok([
        device(amp.map(|a| readout_word(knowns.carrier_profile, a))),
        device(amp.map(|a| calibration_word(knowns.carrier_profile, a).abs())),
    ])
}

/// The readout scale factors at `op`: the exact theory's small-signal
/// slope (`theory::sf_read_per_rad_s`) at the identified device,
/// (m^2/s^2) / (rad/s) per output.
pub fn readout_sf(knowns: &Knowns, id: &Identified, op: &Operating) -> Result<[f64; 2], Error> {
    let [read, _] = devices(knowns, &id.gyro(&knowns.nominal), op)?;
    Ok(theory::sf_read_per_rad_s(&read))
}

/// Each ADC's predicted peak over the cycle's readout rates and
/// calibration frequencies at `op`, as a fraction of full scale.
///
/// The identified mode k answers its own drive with Y = C_k / D_k(f) (ADC
/// LSB per drive LSB, D in Hz^2), while the theory gives displacements x_k
/// = F_k / (4 pi^2 D_k) for a force F_k = g_k W: so ADC k's gain is
/// a_k = 4 pi^2 |C_k| / g_k (LSB per metre), with g_k the design force per
/// DAC LSB. The peaks are a_k times the theory's peak displacements
/// (`theory::readout_peak_displacement`, `calibration_peak_displacement`),
/// which include the Coriolis and coupling cross terms.
pub fn adc_peaks(knowns: &Knowns, id: &Identified, op: &Operating) -> Result<[f64; 2], Error> {
    let gyro = id.gyro(&knowns.nominal);
    let [read, cal] = devices(knowns, &gyro, op)?;
    let per_lsb = knowns.force_full_scale.map(|f| f / 32768.0);
    let gain: [f64; 2] = std::array::from_fn(|k| 4.0 * PI * PI * id.modes[k].gain_hz2 / per_lsb[k]);
    let mut peak = [0.0f64; 2];
    let rates = knowns
        .rates_dps
        .iter()
        .map(|r| theory::readout_peak_displacement(&read, r.to_radians()));
    let cals = knowns
        .cal_freqs_hz
        .iter()
        .map(|&f| theory::calibration_peak_turning(&cal, f, op.cycle_rate_dps.to_radians()));
    for x in rates.chain(cals) {
        for k in 0..2 {
            peak[k] = peak[k].max(gain[k] * x[k] / CONVERTER_FULL_SCALE);
        }
    }
    Ok(peak)
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
    predicted_ratio_lagged(knowns, gyro, op, cal_hz, 0.0, None)
}

/// [`predicted_ratio`] with a residual loop phase error `lag_rad` left by
/// the correction (the responses lag their references by that much more),
/// and the front end in the first-order form with the gain slope
/// `linear_gain_per_hz` when given (`images::ImageFront`) instead of the
/// group delay's turn: at the images, and across the calibration's
/// sidebands. There a slope a scales the sidebands at wb -+ Om by
/// 1 -+ a f_cal, which turns the resonant part of each response, symmetric
/// in the sidebands and far larger than the calibration signal
/// (`theory::calibration_z_with_envelope_lead`), into signal: a relative
/// change of the calibration scale factor proportional to a and
/// independent of f_cal (the signal grows with f_cal as the asymmetry
/// does). A pick-off lag of 8 deg (a = sin(phi)^2 / f) moved seed 2096's
/// output 1 by -1.2e-3 at calibration frequencies 1.3 to 16 Hz alike
/// (`tests/field_coverage.rs`).
pub(super) fn predicted_ratio_lagged(
    knowns: &Knowns,
    gyro: &GyroParams,
    op: &Operating,
    cal_hz: &[f64],
    lag_rad: f64,
    linear_gain_per_hz: Option<f64>,
) -> Result<Ratio, Error> {
    let front = images::ImageFront {
        delay_s: op.envelope_delay_s,
        gain_per_hz: linear_gain_per_hz.unwrap_or(0.0),
        linear: linear_gain_per_hz.is_some(),
    };
    let clock = knowns.clock_hz;
    let per_lsb = knowns.force_full_scale.map(|f| f / 32768.0);
    let [dev_read, dev_cal] = devices(knowns, gyro, op)?;
    let rad = PI / 180.0;
    let rates = &knowns.rates_dps;
    // The sampled loop: the carrier's phasor and the DAC's images that the
    // ADC aliases onto it (`images`, through the front end's delay; the
    // images without the residual lag, a second-order change of a small
    // term).
    let add = |a: [f64; 2], b: [f64; 2]| [a[0] + b[0], a[1] + b[1]];
    let read_z: Vec<[f64; 2]> = rates
        .iter()
        .map(|r| {
            add(
                theory::readout_z_lagged(&dev_read, r * rad, lag_rad),
                images::readout_images(&dev_read, clock, r * rad, front),
            )
        })
        .collect();
    let hold = hold_gain(op.carrier_hz, clock);
    let cal_z: Vec<[f64; 2]> = cal_hz
        .iter()
        .map(|&f| {
            let sidebands = [-1.0, 1.0]
                .map(|s| hold_gain(op.carrier_hz + s * f, clock) / hold * front.gain(s * f));
            // The response's envelope comes late by the group delay: the
            // references' envelope leads it by that much more.
            let lead = envelope_lead_rad(f, clock) + TAU * f * op.envelope_delay_s;
            let turning = op.cycle_rate_dps * rad;
            add(
                theory::calibration_z_turning(&dev_cal, f, lead, sidebands, lag_rad, turning),
                images::calibration_images(&dev_cal, clock, f, lead, sidebands, front, turning),
            )
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
