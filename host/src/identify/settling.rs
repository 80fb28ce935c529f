//! The resonator's settling residue in each fine-sweep point, worked out
//! and taken off the point (module header of `super`).
//!
//! A carrier step leaves the resonator ringing: its state was the steady
//! response to the last drive, and the difference from the new steady
//! response decays at its own frequency. With the drive's phase
//! continuous across the step (the carrier NCO's accumulator only adds,
//! `gyrocal_hdl::carrier_nco`), the new carrier's frame sees
//!
//! ```text
//!   residue(t) = (a Y(f_prev) - Y(f)) e^(s t),   s = -pi bk + j 2 pi (fk - f)
//! ```
//!
//! t after the step, Y the mode's resonant response (C hold(f) / D(f),
//! without the DAC's images or another mode, whose own transients decay
//! at their own rates) and a the last drive's amplitude over this one's
//! (0 when the drive was off; the readout word is both the drive's and the
//! reference's, so Y is per word squared and the ringing of the old drive
//! counts a times). The output filter (CIC, Butterworth, RC) passes
//! e^(s t) times its response at s ([`filter_response`]), and each window's
//! mean is that over its own samples' times: the I window gives the real
//! part of the point, the Q window, later by `Waits::quarter_s`, the
//! imaginary part. The waits leave some e^-14 of the step at the I window
//! (`super::settling_residue`); small, but on a high-Q mode it is what the
//! residuals and the jackknife saw most of (fork part 0 with no ADC noise:
//! Q1's residual sigma 4.3e-3 at 12 time constants, 2.3e-3 at 24).
//!
//! What the model does not know is when the step happened within the
//! bus's writes: between two reads of SAMPLE_COUNT, plus the datapath's
//! latency from the carrier register to the CIC, tens of clocks, under
//! the least decimation ([`Arrival::step_s`]). That bracket is what the
//! correction may leave ([`Arrival::kept`]).

use super::{C64, ModeFit};
use crate::knowns::Derived;
use crate::theory::hold_gain;
use gyrocal_regs::datapath::CIC_STAGES;
use std::f64::consts::{PI, SQRT_2, TAU};

/// What the resonator carried into one sweep point and when the point's
/// windows saw it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Arrival {
    /// The carrier driven before this point's step (Hz).
    pub from_hz: f64,
    /// That drive's readout word over this point's (0: the drive was off).
    pub from_scale: f64,
    /// Seconds from the step to each sample of the I window.
    pub i_s: Vec<f64>,
    /// Seconds from the step to each sample of the Q window.
    pub q_s: Vec<f64>,
    /// Half-width of the bracket the step lies in (s): the times above
    /// are its middle's.
    pub step_s: f64,
}

impl Arrival {
    /// The arrival of a point whose step came between SAMPLE_COUNT reads
    /// `before` and `after`, whose I and Q windows read the samples
    /// `i_counts` and `q_counts`, `sample_s` a sample: the step lay after
    /// sample `before` was published and before sample `after` + 1 was,
    /// so a window sample c came (c - after - 1) to (c - before) samples
    /// after it. The times are that bracket's middle; its half-width, and
    /// one sample more for the datapath's latency, is `step_s`.
    pub fn from_counts(
        from: (f64, f64),
        (before, after): (u32, u32),
        (i_counts, q_counts): (&[u32], &[u32]),
        sample_s: f64,
    ) -> Self {
        let mid = 0.5 * (f64::from(after.wrapping_sub(before)) + 1.0);
        let times = |counts: &[u32]| -> Vec<f64> {
            (counts.iter())
                .map(|c| (f64::from(c.wrapping_sub(before)) - mid) * sample_s)
                .collect()
        };
        Self {
            from_hz: from.0,
            from_scale: from.1,
            i_s: times(i_counts),
            q_s: times(q_counts),
            step_s: (mid + 1.0) * sample_s,
        }
    }

    /// The fraction of its ringing that the correction of this point at
    /// carrier `f` may leave, for the mode `m`: a step off by dt within
    /// the bracket turns and scales the ringing by e^(s dt), which moves
    /// it by |e^(s dt) - 1| <= e^(|s| dt) - 1 of itself (at most 1: the
    /// residue not corrected). Of the ringing, not of the residue: each
    /// window takes one part of a turned ringing, which can be more of
    /// that part than of the whole.
    ///
    /// ```
    /// use gyrocal_host::identify::settling::{Arrival, Resonance};
    /// use nalgebra::Complex;
    /// let m = Resonance { f_hz: 1e4, bandwidth_hz: 1.0, c: Complex::new(1.0, 0.0) };
    /// let a = Arrival { step_s: 1e-3, ..Default::default() };
    /// // At the mode, |s| = pi bk.
    /// assert!((a.kept(&m, 1e4) - (std::f64::consts::PI * 1e-3).exp_m1()).abs() < 1e-15);
    /// ```
    pub fn kept(&self, m: &Resonance, f: f64) -> f64 {
        let s = ringing(m.f_hz, m.bandwidth_hz, f);
        (s.norm() * self.step_s).exp_m1().min(1.0)
    }
}

/// The output filter's response at the complex frequency `s` (1/s)
/// relative to its DC gain: the CIC's `CIC_STAGES` stages at the clock,
/// then the Butterworth biquad and the RC pole at the output rate
/// (`gyrocal_regs::filter_design`, unquantized: the coefficients' rounding
/// moves it by some 1e-9).
///
/// ```
/// use gyrocal_host::identify::filter_response;
/// use gyrocal_host::knowns::Derived;
/// use nalgebra::Complex;
/// let f = Derived { decimation: 400, butterworth_hz: 50.0, rc_hz: 100.0, min_window_s: 0.1 };
/// assert!((filter_response(&f, 4e6, Complex::new(0.0, 0.0)) - 1.0).norm() < 1e-12);
/// // Far below the cut-offs, a delay: the phase falls as the frequency rises.
/// let h = filter_response(&f, 4e6, Complex::new(0.0, 1.0));
/// assert!(h.arg() < 0.0 && (h.norm() - 1.0).abs() < 1e-3);
/// ```
pub fn filter_response(filter: &Derived, clock_hz: f64, s: C64) -> C64 {
    let r = f64::from(filter.decimation);
    let x = s / clock_hz;
    let cic = (decay_mean(x * r) / decay_mean(x)).powi(CIC_STAGES as i32);
    let fz = clock_hz / r;
    let zi = (-x * r).exp();
    let w = (PI * filter.butterworth_hz / fz).tan();
    let d = 1.0 + SQRT_2 * w + w * w;
    let (a1, a2) = (2.0 * (w * w - 1.0) / d, (1.0 - SQRT_2 * w + w * w) / d);
    let biquad = (1.0 + zi).powi(2) / (1.0 + a1 * zi + a2 * zi * zi) * ((1.0 + a1 + a2) / 4.0);
    let alpha = -(-TAU * filter.rc_hz / fz).exp_m1();
    let rc = alpha / (1.0 - (1.0 - alpha) * zi);
    cic * biquad * rc
}

/// (1 - e^-x) / x, without the cancellation near 0 (1 at 0).
fn decay_mean(x: C64) -> C64 {
    if x.norm() < 1e-3 {
        1.0 - x / 2.0 * (1.0 - x / 3.0 * (1.0 - x / 4.0))
    } else {
        (1.0 - (-x).exp()) / x
    }
}

/// The mode's own complex frequency in the frame of carrier `f` (1/s).
fn ringing(fk: f64, bk: f64, f: f64) -> C64 {
    C64::new(-PI * bk, TAU * (fk - f))
}

/// A mode's resonance as the residue needs it: Y(f) = C hold(f) /
/// ((fk - f)(fk + f) + j f bk).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resonance {
    /// fk (Hz).
    pub f_hz: f64,
    /// bk (Hz).
    pub bandwidth_hz: f64,
    /// C (the point's units times Hz^2).
    pub c: C64,
}

impl Resonance {
    /// Y at carrier `f` on a clock of `clock_hz`: the mode's resonant
    /// response through the DAC hold's gain.
    pub fn at(&self, f: f64, clock_hz: f64) -> C64 {
        let (fk, bk) = (self.f_hz, self.bandwidth_hz);
        self.c * hold_gain(f, clock_hz) / C64::new((fk - f) * (fk + f), f * bk)
    }

    /// The resonance of a fitted mode.
    pub(crate) fn of(m: &ModeFit) -> Self {
        Self {
            f_hz: m.f_hz.value,
            bandwidth_hz: m.f_hz.value / m.q.value,
            c: m.c,
        }
    }
}

/// The ringing the windows of the point at carrier `f` that arrived as
/// `a` see (module header), for the mode `m`, in the point's units (those
/// of `m.c` over Hz^2), on a clock of `clock_hz` through `filter`: the
/// I window's and the Q window's, before each takes its part.
pub fn ringing_seen(
    m: &Resonance,
    f: f64,
    a: &Arrival,
    clock_hz: f64,
    filter: &Derived,
) -> [C64; 2] {
    let before = match a.from_scale {
        0.0 => C64::new(0.0, 0.0),
        scale => m.at(a.from_hz, clock_hz) * scale,
    };
    let s = ringing(m.f_hz, m.bandwidth_hz, f);
    let seen = (before - m.at(f, clock_hz)) * filter_response(filter, clock_hz, s);
    let mean =
        |times: &[f64]| times.iter().map(|t| (s * t).exp()).sum::<C64>() / times.len() as f64;
    [seen * mean(&a.i_s), seen * mean(&a.q_s)]
}

/// The residue in the point: the real part of the I window's ringing and
/// the imaginary part of the Q window's ([`ringing_seen`]).
pub fn residue(m: &Resonance, f: f64, a: &Arrival, clock_hz: f64, filter: &Derived) -> C64 {
    let [i, q] = ringing_seen(m, f, a, clock_hz, filter);
    C64::new(i.re, q.im)
}

/// `sweep` with each point's residue taken off (`arrivals` one per point),
/// for the mode fitted as `m`.
pub(crate) fn corrected(
    m: &ModeFit,
    sweep: &[(f64, C64)],
    arrivals: &[Arrival],
    clock_hz: f64,
    filter: &Derived,
) -> Vec<(f64, C64)> {
    let m = Resonance::of(m);
    (sweep.iter().zip(arrivals))
        .map(|(&(f, y), a)| (f, y - residue(&m, f, a, clock_hz, filter)))
        .collect()
}

/// The fraction of the residue the correction may leave, the largest over
/// the points ([`Arrival::kept`]).
pub(crate) fn kept(m: &ModeFit, sweep: &[(f64, C64)], arrivals: &[Arrival]) -> f64 {
    let m = Resonance::of(m);
    (sweep.iter().zip(arrivals))
        .map(|(&(f, _), a)| a.kept(&m, f))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::knowns::Knowns;

    /// The output filter played sample by sample: the CIC's four running
    /// sums of R at the clock, kept every R clocks, then the Butterworth
    /// biquad and the RC pole in their difference equations, from the
    /// steady state of a constant input `z0`.
    struct Chain {
        r: usize,
        cic: [std::collections::VecDeque<C64>; 4],
        sums: [C64; 4],
        b: [f64; 3],
        a: [f64; 2],
        alpha: f64,
        x: [C64; 2],
        y: [C64; 2],
        out: C64,
        clock: usize,
    }

    impl Chain {
        fn new(filter: &Derived, clock_hz: f64, z0: C64) -> Self {
            let r = filter.decimation as usize;
            let fz = clock_hz / r as f64;
            let w = (PI * filter.butterworth_hz / fz).tan();
            let d = 1.0 + SQRT_2 * w + w * w;
            let b0 = w * w / d;
            Self {
                r,
                cic: std::array::from_fn(|_| std::iter::repeat_n(z0, r).collect()),
                sums: [z0 * r as f64; 4],
                b: [b0, 2.0 * b0, b0],
                a: [2.0 * (w * w - 1.0) / d, (1.0 - SQRT_2 * w + w * w) / d],
                alpha: -(-TAU * filter.rc_hz / fz).exp_m1(),
                x: [z0; 2],
                y: [z0; 2],
                out: z0,
                clock: 0,
            }
        }

        /// One clock's input; the output sample when one is made.
        fn clock(&mut self, mut v: C64) -> Option<C64> {
            for (line, sum) in self.cic.iter_mut().zip(self.sums.iter_mut()) {
                *sum += v - line.pop_front().unwrap();
                line.push_back(v);
                v = *sum / self.r as f64;
            }
            self.clock += 1;
            if !self.clock.is_multiple_of(self.r) {
                return None;
            }
            let [b0, b1, b2] = self.b;
            let y = b0 * v + b1 * self.x[0] + b2 * self.x[1]
                - self.a[0] * self.y[0]
                - self.a[1] * self.y[1];
            (self.x, self.y) = ([v, self.x[0]], [y, self.y[0]]);
            let dc = (b0 + b1 + b2) / (1.0 + self.a[0] + self.a[1]);
            self.out += self.alpha * (y / dc - self.out);
            Some(self.out)
        }
    }

    /// The paper's modes on a fake board (9.64 MHz and 250 Hz above, Q
    /// 55,000, a 3 deg front end), ringing or not, with no noise, and
    /// what the host knows of it.
    fn paper_board(ringing: bool) -> (crate::fake::Lorentzian, Knowns) {
        let c = C64::from_polar(2.0e9, -3f64.to_radians());
        let (f1, f2) = (9.64e6, 9.64e6 + 250.0);
        let mut board =
            crate::fake::Lorentzian::new(50e6, [(f1, f1 / 55e3, c), (f2, f2 / 55e3, c * 0.8)], 0.0);
        board.ringing = ringing;
        let knowns = crate::fake::paper_knowns(crate::fake::paper_datasheet(f1, f2));
        (board, knowns)
    }

    /// Mode 1's fine sweep around its truth on `paper_board`, after a
    /// last measurement `from` bandwidths away (where a coarse search
    /// leaves the drive): the host's fit of it (`super::super::fine_fit`,
    /// the ringing taken off), and a fit of its points as they came.
    fn fine_on(ringing: bool, from: f64) -> (ModeFit, ModeFit) {
        use crate::identify::{fine_fit, fine_sweep, fit, probe::Prober};
        let (mut board, knowns) = paper_board(ringing);
        let (fk, bk) = (9.64e6, 9.64e6 / 55e3);
        let mut probe = Prober::new(&mut board, &knowns, 0, 0.5);
        probe.tau_s = crate::knowns::TAU_MARGIN / (PI * bk);
        probe.measure(fk + from * bk).unwrap();
        let host = fine_fit(&mut probe, fk, bk).unwrap().unwrap();
        let (mut board, _) = paper_board(ringing);
        let mut probe = Prober::new(&mut board, &knowns, 0, 0.5);
        probe.tau_s = crate::knowns::TAU_MARGIN / (PI * bk);
        probe.measure(fk + from * bk).unwrap();
        let (sweep, _) = fine_sweep(&mut probe, fk, bk).unwrap();
        let clock = Some(knowns.clock_hz);
        let raw = fit::fit_mode(&sweep, fk, bk, clock, &fit::no_pull, Default::default()).unwrap();
        (host, raw)
    }

    /// On a board whose modes ring after each step (`Lorentzian::ringing`:
    /// its own ringing, through a filter of the registers' coefficients),
    /// the host's fine fit lies where the same sweep of a board that does
    /// not ring does: within three of the sigma the host gives what its
    /// correction may leave (`super::super::settle_sd` times
    /// `Waits::settling`, the residue times `Waits::kept`, 5.4% here), and
    /// within a third of where the points as they came put fk and Q (the
    /// ringing, some 1e-8 of each point after the waits' 18 time
    /// constants, moves fk by 5.6e-9 to 4.1e-8 Hz, up to 4.3 of that sigma,
    /// and Q by 1.9e-6 to 2.1e-5, from three places the drive comes from;
    /// the fit then moves fk by 1 or 2 of the doubles' steps at 9.64 MHz).
    /// On the fake, whose steady state lacks the DAC's images that the fit
    /// models, the board that does not ring is the reference; both sweeps
    /// visit the same carriers at the same clocks, at half of full scale,
    /// where the fake's z words (1/256 LSB) resolve the ringing to 1e-3.
    #[test]
    fn the_fine_fit_takes_the_ringing_off_the_points() {
        for from in [-2.0, 0.3, 3.0] {
            let ((host, raw), (_, still)) = (fine_on(true, from), fine_on(false, from));
            let w = host.waits;
            let bk = host.f_hz.value / host.q.value;
            let pull = super::super::settle_sd(PI * bk * w.quarter_s);
            let left = w.settling(bk);
            let sigma = [pull[0] * left * bk, pull[1] * left * host.q.value];
            let off = |m: &ModeFit| [m.f_hz.value - still.f_hz.value, m.q.value - still.q.value];
            let (corrected, uncorrected) = (off(&host), off(&raw));
            eprintln!(
                "from {from} bk: corrected {corrected:?}, uncorrected {uncorrected:?}, \
                 sigma of what is left {sigma:?} (kept {})",
                w.kept
            );
            assert!(w.kept > 0.0 && w.kept < 0.1, "kept {}", w.kept);
            for i in 0..2 {
                assert!(
                    corrected[i].abs() <= 3.0 * sigma[i],
                    "{corrected:?} against {sigma:?}"
                );
                assert!(
                    3.0 * corrected[i].abs() <= uncorrected[i].abs(),
                    "{corrected:?} against {uncorrected:?}"
                );
            }
        }
    }

    const CLOCK: f64 = 100e3;
    const FILTER: Derived = Derived {
        decimation: 166,
        butterworth_hz: 20.0,
        rc_hz: 60.0,
        min_window_s: 0.1,
    };

    /// `filter_response` is what the filter does to a decaying turn:
    /// e^(s t) played through the chain sample by sample for 1.5 s (the
    /// chain's own transient gone to 1e-30), against e^(s t) times the
    /// response, within 1e-9, at turns inside and beyond the cut-offs.
    #[test]
    fn the_filter_response_is_what_the_chain_does_to_a_decaying_turn() {
        for s in [
            C64::new(-3.0, TAU * 2.0),
            C64::new(-6.0, -TAU * 15.0),
            C64::new(-0.5, TAU * 45.0),
        ] {
            let mut chain = Chain::new(&FILTER, CLOCK, C64::new(1.0, 0.0));
            let h = filter_response(&FILTER, CLOCK, s);
            let n = (1.5 * CLOCK) as usize;
            let mut last = None;
            for i in 1..=n {
                let t = i as f64 / CLOCK;
                if let Some(out) = chain.clock((s * t).exp()) {
                    last = Some(out / (s * t).exp());
                }
            }
            let seen = last.unwrap();
            assert!(
                (seen - h).norm() < 1e-9 * h.norm(),
                "s {s}: {seen} against {h}"
            );
        }
    }
}
