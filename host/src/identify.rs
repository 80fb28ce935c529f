//! Host-side identification of a drifting gyroscope through the gateware's
//! registers alone: f1, f2, Q1, Q2 and the loop (front-end) phase, each
//! with a 1-sigma uncertainty from the data.
//!
//! # What is measured
//!
//! In readout (SELECT = 0) with one drive on (AMP_k, the other 0), output k
//! is the mean of ADC_k times drive k's own word. At rest the modes are
//! uncoupled, so the ADC sees mode k's response to that word alone. With
//! REF_PHASE at its aligned value (carrier_step / 2, `settings`) the
//! mixer gives the in-phase part; with REF_PHASE advanced by a quarter
//! turn, the quadrature part. The complex response per drive LSB is
//!
//! ```text
//! Y(f) = 2 (z_I + j z_Q) / (dc_gain W^2) = C / ((fk - f)(fk + f) + j f bk),   C = G e^(-j phi)
//! ```
//!
//! with W the drive word's amplitude (known from AMP), dc_gain the filter's
//! (known from its settings), bk = fk / Qk the bandwidth (Hz), G > 0 the
//! product of drive gain, hold, pick-off and ADC gain (unknown, and not
//! needed), and phi the front end's unmodelled phase lag. This is the
//! exact steady state of the model (the DAC hold's delay is what
//! REF_PHASE's aligned value cancels; its sinc moves G by 1e-5 over a sweep).
//!
//! # How
//!
//! 1. Coarse search from the datasheet frequency: Y at three carriers
//!    around a centre, and the narrow-band form 1 / (Y f) = a + b (f - f0)
//!    (linear in two complex unknowns) gives fk, bk and the peak response
//!    even many bandwidths away; the centre moves there until it lands
//!    within a quarter bandwidth. The drive amplitude is set from the
//!    predicted peak so that the ADC stays below `ADC_TARGET` of full scale
//!    (a response above `ADC_CLIP` of full scale is measured again at a
//!    quarter of the amplitude). Mode 2's search starts at mode 1's
//!    identified frequency plus the datasheet's split.
//! 2. Fine sweep: `FINE_POINTS` carriers over +-`FINE_SPAN` bandwidths,
//!    up then down, so that any settling lag shows as a misfit instead of
//!    a shift. Each point waits `SETTLE_TAUS` amplitude time constants
//!    after a carrier step (the coarse search's bandwidth gives the time
//!    constant; the datasheet's until then, each with a 20% margin) and the
//!    filter's settling after a REF_PHASE step.
//! 3. Gauss-Newton fit of the exact form above (4 real unknowns: C, fk, bk)
//!    from the narrow-band solution. Uncertainties: the residual variance
//!    times the inverse normal matrix, propagated to Qk = fk / bk and
//!    phi = -arg C.
//!
//! The loop phase is read off the line through the two modes' phi at the
//! operating carrier (both references go through one REF_PHASE, so one
//! common correction is what the gateware can apply); the line's slope is
//! the front end's group delay, which the prediction needs: a front end
//! that lags the carrier by phi usually delays the envelope too (a pure
//! delay by phi / w, the pick-off model of `frontend::PickoffPhase` by
//! about sin(phi) cos(phi) / w), and in calibration that mixes the
//! resonant part of the response into the output (13% of the detuned
//! output of a 25 kHz device with 3 deg, measured).

use crate::board::Board;
use crate::device::GyroParams;
use crate::error::Error;
use crate::knowns::{FILTER_SETTLE, Knowns, TAU_MARGIN};
use crate::sampling::average_z;
use gyrocal_regs::datapath::{CONVERTER_FULL_SCALE, PEAK};
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

type C64 = Complex<f64>;

/// Amplitude time constants Qk / (pi fk) waited after a carrier step: the
/// transient falls to e^-12 = 6e-6 of the step in response.
pub const SETTLE_TAUS: f64 = 12.0;
/// Fraction of ADC full scale the identification drives the peak to.
pub const ADC_TARGET: f64 = 0.5;
/// Above this fraction of full scale a response may be clipped.
pub const ADC_CLIP: f64 = 0.8;
/// Carriers of the fine sweep (each measured going up and coming down).
pub const FINE_POINTS: usize = 5;
/// Half-width of the fine sweep in bandwidths bk.
pub const FINE_SPAN: f64 = 1.5;
/// z samples averaged for each of I and Q.
pub const SAMPLES_PER_PHASE: u64 = 128;
/// What the waits leave of a step in the response, relative to the peak
/// response: the resonator's e^-SETTLE_TAUS and the filter's
/// `FILTER_SETTLE`. It is a bias, not noise (the fit's residuals do not
/// see it when it repeats from point to point), and it moves the fitted
/// phase by at most this many radians, fk and bk by this times bk, and Q by
/// this fraction: each estimate's uncertainty includes it in quadrature
/// (a bound used as one sigma).
pub fn settling_residue() -> f64 {
    (-SETTLE_TAUS).exp() + FILTER_SETTLE
}
/// Most coarse-search moves before giving up.
const MAX_MOVES: usize = 12;

/// Fundamental amplitude (LSB) of a readout drive word for a Q1.15
/// amplitude (`gyrocal_regs::datapath::readout_word`), unsigned.
pub fn readout_word(amp: i16) -> f64 {
    gyrocal_regs::datapath::readout_word(amp).abs()
}

/// A value and its 1-sigma uncertainty.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// 1-sigma uncertainty.
    pub uncertainty: f64,
}

/// One mode's fitted response.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModeFit {
    /// Resonance frequency (Hz).
    pub f_hz: Estimate,
    /// Quality factor.
    pub q: Estimate,
    /// Loop phase lag seen through this mode (deg).
    pub phase_deg: Estimate,
    /// RMS residual over the peak response (relative misfit).
    pub relative_rms: f64,
    /// Sweep points (carrier Hz) and responses (ADC LSB per drive LSB).
    #[serde(skip)]
    pub sweep: Vec<(f64, C64)>,
}

/// The identified device.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Identified {
    /// Mode 1 and mode 2.
    pub modes: [ModeFit; 2],
    /// Loop phase lag at the operating carrier (deg): the line through
    /// the two modes' phases, evaluated there.
    pub loop_phase_deg: Estimate,
    /// Group delay of the loop (s): the slope of that line, d phi / d w.
    /// It delays the response's envelope against the references', which
    /// REF_PHASE (a carrier phase) cannot undo: the prediction carries it
    /// as an envelope lead (`selfcal::predicted_ratio`).
    pub group_delay_s: Estimate,
    /// Clocks the identification took.
    pub clocks: u64,
}

impl Identified {
    /// The identified mechanical parameters, lambda and the couplings from
    /// the datasheet.
    pub fn gyro(&self, nominal: &GyroParams) -> GyroParams {
        GyroParams {
            f1_hz: self.modes[0].f_hz.value,
            f2_hz: self.modes[1].f_hz.value,
            q1: self.modes[0].q.value,
            q2: self.modes[1].q.value,
            ..nominal.clone()
        }
    }
}

/// Measures mode k's complex response through one drive.
struct Prober<'a> {
    board: &'a mut dyn Board,
    knowns: &'a Knowns,
    k: usize,
    /// Drive amplitude in use (fraction of full scale).
    amplitude: f64,
    /// Amplitude time constant waited on (s): the datasheet's until the
    /// coarse search has measured the mode's bandwidth.
    tau_s: f64,
    clocks: u64,
}

impl Prober<'_> {
    /// Y at `carrier_hz` (ADC LSB per drive LSB): I, then Q a quarter turn
    /// later; returns the realized carrier.
    fn measure_once(&mut self, carrier_hz: f64) -> Result<(f64, C64, f64), Error> {
        let kn = self.knowns;
        let amps = if self.k == 0 {
            (self.amplitude, 0.0)
        } else {
            (0.0, self.amplitude)
        };
        let (regs, real) = kn.registers(carrier_hz, None, amps, 0.0)?;
        self.board.program(&regs)?;
        let r = kn.filter.decimation;
        let settle =
            (SETTLE_TAUS * self.tau_s * kn.clock_hz).ceil() as u64 + kn.filter_settle_clocks();
        let zi = average_z(self.board, settle, SAMPLES_PER_PHASE)?[self.k];
        let mut quarter = regs;
        quarter.ref_phase = regs.ref_phase.wrapping_add(1 << 30);
        self.board.program(&quarter)?;
        let filter = kn.filter_settle_clocks();
        let zq = average_z(self.board, filter, SAMPLES_PER_PHASE)?[self.k];
        self.clocks += settle + filter + 2 * SAMPLES_PER_PHASE * u64::from(r);
        let amp_word = [regs.amp.0, regs.amp.1][self.k];
        let w = readout_word(amp_word);
        let y = C64::new(zi, zq) * (2.0 / (real.filter.dc_gain * w * w));
        Ok((real.carrier_hz, y, y.norm() * w / CONVERTER_FULL_SCALE))
    }

    /// `measure_once`, again at a quarter of the amplitude while the ADC
    /// may clip.
    fn measure(&mut self, carrier_hz: f64) -> Result<(f64, C64), Error> {
        loop {
            let (f, y, full_scale) = self.measure_once(carrier_hz)?;
            if full_scale <= ADC_CLIP {
                return Ok((f, y));
            }
            self.amplitude /= 4.0;
            if self.amplitude * 32768.0 < 1.0 {
                return Err(Error::Identification {
                    mode: self.k + 1,
                    reason: "the response clips the ADC even at one DAC LSB".into(),
                });
            }
        }
    }

    /// Drive amplitude that puts a peak response `peak` (per drive LSB) at
    /// `ADC_TARGET` of full scale, at most the readout amplitude.
    fn set_amplitude_for_peak(&mut self, peak: f64) {
        let max = [self.knowns.amplitude.0, self.knowns.amplitude.1][self.k].abs();
        // Word amplitude ~ a x PEAK^2 / 2^15 per unit amplitude.
        let per_unit = f64::from(PEAK) * f64::from(PEAK) / 32768.0;
        let wanted = ADC_TARGET * CONVERTER_FULL_SCALE / (peak * per_unit);
        if wanted.is_finite() && wanted > 0.0 {
            self.amplitude = wanted.min(max);
        }
    }
}

/// The narrow-band solution: 1 / (Y f) = a + b (f - f0), so that
/// D = -b / 2, fk = f0 + Re(a / D) / 2, bk = Im(a / D), peak |Y| = 1 / (|D| fk bk).
/// Returns (fk, bk, peak) from two or more points.
fn narrow_band(points: &[(f64, C64)]) -> Option<(f64, f64, f64)> {
    let f0 = points.iter().map(|p| p.0).sum::<f64>() / points.len() as f64;
    // Complex least squares of v = a + b u.
    let n = points.len() as f64;
    let u: Vec<f64> = points.iter().map(|p| p.0 - f0).collect();
    let v: Vec<C64> = points.iter().map(|p| 1.0 / (p.1 * p.0)).collect();
    let mu = u.iter().sum::<f64>() / n;
    let mv = v.iter().sum::<C64>() / n;
    let suu: f64 = u.iter().map(|x| (x - mu) * (x - mu)).sum();
    if suu <= 0.0 {
        return None;
    }
    let suv: C64 = u.iter().zip(&v).map(|(x, y)| (y - mv) * (x - mu)).sum();
    let b = suv / suu;
    let a = mv - b * mu;
    let d = -b / 2.0;
    let r = a / d;
    let fk = f0 + r.re / 2.0;
    let bk = r.im;
    let peak = 1.0 / (d.norm() * fk * bk.abs());
    (fk.is_finite() && bk.is_finite() && bk > 0.0).then_some((fk, bk, peak))
}

/// Gauss-Newton fit of Y = C / ((fk - f)(fk + f) + j f bk) from a start
/// (fk, bk); returns the mode's estimates.
fn fit_mode(points: &[(f64, C64)], fk0: f64, bk0: f64) -> Result<ModeFit, &'static str> {
    let den = |fk: f64, bk: f64, f: f64| C64::new((fk - f) * (fk + f), f * bk);
    // Best C for given (fk, bk) is linear: C = sum(Y conj(1/den)) / sum |1/den|^2.
    let best_c = |fk: f64, bk: f64| {
        let (mut num, mut norm) = (C64::new(0.0, 0.0), 0.0);
        for &(f, y) in points {
            let g = 1.0 / den(fk, bk, f);
            num += y * g.conj();
            norm += g.norm_sqr();
        }
        num / norm
    };
    let mut p = {
        let c = best_c(fk0, bk0);
        [c.re, c.im, fk0, bk0]
    };
    let n = points.len();
    let jacobian = |p: &[f64; 4]| {
        let c = C64::new(p[0], p[1]);
        let mut j = DMatrix::<f64>::zeros(2 * n, 4);
        let mut r = DVector::<f64>::zeros(2 * n);
        for (i, &(f, y)) in points.iter().enumerate() {
            let d = den(p[2], p[3], f);
            let m = c / d;
            let res = y - m;
            r[2 * i] = res.re;
            r[2 * i + 1] = res.im;
            let cols = [
                1.0 / d,
                C64::new(0.0, 1.0) / d,
                -c * 2.0 * p[2] / (d * d),
                -c * C64::new(0.0, f) / (d * d),
            ];
            for (col, v) in cols.iter().enumerate() {
                j[(2 * i, col)] = v.re;
                j[(2 * i + 1, col)] = v.im;
            }
        }
        (j, r)
    };
    let scaled_solve =
        |j: &DMatrix<f64>, r: &DVector<f64>| -> Option<(DVector<f64>, DMatrix<f64>)> {
            let scale: Vec<f64> = (0..4).map(|c| j.column(c).norm()).collect();
            let mut js = j.clone();
            for (c, s) in scale.iter().enumerate() {
                js.column_mut(c).scale_mut(1.0 / s);
            }
            let normal = js.transpose() * &js;
            let inv = normal.try_inverse()?;
            let step = &inv * js.transpose() * r;
            let mut cov = inv;
            for a in 0..4 {
                for b in 0..4 {
                    cov[(a, b)] /= scale[a] * scale[b];
                }
            }
            Some((step.component_div(&DVector::from_vec(scale)), cov))
        };
    let mut cov = DMatrix::<f64>::zeros(4, 4);
    let mut rss = 0.0;
    for _ in 0..30 {
        let (j, r) = jacobian(&p);
        let (step, c) = scaled_solve(&j, &r).ok_or("singular fit")?;
        for (v, s) in p.iter_mut().zip(step.iter()) {
            *v += s;
        }
        cov = c;
        rss = r.norm_squared();
        if step[2].abs() < 1e-9 * p[3] && step[3].abs() < 1e-9 * p[3] {
            break;
        }
    }
    let (j, r) = jacobian(&p);
    if let Some((_, c)) = scaled_solve(&j, &r) {
        cov = c;
        rss = r.norm_squared();
    }
    let dof = (2 * n).saturating_sub(4).max(1) as f64;
    let s2 = rss / dof;
    let sd = |a: usize| (s2 * cov[(a, a)]).sqrt();
    let (fk, bk) = (p[2], p[3]);
    if !(fk.is_finite() && bk.is_finite() && bk > 0.0) {
        return Err("the fit diverged (no finite, positive bandwidth)");
    }
    let q = fk / bk;
    let q_sd = q * ((sd(3) / bk).powi(2) + (sd(2) / fk).powi(2)).sqrt();
    let c = C64::new(p[0], p[1]);
    // phi = -arg C; d arg / d (Cr, Ci) = (-Ci, Cr) / |C|^2.
    let g = [-p[1] / c.norm_sqr(), p[0] / c.norm_sqr()];
    let var_phi = s2
        * (g[0] * g[0] * cov[(0, 0)] + 2.0 * g[0] * g[1] * cov[(0, 1)] + g[1] * g[1] * cov[(1, 1)]);
    let peak = c.norm() / (fk * bk);
    Ok(ModeFit {
        f_hz: Estimate {
            value: fk,
            uncertainty: sd(2),
        },
        q: Estimate {
            value: q,
            uncertainty: q_sd,
        },
        phase_deg: Estimate {
            value: -c.arg().to_degrees(),
            uncertainty: var_phi.sqrt().to_degrees(),
        },
        relative_rms: (rss / n as f64).sqrt() / peak,
        sweep: points.to_vec(),
    })
}

/// Identify mode k starting from `guess_hz`.
pub fn identify_mode(
    board: &mut dyn Board,
    knowns: &Knowns,
    k: usize,
    guess_hz: f64,
) -> Result<(ModeFit, u64), Error> {
    let max = [knowns.amplitude.0, knowns.amplitude.1][k].abs();
    let mut probe = Prober {
        board,
        knowns,
        k,
        amplitude: max / 8.0,
        tau_s: knowns.tau_s(k),
        clocks: 0,
    };
    let bw = knowns.bandwidth_hz(k);
    let mut centre = guess_hz;
    let mut found = None;
    for _ in 0..MAX_MOVES {
        let pts: Vec<(f64, C64)> = [-1.0, 0.0, 1.0]
            .iter()
            .map(|s| probe.measure(centre + s * bw))
            .collect::<Result<_, _>>()?;
        let Some((fk, bk, peak)) = narrow_band(&pts) else {
            return Err(Error::Identification {
                mode: k + 1,
                reason: format!("no resonance seen near {centre} Hz"),
            });
        };
        probe.set_amplitude_for_peak(peak);
        let moved = fk - centre;
        centre = fk;
        if moved.abs() < bw / 4.0 {
            found = Some(bk);
            break;
        }
    }
    let bk = found.ok_or_else(|| Error::Identification {
        mode: k + 1,
        reason: format!("the coarse search did not settle within {MAX_MOVES} moves"),
    })?;
    // The mode's own time constant 1 / (pi bk), with the datasheet's 20%
    // margin for the narrow-band estimate of bk.
    probe.tau_s = TAU_MARGIN / (PI * bk);
    let offsets: Vec<f64> = (0..FINE_POINTS)
        .map(|i| FINE_SPAN * (2.0 * i as f64 / (FINE_POINTS - 1) as f64 - 1.0))
        .collect();
    let order = offsets.iter().chain(offsets.iter().rev());
    let mut sweep = vec![];
    for s in order {
        sweep.push(probe.measure(centre + s * bk)?);
    }
    let mut fit = fit_mode(&sweep, centre, bk).map_err(|reason| Error::Identification {
        mode: k + 1,
        reason: reason.into(),
    })?;
    let eps = settling_residue();
    let floor = |e: &mut Estimate, bias: f64| e.uncertainty = e.uncertainty.hypot(bias);
    let bk = fit.f_hz.value / fit.q.value;
    floor(&mut fit.f_hz, eps * bk);
    let q = fit.q.value;
    floor(&mut fit.q, eps * q);
    floor(&mut fit.phase_deg, eps.to_degrees());
    Ok((fit, probe.clocks))
}

/// Identify both modes, starting from `guess` (the datasheet or the last
/// identification).
pub fn identify(
    board: &mut dyn Board,
    knowns: &Knowns,
    guess: &GyroParams,
) -> Result<Identified, Error> {
    let (m1, c1) = identify_mode(board, knowns, 0, guess.f1_hz)?;
    // Mode 2 from mode 1 plus the guess's split, scaled with mode 1's
    // move: the common drift (hundreds of Hz per K) is gone, what is left is
    // the split's drift (a few Hz per K), within the coarse search's first
    // look.
    let guess_f2 = m1.f_hz.value + (guess.f2_hz - guess.f1_hz) * (m1.f_hz.value / guess.f1_hz);
    let (m2, c2) = identify_mode(board, knowns, 1, guess_f2)?;
    let carrier = m1.f_hz.value + knowns.carrier_offset_hz;
    let (f1, f2) = (m1.f_hz.value, m2.f_hz.value);
    let (p1, p2) = (m1.phase_deg, m2.phase_deg);
    // Modes closer than a tenth of a bandwidth: one frequency, one phase;
    // the delay is not observable (and its envelope lead then negligible).
    let resolvable = (f2 - f1).abs() > 0.1 * (f1 / m1.q.value).max(f2 / m2.q.value);
    let w2 = if resolvable {
        (carrier - f1) / (f2 - f1)
    } else {
        0.5
    };
    let loop_phase_deg = Estimate {
        value: p1.value + w2 * (p2.value - p1.value),
        uncertainty: ((1.0 - w2) * p1.uncertainty).hypot(w2 * p2.uncertainty),
    };
    let per_hz = 1.0f64.to_radians() / (TAU * (f2 - f1));
    let group_delay_s = if resolvable {
        Estimate {
            value: (p2.value - p1.value) * per_hz,
            uncertainty: p1.uncertainty.hypot(p2.uncertainty) * per_hz.abs(),
        }
    } else {
        Estimate {
            value: 0.0,
            uncertainty: f64::INFINITY,
        }
    };
    Ok(Identified {
        modes: [m1, m2],
        loop_phase_deg,
        group_delay_s,
        clocks: c1 + c2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn narrow_band_and_the_fit_recover_a_lorentzian() {
        let (fk, bk, phi) = (9.64e6 + 123.0, 175.3f64, 3.0f64.to_radians());
        let c = C64::from_polar(2.0e9, -phi);
        let y = |f: f64| c / C64::new((fk - f) * (fk + f), f * bk);
        let far: Vec<(f64, C64)> = [-1.0, 0.0, 1.0]
            .iter()
            .map(|s| (9.64e6 - 2000.0 + s * 175.0, y(9.64e6 - 2000.0 + s * 175.0)))
            .collect();
        let (f_est, b_est, _) = narrow_band(&far).unwrap();
        assert!((f_est - fk).abs() < 1.0, "{f_est}");
        assert!((b_est / bk - 1.0).abs() < 0.01, "{b_est}");
        let near: Vec<(f64, C64)> = (0..9)
            .map(|i| fk + 30.0 + bk * (i as f64 / 4.0 - 1.0))
            .map(|f| (f, y(f)))
            .collect();
        let m = fit_mode(&near, fk + 30.0, 150.0).unwrap();
        assert!((m.f_hz.value - fk).abs() < 1e-6, "{:?}", m.f_hz);
        assert!((m.q.value / (fk / bk) - 1.0).abs() < 1e-9);
        assert!((m.phase_deg.value - 3.0).abs() < 1e-9, "{:?}", m.phase_deg);
    }
}
