//! Host-side measurement of the drive-gain ratio g2 / g1 while the device
//! turns: the one converter drift the cycle at rest cannot see
//! (`selfcal` module header), observed through the Coriolis cross
//! responses, with nothing but register writes and z reads.
//!
//! # Why it needs a rotation, and why the rate cancels
//!
//! With H_jk the response at ADC j to drive k, H_jk = a_j g_k M_jk, where
//! a_j is ADC j's gain, g_k drive k's force per DAC LSB and M the coupled
//! resonators' response. The gyroscope's phasor equations at the carrier
//! w are, with G_k = 1 / (w_k^2 - w^2 + j w b_k) and c = j w 2 lambda Omega,
//!
//! ```text
//! [ 1/G_1   -c  ] [X_1]   [F_1]                   1   [ 1/G_2   c  ]
//! [   c   1/G_2 ] [X_2] = [F_2],   so  M = ------ [             ]
//!                                           det   [  -c   1/G_1 ]
//! ```
//!
//! exactly, at any rate: M_12 / M_21 = -1 and M_22 / M_11 = G_2 / G_1. So
//!
//! ```text
//! (H_12 H_22) / (H_21 H_11) = (g_2 / g_1)^2 (M_12 M_22) / (M_21 M_11) = -(g_2 / g_1)^2 G_2 / G_1
//! ```
//!
//! The ADC gains, the rate (unknown to the host) and any phase common to
//! both pick-offs cancel; G_2 / G_1 comes from the identified f_k and Q_k.
//! At rest H_12 = H_21 = 0 and the ratio is 0 / 0: the device must turn
//! (the cross responses grow with the rate), at any steady rate.
//!
//! # How the gateware exposes the four responses
//!
//! In readout, output j is the mean of ADC_j times drive j's own word, and
//! the reference word of drive j carries drive j's amplitude: with one
//! drive off, the other output reads zero. So both drives stay on, and
//! drive 2's amplitude word is negated for a second measurement: with W_k
//! the drive words' signed amplitudes (drive 2's word is a sine, a phasor
//! -j W_2), I and Q through REF_PHASE (as `identify` measures them),
//!
//! ```text
//! Z_1(W_2)       = kappa_1 W_1 a_1 (g_1 M_11 W_1 - j g_2 M_12 W_2)  = P_1 + Q_1 W_2
//! Z_2(W_2) / W_2 = kappa_2     a_2 (g_1 M_21 W_1 - j g_2 M_22 W_2)  = P_2 + Q_2 W_2
//! ```
//!
//! two lines in W_2 from its two signed values (the rounded words, which
//! differ from exact negatives by at most one LSB of the envelope), whence
//!
//! ```text
//! (g_2 / g_1)^2 = Q_1 Q_2 W_1^2 / (P_1 P_2) x G_1 / G_2
//! ```
//!
//! (kappa_j, the output's reference phase and filter gain, cancels within
//! each output). |g_2 / g_1| is the estimate; the phase of the right-hand
//! side, zero for drives that differ in gain only, is reported as a check.
//!
//! # Drive 1 at a fraction
//!
//! On a device excited at mode 1, output 1's cross term Q_1 W_2 is some
//! 6e-4 of its direct term P_1 at 200 deg/s (the consumer device), and
//! anything that moves with the direct term between the windows moves
//! Q_1: the carrier table's spurs beat with the resonant response at some
//! 1e-7 of it (`scenario::rate_table`), and the filter's residue after a
//! REF_PHASE step is 1e-6 of the step. Measured on the consumer device
//! without ADC noise at drive 1's full readout amplitude, the ratio came
//! out 2.7e-4 low (-17 sigma); with three times the waits, 1.7e-4 high:
//! a beat, not a transient. Drive 1 runs at `DRIVE1_FRACTION` of its
//! amplitude instead: output 1's direct term and everything that scales
//! with it shrink by that much, while its cross term keeps its size against
//! output 1's noise (drive 1's word is also output 1's reference, so signal
//! and noise scale alike); output 2's cross term (drive 1 at ADC 2) loses
//! the factor against output 2's noise, which the 0.1 cross over direct
//! ratio of that output affords. Measured, same device: 1.3e-5 +- 0.4e-5
//! without noise; with the 1 LSB ADC noise at 1/8 and 1/16, every step
//! within 0.5 sigma.
//!
//! # Uncertainty
//!
//! Each of the four windows is cut into `BATCHES` consecutive batches; the
//! estimate is formed from each batch index alone and the spread of those
//! `BATCHES` estimates gives the noise's standard error, times the
//! coverage factor of its `BATCHES - 1` degrees of freedom. The identified
//! parameters' uncertainties enter through G_1 / G_2 (propagated by finite
//! differences). A rate that drifts between the two signs cancels to first
//! order (each of Q_1 and P_2 is the mean over both). A quadrature
//! (stiffness) coupling breaks M_12 = -M_21 but not the magnitude of the
//! estimate (`from_windows`); it makes the ratio observable at rest,
//! where the cycle measures it ([`crate::coupling`]).

use crate::board::Board;
use crate::coupling::{TurningLine, spur_sigma};
use crate::error::Error;
use crate::identify::{self, CouplingFigure, Estimate, Identified};
use crate::knowns::Knowns;
use crate::sampling::average_z;
use crate::selfcal::Operating;
use crate::stats::{coverage_factor, mean_and_standard_error};
use gyrocal_regs::datapath::readout_word as signed_readout_word;
use nalgebra::Complex;
use serde::Serialize;

type C64 = Complex<f64>;

/// Batches per window: the standard error's degrees of freedom + 1.
pub const BATCHES: usize = 8;

/// Drive 1's amplitude during the measurement, as a fraction of its
/// readout amplitude (module header, "Drive 1 at a fraction").
pub const DRIVE1_FRACTION: f64 = 0.125;

/// The measured drive-gain ratio.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DriveRatio {
    /// |g_2 / g_1| over the design ratio (`Knowns::force_full_scale`).
    pub relative: Estimate,
    /// Half the phase of the measured (g_2 / g_1)^2 (deg): zero when the
    /// drives differ in gain only and the modes are coupled by the
    /// rotation alone; +-90 at rest with a quadrature coupling
    /// (`from_windows` says why).
    pub phase_deg: Estimate,
    /// |H_21 / H_22|: the cross response over the direct one on output 2,
    /// which sets the precision (it grows with the rate).
    pub cross_over_direct: f64,
    /// Clocks the measurement took.
    pub clocks: u64,
}

/// G_k(f) up to a common factor: 1 / ((f_k - f)(f_k + f) + j f b_k).
pub(crate) fn resonator(f_k: f64, q_k: f64, f: f64) -> C64 {
    1.0 / C64::new((f_k - f) * (f_k + f), f * f_k / q_k)
}

/// What output `k`'s windows see of the coupled modes at `carrier_hz`,
/// each DAC image folded onto the carrier (`crate::images`; the module
/// header of `crate::coupling`, "Images"), weighted by the front end that
/// output's mode was fitted through (`ModeFit::front_at`): the direct
/// response S_kk and the cross response per unit of each coupling term,
/// to first order in kappa(v) = K + j v D (K in Hz^2, D in Hz):
/// M_cross / M_direct = -(K `stiffness` + D `damping`) / `direct`.
/// Without images (j = 0 alone) these are G_k, G_1 G_2 and j f G_1 G_2.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Folded {
    /// S_kk.
    pub direct: C64,
    /// Per unit K.
    pub stiffness: C64,
    /// Per unit D (and, turning, per unit of the Coriolis term 2 lambda
    /// Omega, which also grows as j v).
    pub damping: C64,
}

impl Folded {
    /// Output `k`'s sums for the modes of `id`.
    pub fn of(id: &Identified, k: usize, carrier_hz: f64, clock_hz: f64) -> Self {
        let [m1, m2] = &id.modes;
        let mode = &id.modes[k];
        let modes = [(m1.f_hz.value, m1.q.value), (m2.f_hz.value, m2.q.value)];
        Self::sum(modes, k, carrier_hz, clock_hz, |v| mode.front_at(v))
    }

    /// Output `k`'s sums for modes `(f_k, Q_k)` behind a front end whose
    /// response at v is `front(v)`.
    pub fn sum(
        modes: [(f64, f64); 2],
        k: usize,
        carrier_hz: f64,
        clock_hz: f64,
        front: impl Fn(f64) -> C64,
    ) -> Self {
        let g = |i: usize, v: f64| resonator(modes[i].0, modes[i].1, v);
        let zero = C64::new(0.0, 0.0);
        let mut sum = Self {
            direct: zero,
            stiffness: zero,
            damping: zero,
        };
        for j in -identify::IMAGES..=identify::IMAGES {
            let v = carrier_hz + f64::from(j) * clock_hz;
            let weight = front(v) * (carrier_hz / v);
            let cross = g(0, v) * g(1, v);
            sum.direct += weight * g(k, v);
            sum.stiffness += weight * cross;
            sum.damping += weight * C64::new(0.0, v) * cross;
        }
        sum
    }

    /// The phasor theory's sums (the carrier alone) for resonators `g`
    /// at `f`.
    #[cfg(test)]
    pub fn phasor(g: [C64; 2], k: usize, f: f64) -> Self {
        let cross = g[0] * g[1];
        Self {
            direct: g[k],
            stiffness: cross,
            damping: C64::new(0.0, f) * cross,
        }
    }
}

/// The line y = P + Q W_2 through `y` measured at drive 2's two signed
/// words `w2`: (P, Q).
pub(crate) fn line(y: [C64; 2], w2: [f64; 2]) -> (C64, C64) {
    let q = (y[0] - y[1]) / (w2[0] - w2[1]);
    (y[0] - q * w2[0], q)
}

/// (g_2 / g_1)^2 from the two outputs' lines in W_2 (Z_1 = P_1 + Q_1
/// W_2, Z_2 / W_2 = P_2 + Q_2 W_2), drive 1's word and G_1 / G_2.
fn ratio_squared(p1: C64, q1: C64, p2: C64, q2: C64, w1: f64, g1_over_g2: C64) -> C64 {
    q1 * q2 * w1 * w1 / (p1 * p2) * g1_over_g2
}

/// The relative 1-sigma of a positive `size` of the identified modes'
/// (f_1, Q_1, f_2, Q_2), each moved by its uncertainty (finite
/// differences, independent fits, in quadrature).
pub(crate) fn propagated(id: &Identified, size: impl Fn([f64; 4]) -> f64) -> f64 {
    let [m1, m2] = &id.modes;
    let p = [m1.f_hz, m1.q, m2.f_hz, m2.q];
    let values = p.map(|e| e.value);
    let centre = size(values);
    (0..4)
        .map(|i| {
            let mut moved = values;
            let h = 1e-3 * p[i].uncertainty.max(1e-9 * p[i].value.abs());
            moved[i] += h;
            let slope = (size(moved) / centre).ln() / h;
            (slope * p[i].uncertainty).powi(2)
        })
        .sum::<f64>()
        .sqrt()
}

/// The relative 1-sigma uncertainty of |G_1 / G_2| at the carrier from
/// the identified modes ([`propagated`]).
fn resonator_ratio_error(id: &Identified, carrier_hz: f64) -> f64 {
    let ratio = |v: [f64; 4]| resonator(v[0], v[1], carrier_hz) / resonator(v[2], v[3], carrier_hz);
    propagated(id, |v| ratio(v).norm())
}

/// What takes G_1 / G_2's place in [`ratio_squared`] in the sampled
/// loop: (S_11 / S_22) (X_2 / X_1), the direct responses and the cross
/// responses (each output's `Folded::damping`, the form of the Coriolis
/// and damping terms, which grow as j v) with the DAC's images folded in.
/// Without images it is G_1 / G_2 (the outputs' front ends cancel).
/// Images matter on a detuned output at a few clocks per carrier: on a
/// Q 270 / 410 device 12.6 bandwidths split at 2.64 clocks per carrier,
/// mode 2's direct response at the carrier carries 3% of images.
fn folded_ratio(id: &Identified, carrier_hz: f64, clock_hz: f64) -> C64 {
    let s = [0, 1].map(|k| Folded::of(id, k, carrier_hz, clock_hz));
    s[0].direct / s[1].direct * (s[1].damping / s[0].damping)
}

/// Mean and standard error of `v`, times the coverage factor of its
/// `v.len() - 1` degrees of freedom (1.51 for the `BATCHES` = 8 batches):
/// a standard error from 7 degrees of freedom leaves 2% of Student t
/// beyond 3 of its sigmas, not 0.27%.
pub(crate) fn mean_and_error(v: &[f64]) -> Estimate {
    let (value, se) = mean_and_standard_error(v);
    let dof = u32::try_from(v.len() - 1).unwrap_or(u32::MAX);
    Estimate {
        value,
        uncertainty: se * coverage_factor(dof),
    }
}

/// `BATCHES` batch means of both outputs, `per_batch` z samples each,
/// after waiting `settle` clocks.
fn batch_means(board: &mut dyn Board, settle: u64, per_batch: u64) -> Result<Vec<[f64; 2]>, Error> {
    board.wait_clocks(settle)?;
    (0..BATCHES)
        .map(|_| average_z(board, 0, per_batch))
        .collect()
}

/// The four responses' windows (module header, "How the gateware exposes
/// the four responses"): both drives at the readout amplitudes (drive 1 at
/// `DRIVE1_FRACTION`), drive 2 at its two signs, I and Q of each; every
/// window `min_window_s` long, cut into `BATCHES` batches.
#[derive(Clone)]
pub(crate) struct CrossWindows {
    /// Batch means, `means[sign][quadrature][batch][output]`.
    means: Vec<Vec<Vec<[f64; 2]>>>,
    /// Drive 1's signed readout word.
    pub w1: f64,
    /// Drive 2's signed readout words at its two signs.
    pub words: [f64; 2],
    /// Clocks the windows took.
    pub clocks: u64,
    /// Each window's length (s).
    pub window_s: f64,
    /// Each window's centre from the first write (s),
    /// `times_s[sign][quadrature]`.
    pub times_s: [[f64; 2]; 2],
}

impl CrossWindows {
    /// Measure the windows at the operating point `op`.
    pub fn measure(board: &mut dyn Board, knowns: &Knowns, op: &Operating) -> Result<Self, Error> {
        let r = knowns.filter.decimation;
        let window = knowns.window_samples();
        let per_batch = window.div_ceil(BATCHES as u64).max(1);
        let settle = knowns.settle_clocks(identify::SETTLE_TAUS);
        let filter = knowns.filter_settle_clocks();
        let mut means = vec![];
        let mut words = [0.0; 2];
        let mut w1 = 0.0;
        let mut clocks = 0;
        let window_clocks = BATCHES as u64 * per_batch * u64::from(r);
        let mut times_s = [[0.0; 2]; 2];
        for (s, sign) in [1.0, -1.0].into_iter().enumerate() {
            let amps = (DRIVE1_FRACTION * op.amplitude.0, sign * op.amplitude.1);
            let (regs, _) = knowns.registers(op.carrier_hz, None, amps, op.ref_lag_deg)?;
            w1 = signed_readout_word(knowns.carrier_profile, regs.amp.0);
            words[s] = signed_readout_word(knowns.carrier_profile, regs.amp.1);
            let mut pair = vec![];
            for (q, quarter) in [0u32, 1 << 30].into_iter().enumerate() {
                let mut rotated = regs;
                rotated.ref_phase = regs.ref_phase.wrapping_add(quarter);
                board.program(&rotated)?;
                let wait = if quarter == 0 { settle } else { filter };
                pair.push(batch_means(board, wait, per_batch)?);
                times_s[s][q] = (clocks + wait) as f64 + window_clocks as f64 / 2.0;
                times_s[s][q] /= knowns.clock_hz;
                clocks += wait + window_clocks;
            }
            means.push(pair);
        }
        if words[0] == words[1] || w1 == 0.0 {
            return Err(Error::Measurement {
                what: "cross responses",
                reason: "both drive amplitudes must be non-zero".into(),
            });
        }
        Ok(Self {
            means,
            w1,
            words,
            clocks,
            window_s: window_clocks as f64 / knowns.clock_hz,
            times_s,
        })
    }

    /// Output k's complex mean at drive 2's sign s, batch b (`None`: all).
    fn z(&self, s: usize, k: usize, b: Option<usize>) -> C64 {
        let part = |q: usize| match b {
            Some(b) => self.means[s][q][b][k],
            None => self.means[s][q].iter().map(|m| m[k]).sum::<f64>(),
        };
        C64::new(part(0), part(1))
    }

    /// Windows whose every batch reads `z[s][k]` (output k at drive 2's
    /// sign s, in-phase and quadrature as the real and imaginary part).
    #[cfg(test)]
    pub fn constant(z: [[C64; 2]; 2], w1: f64, words: [f64; 2], times_s: [[f64; 2]; 2]) -> Self {
        let means = z
            .iter()
            .map(|zs| {
                [0, 1]
                    .map(|q| vec![zs.map(|v| if q == 0 { v.re } else { v.im }); BATCHES])
                    .to_vec()
            })
            .collect();
        Self {
            means,
            w1,
            words,
            clocks: 0,
            window_s: 0.0,
            times_s,
        }
    }

    /// Output k's complex mean at drive 2's sign s (its in-phase and
    /// quadrature windows), all batches.
    pub fn mean(&self, s: usize, k: usize) -> C64 {
        self.z(s, k, None) / BATCHES as f64
    }

    /// The same windows with `delta` added to output k's every batch mean
    /// at drive 2's sign s, in-phase (q = 0) or quadrature (q = 1).
    pub fn shifted(&self, s: usize, q: usize, k: usize, delta: f64) -> Self {
        let mut moved = self.clone();
        for batch in &mut moved.means[s][q] {
            batch[k] += delta;
        }
        moved
    }

    /// Both outputs' lines in W_2 of batch `b` (`None`: the sums):
    /// ((P_1, Q_1), (P_2, Q_2)), Z_1 = P_1 + Q_1 W_2 and Z_2 / W_2 = P_2 +
    /// Q_2 W_2.
    pub fn lines(&self, b: Option<usize>) -> ((C64, C64), (C64, C64)) {
        let w2 = self.words;
        (
            line([self.z(0, 0, b), self.z(1, 0, b)], w2),
            line([self.z(0, 1, b) / w2[0], self.z(1, 1, b) / w2[1]], w2),
        )
    }
}

/// Measure g_2 / g_1 on a board that turns at a steady (unknown) rate,
/// at the operating point `op` of identification `id` (the four
/// responses of the module header, "How the gateware exposes the four
/// responses").
///
/// The estimate's magnitude moves with the rate where the device has a
/// damping coupling (`turning_factor`), so the rate is read from the
/// same windows (`coupling::from_windows`, at the design ratio) and
/// read again at each round's ratio (`selfcal::at_rest`'s C = a h + b
/// m), round after round until the ratio settles. Without it the factor
/// was the one of the cycle's rate, 0: on random devices
/// (`scripts/coverage/drive_probe.py 601 40`: 10 to 150 kHz, Q 800 to
/// 10,000, probed at 20 to 300 deg/s) every one with a damping coupling
/// of 0.3 deg/s or more read g2/g1 39 to 517 of its sigmas off (a 4.4
/// deg/s coupling probed at -24.5 deg/s: 1.2001 for 1), and its scale
/// factors up to 290.
///
/// Near the damping coupling's own rate, or below it, the rounds swing
/// without end (`settled`) or settle on the identity's second root,
/// where the rate read at that ratio is 0 and no turning is taken out
/// (r^2 = (m - h) / (m + h) with no stiffness coupling): each is an error
/// in one line, never a figure.
pub fn measure(
    board: &mut dyn Board,
    knowns: &Knowns,
    op: &Operating,
    id: &Identified,
) -> Result<DriveRatio, Error> {
    let windows = CrossWindows::measure(board, knowns, op)?;
    let lines = crate::coupling::spur_lines(&windows, knowns, op, id)?;
    let lines = lines.as_deref();
    let read = crate::coupling::from_windows(&windows, knowns, op, id, lines)?;
    let mut probe = id.clone();
    let first = from_windows(&windows, knowns, op, &probe, lines);
    let damping = read.damping_dps.value;
    let ratio = settled(
        first,
        |ratio| {
            let rate = at_ratio(read.rate_dps, damping, ratio.relative);
            probe.cycle_rate_dps = Some(rate);
            Ok(from_windows(&windows, knowns, op, &probe, lines))
        },
        |last, step| Error::Measurement {
            what: "drive-gain ratio",
            reason: format!(
                "[drive_probe]'s rounds did not settle: after {RATIO_MAX_ROUNDS} the last moved g2/g1 by {step:.1} of its sigmas ({:.4} +- {:.1e}); the probe's rate, read {:.2} deg/s, is too near the damping coupling, read {damping:.2} deg/s, whose turning the ratio's identity must take out: probe at a rate several times the coupling (rate_dps)",
                last.relative.value, last.relative.uncertainty, read.rate_dps.value
            ),
        },
    )?;
    // With a damping coupling the identity has a second root, where the
    // rate read at that ratio is 0 and so no turning is taken out; the
    // probe turned, so a root whose rate is not seen is that one.
    let settled_rate = probe.cycle_rate_dps.unwrap_or(read.rate_dps);
    if !crate::selfcal::rate_seen(settled_rate) {
        return Err(Error::Measurement {
            what: "drive-gain ratio",
            reason: format!(
                "[drive_probe]'s rounds settled on g2/g1 {:.4} +- {:.1e}, where the rate reads {:.3} +- {:.3} deg/s: the identity's second root with a damping coupling, not the turn, read {:.3} deg/s at the design ratio; the probe's rate is too near the damping coupling, read {damping:.3} deg/s: probe at a rate several times the coupling (rate_dps)",
                ratio.relative.value,
                ratio.relative.uncertainty,
                settled_rate.value,
                settled_rate.uncertainty,
                read.rate_dps.value
            ),
        });
    }
    Ok(ratio)
}

/// A drive-gain ratio read from windows and the figures read again at it,
/// round after round: `round(r)` puts the figures at the ratio `r` and
/// reads the windows' ratio with them (the ratio's magnitude moves with
/// the rate where there is a damping coupling, [`turning_factor`], and
/// the rate the windows read moves with the ratio, [`at_ratio`]), until a
/// round moves the ratio by at most [`RATIO_CONVERGED`] of its sigma, at
/// most [`RATIO_MAX_ROUNDS`]. Both the probe ([`measure`]) and the ratio
/// at rest (`selfcal::at_rest`) iterate so; an `Err` from `round` stops
/// the rounds with it. Where the rate is not seen at rest it is predicted
/// at 0 and the ratio does not move: one round.
///
/// Rounds that do not settle are `unsettled(last, step)`'s error, `step`
/// the last round's move in the ratio's sigmas, never the last ratio as a
/// figure: near a damping coupling's own rate the rounds swing without end
/// (a 4.4 deg/s coupling probed at -6, 3 or 5 deg/s read g2/g1 2.27, 0.44
/// and 0.44 for 1 after 64 rounds, 27 to 155 of its sigmas off, and the
/// scale factors up to 140 of theirs; at 8 deg/s, 0.45 sigma).
pub(crate) fn settled<E>(
    first: DriveRatio,
    mut round: impl FnMut(&DriveRatio) -> Result<DriveRatio, E>,
    unsettled: impl FnOnce(&DriveRatio, f64) -> E,
) -> Result<DriveRatio, E> {
    let mut ratio = first;
    let mut step = f64::INFINITY;
    for _ in 0..RATIO_MAX_ROUNDS {
        let next = round(&ratio)?;
        step = (next.relative.value - ratio.relative.value).abs() / next.relative.uncertainty;
        ratio = next;
        if step <= RATIO_CONVERGED {
            return Ok(ratio);
        }
    }
    Err(unsettled(&ratio, step))
}

/// Most rounds of a ratio and the figures read at it ([`settled`]).
/// Each round shrinks the ratio's error by a factor that grows as the
/// coupling nears the rate: on the coupled device (250 deg/s of
/// stiffness, -200 of damping) probed at 200 deg/s, 6 (1.064, 1.0115,
/// 1.0020, 1.00034 for 1), where four rounds left it 10.7 sigma off.
const RATIO_MAX_ROUNDS: usize = 64;

/// The rounds stop once a round moves the ratio by less than this share
/// of its sigma ([`settled`]).
const RATIO_CONVERGED: f64 = 1e-3;

/// The rate C the windows read as h (their outputs' half difference) and
/// m (their mean damping term) at the design ratio, read again at the
/// ratio `r` (relative to the design): C = a h + b m with a, b = (r +-
/// 1/r) / 2, its sigma h's times a and r's times |m|
/// (`selfcal::at_rest`, module header).
pub(crate) fn at_ratio(h: Estimate, m: f64, r: Estimate) -> Estimate {
    let (a, b) = (
        (r.value + 1.0 / r.value) / 2.0,
        (r.value - 1.0 / r.value) / 2.0,
    );
    Estimate {
        value: a * h.value + b * m,
        uncertainty: (a * h.uncertainty).hypot(m * r.uncertainty),
    }
}

/// What a rate during the windows does to the at-rest estimate's
/// magnitude, taken out: the estimate is the ratio squared times M_12 /
/// M_21, 1 at rest, and with the device turning M_12 = -(kappa - c) /
/// det and M_21 = -(kappa + c) / det (`crate::coupling` module header; c
/// = j w 2 lambda Omega, kappa = k + j w d). With a stiffness coupling
/// alone |kappa - c| = |kappa + c|; with a damping coupling too they
/// differ at first order in the rate (`tests/data/field_coupled.toml`
/// with 10 deg/s of damping coupling at 50 deg/s: its output 2 was 9.6
/// sigma off, and 3 deg/s, 0.46% on the estimate, 2.8 sigma). So
/// |kappa + c| / |kappa - c|, from the identified couplings and the rate
/// the prediction is at ([`cross_terms`]); 1 at rest.
fn turning_factor(id: &Identified, carrier_hz: f64) -> f64 {
    let (kappa, c) = cross_terms(id, carrier_hz);
    let (plus, minus) = ((kappa + c).norm(), (kappa - c).norm());
    if minus > 0.0 { plus / minus } else { 1.0 }
}

/// The relative 1-sigma of [`turning_factor`]: the couplings moved by
/// their measurements' sigmas (lambda cancels in the factor: the
/// couplings and the rate are in the same deg/s) and the rate by its
/// sigma, in quadrature. A probe at 25 deg/s on a 4.4 deg/s damping
/// coupling moves the factor by some 2 Omega_d / Omega = 35%, so a
/// coupling known within 0.01 deg/s leaves 8e-4 on it.
fn turning_sigma(id: &Identified, carrier_hz: f64) -> f64 {
    let base = turning_factor(id, carrier_hz);
    let moved = |nudge: &dyn Fn(&mut Identified)| {
        let mut m = id.clone();
        nudge(&mut m);
        turning_factor(&m, carrier_hz) / base - 1.0
    };
    let couplings = |f: fn(&mut Identified) -> &mut Option<CouplingFigure>| {
        moved(&|m| {
            if let Some(c) = f(m) {
                c.value += c.measurement_uncertainty;
            }
        })
    };
    let quadrature = couplings(|m| &mut m.quadrature_dps);
    let damping = couplings(|m| &mut m.damping_coupling_dps);
    let rate = moved(&|m| {
        if let Some(r) = &mut m.cycle_rate_dps {
            r.value += r.uncertainty.copysign(r.value);
        }
    });
    quadrature.hypot(damping).hypot(rate)
}

/// The cross responses' two terms at the carrier from the
/// identification, in the couplings' units (deg/s, `turning_factor`):
/// kappa = Omega_q + j fc / f1 Omega_d and the Coriolis c = j fc / f1
/// Omega, Omega the rate the prediction is at (`selfcal::predicted_rate`).
pub(crate) fn cross_terms(id: &Identified, carrier_hz: f64) -> (C64, C64) {
    let value = |e: Option<CouplingFigure>| e.map_or(0.0, |c| c.value);
    let to_carrier = carrier_hz / id.modes[0].f_hz.value;
    let kappa = C64::new(
        value(id.quadrature_dps),
        to_carrier * value(id.damping_coupling_dps),
    );
    let rate = crate::selfcal::prediction_rate_dps(id);
    (kappa, C64::new(0.0, to_carrier * rate))
}

/// g_2 / g_1 from measured windows. With a quadrature coupling k the
/// cross responses are M_12 = -(k - c) / det and M_21 = -(k + c) / det
/// (`crate::coupling`), so the identity of the module header reads
/// -(g_2 / g_1)^2 (k - c) / (k + c) on the right where it read
/// (g_2 / g_1)^2. For a stiffness k (real) and the Coriolis c (imaginary)
/// that factor has magnitude 1: |g_2 / g_1| stays exact while turning, at
/// rest (c = 0, when k is large enough to see) or both; only the phase
/// moves. A damping coupling makes kappa complex, and the magnitude moves
/// with the rate ([`turning_factor`], taken out).
///
/// `spur_lines`: the table core's lines in the windows' means
/// (`coupling::spur_lines`), which the batches' spread does not see; their
/// share of the ratio's sigma is `coupling::spur_sigma`'s, as for the
/// couplings read from the same windows.
pub(crate) fn from_windows(
    windows: &CrossWindows,
    knowns: &Knowns,
    op: &Operating,
    id: &Identified,
    spur_lines: Option<&[TurningLine]>,
) -> DriveRatio {
    let g_error = resonator_ratio_error(id, op.carrier_hz);
    let g_ratio = folded_ratio(id, op.carrier_hz, knowns.clock_hz);
    let squared_of = |w: &CrossWindows| -> Vec<C64> {
        (0..BATCHES)
            .map(|b| {
                let ((p1, q1), (p2, q2)) = w.lines(Some(b));
                ratio_squared(p1, q1, p2, q2, w.w1, g_ratio)
            })
            .collect()
    };
    let design = knowns.force_full_scale[1] / knowns.force_full_scale[0];
    let turning = turning_factor(id, op.carrier_hz);
    let magnitude_of = |squared: &[C64]| -> Vec<f64> {
        squared
            .iter()
            .map(|v| (v.norm() * turning).sqrt() / design)
            .collect()
    };
    let squared = squared_of(windows);
    let magnitude = magnitude_of(&squared);
    let [spur] = spur_lines.map_or([0.0], |lines| {
        spur_sigma(windows, lines, |w| {
            let m = magnitude_of(&squared_of(w));
            [m.iter().sum::<f64>() / m.len() as f64]
        })
    });
    // Phases about the batches' mean (at rest with a coupling they sit at
    // +-180 deg, where a plain mean of arguments would wrap).
    let centre = squared.iter().sum::<C64>();
    let phase: Vec<f64> = squared
        .iter()
        .map(|v| 0.5 * ((v / centre).arg() + centre.arg()).to_degrees())
        .collect();
    let mut relative = mean_and_error(&magnitude);
    // The ratio is the square root of the estimate: half its relative
    // errors.
    let turning_error = turning_sigma(id, op.carrier_hz);
    relative.uncertainty = relative
        .uncertainty
        .hypot(0.5 * g_error * relative.value)
        .hypot(0.5 * turning_error * relative.value)
        .hypot(spur);
    let (_, (p2, q2)) = windows.lines(None);
    DriveRatio {
        relative,
        phase_deg: mean_and_error(&phase),
        cross_over_direct: (p2 / (q2 * windows.w1)).norm(),
        clocks: windows.clocks,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coupling::tests::line_error_rms;
    use crate::selfcal::spurs::RelativeLine;

    /// A device identified exactly (no sigma on its modes, no coupling, an
    /// ideal front end), knowns with equal drive full scales and a fast
    /// clock, and the operating point at the carrier `f`.
    fn exact_device(modes: [(f64, f64); 2], f: f64) -> (Knowns, Operating, Identified) {
        let exact = |value| Estimate {
            value,
            uncertainty: 0.0,
        };
        let fit = |(f_hz, q): (f64, f64)| identify::ModeFit {
            f_hz: exact(f_hz),
            q: exact(q),
            phase_deg: exact(0.0),
            relative_rms: 0.0,
            gain_hz2: 1.0,
            scanned: false,
            sweep: vec![],
            waits: Default::default(),
            spur_sd: vec![],
            c: C64::new(1.0, 0.0),
            front: Default::default(),
            residual_sd: 0.0,
            probe: vec![],
            probed_delay_s: None,
        };
        let id = Identified {
            modes: modes.map(fit),
            loop_phase_deg: exact(0.0),
            group_delay_s: exact(0.0),
            quadrature_dps: None,
            damping_coupling_dps: None,
            cycle_rate_dps: None,
            clocks: 0,
        };
        let nominal = crate::device::GyroParams {
            f1_hz: modes[0].0,
            f2_hz: modes[1].0,
            q1: modes[0].1,
            q2: modes[1].1,
            angular_gain: 0.7,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        };
        let knowns = Knowns::exact(nominal, 1e9, f);
        let op = Operating {
            carrier_hz: f,
            ref_lag_deg: 0.0,
            envelope_delay_s: 0.0,
            amplitude: (0.9, 0.9),
            scaled_drives: None,
            fold_shift_hz: 0.0,
            static_fold: None,
            spur_move: None,
            cycle_rate_dps: 0.0,
        };
        (knowns, op, id)
    }

    /// `settled` stops where a round moves the ratio by at most
    /// `RATIO_CONVERGED` of its sigma, and a swing that never settles is
    /// `unsettled`'s error with the last move, never the last ratio:
    /// - rounds that halve the distance to 1.02 settle within the rounds;
    /// - rounds that swing between 0.44 and 2.27 (the probe near a damping
    ///   coupling's rate, the doc comment's case) end in the error after
    ///   `RATIO_MAX_ROUNDS`, its step the swing in sigmas;
    /// - a round's own error stops the rounds at once.
    #[test]
    fn rounds_that_do_not_settle_are_an_error_not_a_figure() {
        let at = |value: f64| DriveRatio {
            relative: Estimate {
                value,
                uncertainty: 1e-4,
            },
            phase_deg: Estimate {
                value: 0.0,
                uncertainty: 0.1,
            },
            cross_over_direct: 0.1,
            clocks: 0,
        };
        let mut rounds = 0;
        let halving = settled(
            at(1.1),
            |r| {
                rounds += 1;
                Ok::<_, f64>(at(1.02 + (r.relative.value - 1.02) / 2.0))
            },
            |_, step| step,
        )
        .unwrap();
        assert!((halving.relative.value - 1.02).abs() <= 1e-7, "{halving:?}");
        assert!(rounds < RATIO_MAX_ROUNDS, "{rounds} rounds");
        let mut rounds = 0;
        let swing = settled(
            at(2.27),
            |r| {
                rounds += 1;
                Ok::<_, f64>(at(if r.relative.value > 1.0 { 0.44 } else { 2.27 }))
            },
            |last, step| {
                assert!(last.relative.value == 0.44 || last.relative.value == 2.27);
                step
            },
        );
        assert_eq!(rounds, RATIO_MAX_ROUNDS);
        let step = swing.unwrap_err();
        assert!((step - 1.83e4).abs() < 1.0, "{step}");
        let mut rounds = 0;
        let stopped = settled(
            at(1.0),
            |_| {
                rounds += 1;
                Err(-1.0)
            },
            |_, step| step,
        );
        assert_eq!((stopped.unwrap_err(), rounds), (-1.0, 1));
    }

    /// The ratio's spur share (`from_windows` with the lines) against the
    /// error a line leaves on it (`coupling::tests::line_error_rms`: 4000
    /// draws of its phases, the RMS of 4000 draws scattering by about
    /// 1.1%): within 5%, where the windows are constant (no batch spread)
    /// and the device exact, so the spur is the ratio's whole sigma. The
    /// windows are the module header's model with a Coriolis term and the
    /// drives 1.3% apart; the clean ratio reads that within 1e-6 (a 1 GHz
    /// clock folds no image in). The ratio comes from cross responses
    /// small beside the direct ones in the same windows, so a line moves it
    /// some 600 times its rho (1e-6 on output 2: 5.9e-4); the line is kept
    /// that small so that the ratio stays linear in it, as the sigma's
    /// slopes take it (at 1e-3 the error's RMS was 0.75 of the sigma).
    #[test]
    fn the_ratio_sigma_holds_the_spur_a_line_leaves() {
        let (f, modes) = (25.1e3, [(25.1e3, 3000.0), (25.8e3, 3000.0)]);
        let (g1, g2) = (resonator(25.1e3, 3000.0, f), resonator(25.8e3, 3000.0, f));
        let c = C64::new(0.0, 3e-4) * 1e12;
        let det = 1.0 / (g1 * g2) + c * c;
        let m = [[1.0 / (g2 * det), c / det], [-c / det, 1.0 / (g1 * det)]];
        let (w1, w2, rho) = (20000.0, [15000.0, -14999.0], 1.013);
        let z = |w: f64| {
            let j = C64::new(0.0, 1.0);
            let x1 = m[0][0] * w1 - j * rho * m[0][1] * w;
            let x2 = m[1][0] * w1 - j * rho * m[1][1] * w;
            [w1 * x1, w * x2]
        };
        let times = [[0.05, 0.09], [0.17, 0.21]];
        let windows = CrossWindows::constant([z(w2[0]), z(w2[1])], w1, w2, times);
        let (knowns, op, id) = exact_device(modes, f);
        let ratio = |w: &CrossWindows, lines| from_windows(w, &knowns, &op, &id, lines).relative;
        let clean = ratio(&windows, None);
        assert!((clean.value - rho).abs() < 1e-6, "{clean:?}");
        assert_eq!(clean.uncertainty, 0.0, "an exact device's constant windows");
        let line = RelativeLine {
            offset_hz: 2.8,
            rho: [3e-7, 1e-6],
        };
        let lines = crate::coupling::turning(&windows, std::slice::from_ref(&line));
        let sigma = ratio(&windows, Some(&lines)).uncertainty;
        let [rms] = line_error_rms(&windows, &line, |w| [ratio(w, None).value]);
        assert!(
            (rms / sigma - 1.0).abs() <= 0.05,
            "RMS {rms:e} against the sigma {sigma:e}"
        );
    }

    /// The four window means of the module header's model, built from
    /// chosen gains, rate coupling and resonators, give back g_2 / g_1.
    #[test]
    fn the_ratio_of_cross_responses_returns_the_drive_gain_ratio() {
        let f = 25.1e3;
        let (g1, g2) = (resonator(25.1e3, 3000.0, f), resonator(25.8e3, 3000.0, f));
        for (c, rho) in [(C64::new(0.0, 3e-4), 1.013), (C64::new(0.0, -2e-2), 0.97)] {
            let c = c * 1e12; // in the units of 1 / G
            let det = 1.0 / (g1 * g2) + c * c;
            let m = [[1.0 / (g2 * det), c / det], [-c / det, 1.0 / (g1 * det)]];
            let (gain1, gain2) = (2.0, 2.0 * rho);
            let (a1, a2) = (C64::from_polar(3.0, 0.2), C64::from_polar(5.0, 0.2));
            let (kappa1, kappa2) = (C64::from_polar(0.7, -1.0), C64::from_polar(0.4, 2.0));
            let w1 = 20000.0;
            let w2 = [15000.0, -14999.0];
            let z = |w: f64| {
                let j = C64::new(0.0, 1.0);
                let x1 = a1 * (gain1 * m[0][0] * w1 - j * gain2 * m[0][1] * w);
                let x2 = a2 * (gain1 * m[1][0] * w1 - j * gain2 * m[1][1] * w);
                [kappa1 * w1 * x1, kappa2 * w * x2]
            };
            let (y0, y1) = (z(w2[0]), z(w2[1]));
            let (p1, q1) = line([y0[0], y1[0]], w2);
            let (p2, q2) = line([y0[1] / w2[0], y1[1] / w2[1]], w2);
            let got = ratio_squared(p1, q1, p2, q2, w1, g1 / g2);
            // Exact algebra; the lines subtract windows whose terms differ
            // by up to 1e4 in size, so double rounding leaves some 1e-12.
            assert!((got - rho * rho).norm() < 1e-10, "{got} vs {}", rho * rho);
        }
    }
}
