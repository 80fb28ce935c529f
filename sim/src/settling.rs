//! Settling from power-up: how long a sweep waits before its window, and a
//! bound on what the transient left at the window's start does to the
//! window's mean (a systematic term of the uncertainty budget).
//!
//! From rest the response x_k = steady state - transient, and the
//! transient starts as large as the steady state's amplitude: in z it is at
//! most Z = |x_k| x (its reference's amplitude), the peak product (on a
//! resonant output z itself is near 0 while |x_k| is largest, so |z| is no
//! measure of it). It decays as exp(-t / tau), tau = 2 Q / w of the
//! slowest mode. The filters pass it with a lag: a decaying exponential
//! e^(-a t) leaves them as H(-a) e^(-a t) plus their own transient, which
//! decays at the slowest pole sigma; H(-a) for the Butterworth pair and
//! the RC pole is `lag` (1.5 at most for a derived filter, whose
//! Butterworth cut-off is at least 4 / (2 pi tau)), and the impulse
//! response's negative lobe (4% of its area) adds 10%.
//!
//! Target. The residue at the window's start, `residue`, must be at most
//! `tolerance / SETTLE_MARGIN` of the signal S the fit measures (S = |SF|
//! x span of the rates) and at most `NOISE_SHARE` of a point's expected
//! noise over the first window, divided by sqrt(points) (a slope weighs
//! the points' biases by at most sqrt(points) more than their noise):
//! the noise, from the ADC's noise and quantization alone, sqrt(2 (n^2 +
//! q^2 / 12) / N) ADC LSB of in-phase amplitude over N clocks, against
//! the rate signal's span in the same units (`Plan::signal_lsb`). A
//! tolerance alone left a matched Q 13,000 device's readout scale factors
//! 1.6e-6 off, 4 sigmas (the batches see only part of a transient that
//! spans the window). Time, r = max Z / target: 5 R clocks for the CIC,
//! then the longer of tau ln(2 lag r) (the resonator's lagged decay) and
//! ln(2 `FILTER_OVERSHOOT` r) / sigma (the filters' own transient), so
//! that each leaves half the target; both run at once (the old rule
//! added them, tau ln r + ln r / sigma, 25% longer on the paper's device).
//!
//! Bound. A residue e decaying as exp(-t / tau) biases the mean of a window
//! W by e (tau / W) (1 - exp(-W / tau)).

/// The transient left at the start of a window is at most
/// `tolerance / SETTLE_MARGIN` of the signal: its bias on the mean is then
/// well below the uncertainty the plan aims at (`tolerance` of the ratio).
pub const SETTLE_MARGIN: f64 = 10.0;
/// The transient's bias on a slope is at most this share of its noise.
const NOISE_SHARE: f64 = 0.3;
/// Bound on the filters' step-response error over its exponential
/// envelope (the Butterworth pair overshoots by 4%; 2 leaves room for the
/// RC pole's and the CIC's share before the slowest pole takes over).
const FILTER_OVERSHOOT: f64 = 2.0;

/// What one sweep's settling depends on.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Transient scale Z per point and output (z units).
    pub transient: Vec<[f64; 2]>,
    /// The rate signal over the span per output (z units).
    pub signal: [f64; 2],
    /// The same in ADC LSB of in-phase amplitude (`Plan::signal_lsb`).
    pub signal_lsb: [f64; 2],
    /// The shortest first window of the sweep's points (clocks).
    pub window_cycles: f64,
}

/// The filters' and the resonator's timing, shared by both sweeps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Slowest resonator time constant (s).
    pub tau_s: f64,
    /// Butterworth cut-off (Hz).
    pub butterworth_hz: f64,
    /// RC cut-off (Hz).
    pub rc_hz: f64,
    /// CIC decimation R.
    pub decimation: u32,
    /// Clock (Hz).
    pub clock_hz: f64,
    /// ADC noise variance at the quantizer, noise^2 + step^2 / 12 (word LSB^2).
    pub adc_variance: f64,
    /// Clocks from power-up until the drives start.
    pub drive_start: u64,
}

impl Timing {
    /// Slowest decay rate of the filters (1/s): the Butterworth pair's
    /// real part w_c / sqrt 2, or the RC pole.
    fn sigma(&self) -> f64 {
        let tau = std::f64::consts::TAU;
        (tau * self.butterworth_hz / 2f64.sqrt()).min(tau * self.rc_hz)
    }

    /// Upper bound on how much the filters amplify a residue decaying as
    /// exp(-t / tau) (module header); 2 when the filters are not faster
    /// than twice that decay (explicit slow cut-offs).
    fn lag(&self) -> f64 {
        let tau = std::f64::consts::TAU;
        let a = 1.0 / self.tau_s;
        let (wb, wr) = (tau * self.butterworth_hz, tau * self.rc_hz);
        if a > 0.5 * wb / 2f64.sqrt() || a > 0.5 * wr {
            return 2.0;
        }
        1.1 * wb * wb / (a * a - 2f64.sqrt() * wb * a + wb * wb) * wr / (wr - a)
    }

    /// The CIC's delay before its output follows its input (s): 5 R
    /// clocks (its 4 stages of R, and a sample).
    fn cic_delay(&self) -> f64 {
        5.0 * f64::from(self.decimation) / self.clock_hz
    }

    /// Mean of exp(-t / tau) over a window of `window_s` from its start.
    fn window_factor(&self, window_s: f64) -> f64 {
        let x = window_s / self.tau_s;
        if x < 1e-9 {
            1.0
        } else {
            (1.0 - (-x).exp()) / x
        }
    }
}

/// The residue each output may keep at the window's start (z units):
/// the smaller of the tolerance's and the noise's share (module header).
fn targets(sweep: &Sweep, t: &Timing, tolerance: f64) -> [f64; 2] {
    let n = sweep.transient.len() as f64;
    let window_s = sweep.window_cycles / t.clock_hz;
    std::array::from_fn(|k| {
        let noise = (2.0 * t.adc_variance / sweep.window_cycles).sqrt() / sweep.signal_lsb[k];
        let by_noise = NOISE_SHARE * noise / (n.sqrt() * t.window_factor(window_s));
        sweep.signal[k] * (tolerance / SETTLE_MARGIN).min(by_noise)
    })
}

/// Settling clocks of a sweep (from power-up) and each point's residue at
/// the window's start (z units), per output.
pub fn settle(sweep: &Sweep, t: &Timing, tolerance: f64) -> (u64, Vec<[f64; 2]>) {
    let target = targets(sweep, t, tolerance);
    let r = sweep
        .transient
        .iter()
        .flat_map(|z| (0..2).map(move |k| z[k] / target[k]))
        .fold(1.0f64, f64::max);
    // Half the target each for the resonator's lagged decay and the
    // filters' own transient (`residue`).
    let seconds = t.cic_delay()
        + (t.tau_s * (2.0 * t.lag() * r).ln()).max((2.0 * FILTER_OVERSHOOT * r).ln() / t.sigma());
    let cycles = (seconds * t.clock_hz).ceil() as u64 + t.drive_start;
    let residues = sweep
        .transient
        .iter()
        .map(|z| z.map(|z| residue(z, cycles, t)))
        .collect();
    (cycles, residues)
}

/// The residue of a transient of scale `z` at clock `cycles` after
/// power-up: the resonator's decay since the drives started (less the
/// CIC's delay) times the filters' lag, plus the filters' own transient
/// (their response to the step of z at the drives' start, at most
/// `FILTER_OVERSHOOT` z decaying at sigma).
fn residue(z: f64, cycles: u64, t: &Timing) -> f64 {
    let since = cycles.saturating_sub(t.drive_start) as f64 / t.clock_hz;
    let after = (since - t.cic_delay()).max(0.0);
    z * (t.lag() * (-after / t.tau_s).exp() + FILTER_OVERSHOOT * (-t.sigma() * after).exp())
}

/// Bound on the bias a residue `residue` (z units) leaves on the mean of
/// a window of `window_s` seconds.
pub fn bias_bound(residue: [f64; 2], t: &Timing, window_s: f64) -> [f64; 2] {
    residue.map(|e| e * t.window_factor(window_s))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A derived-like filter (Butterworth at 4 / (2 pi tau)), 1 MHz clock.
    fn timing() -> Timing {
        let tau_s = 1e-3;
        let bw = 4.0 / (std::f64::consts::TAU * tau_s);
        Timing {
            tau_s,
            butterworth_hz: bw,
            rc_hz: 4.0 * bw,
            decimation: 200,
            clock_hz: 1e6,
            adc_variance: 1.0 + 1.0 / 12.0,
            drive_start: 8232,
        }
    }

    #[test]
    fn the_residue_at_the_window_is_within_its_target() {
        // Transients 1e3 and 1e5 times the signal (a detuned readout's
        // offset, a resonant output's amplitude): whichever target binds,
        // the bound left at the window's start meets it, and a window
        // starting earlier would not (the settling is not padded).
        let t = timing();
        for signal_lsb in [1.0, 1e4] {
            let sweep = Sweep {
                transient: vec![[1e3, 1e5], [2e3, 3e4]],
                signal: [1.0, 1.0],
                signal_lsb: [signal_lsb; 2],
                window_cycles: 1e5,
            };
            let target = targets(&sweep, &t, 1e-4);
            let (cycles, residues) = settle(&sweep, &t, 1e-4);
            let worst = |cycles: u64| {
                sweep
                    .transient
                    .iter()
                    .flat_map(|z| (0..2).map(move |k| residue(z[k], cycles, &t) / target[k]))
                    .fold(0.0f64, f64::max)
            };
            assert!(worst(cycles) <= 1.0, "{}", worst(cycles));
            assert!(worst(cycles - 1000) > 1.0, "{}", worst(cycles - 1000));
            assert_eq!(residues[1][0], residue(2e3, cycles, &t));
        }
    }

    #[test]
    fn a_derived_filter_lags_by_at_most_one_and_a_half() {
        // a = 1 / tau against a Butterworth at 4 / tau: H(-a) = 1.36, the
        // RC pole 1.07, and 10% for the negative lobe.
        let lag = timing().lag();
        assert!((1.5..1.7).contains(&lag), "{lag}");
    }

    #[test]
    fn the_bias_falls_as_tau_over_the_window() {
        let t = timing();
        let b = |w: f64| bias_bound([1.0, 1.0], &t, w)[0];
        assert!((b(1e-9) - 1.0).abs() < 1e-6);
        assert!((b(0.1) - 0.01).abs() < 1e-6, "{}", b(0.1));
    }
}
