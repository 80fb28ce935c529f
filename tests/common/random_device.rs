//! Random gyroscopes for the coverage tests: a seed gives one device and
//! its experiment as a configuration file with the required keys alone
//! (plus, when asked, `tolerance` and `budget_s`), so every run is
//! reproducible from its seed.
//!
//! Ranges (README "Supported ranges", kept inside them):
//! - mode 1 at f1, log-uniform in `Ranges::f_hz`; Q1 log-uniform in
//!   `Ranges::q`, Q2 = Q1 x 2^U(-1, 1);
//! - split f2 - f1: 0 (matched) one time in six, else U(-20, 20) mode
//!   bandwidths f1 / Q1 (either sign);
//! - carrier at mode 1 (2 in 5), mode 2 (3 in 10) or at a uniform point
//!   between them;
//! - clock = carrier x 2^U(log2 2.6, log2 40), within 100 kHz..500 MHz,
//!   rounded to 7 significant digits; plans whose carrier is a
//!   small-integer fraction of the clock are drawn again (the tool warns
//!   about them, README);
//! - lambda U(0.3, 0.9);
//! - 2 to 8 readout rates, evenly spaced over [r0, r1], r1 log-uniform in
//!   5..1000 deg/s, r0 one of 0, r1 / 10 or -r1 (sign flips included);
//! - 2 to 6 calibration frequencies evenly spaced up to f_top, f_top a
//!   log-uniform fraction 0.05..1 of the largest the device and clock
//!   allow (3 mode bandwidths, clock x 1e-3, clock / (40 x 166)), the
//!   lowest f_top / 3 or f_top / 2.
//!
//! The generator is splitmix64 (`gyrocal_hdl::host::traffic::Rng`, ours:
//! a dependency's update can never move the pinned devices).

#![allow(dead_code)] // reason: each test crate uses part of it

use gyrocal_hdl::filter_design::MIN_DECIMATION;
use gyrocal_hdl::host::traffic::Rng;
use gyrocal_hdl::settings::{MAX_CAL_RATIO, commensurate_period};
use gyrocal_sim::config::SAMPLES_PER_RIPPLE;

/// Draws from splitmix64 (`traffic::Rng`, the bus tests' generator).
struct Draw(Rng);

impl Draw {
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [a, b).
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    /// Log-uniform in [a, b).
    fn log_uniform(&mut self, a: f64, b: f64) -> f64 {
        (self.uniform(a.ln(), b.ln())).exp()
    }
    /// Uniform integer in a..=b.
    fn int(&mut self, a: u32, b: u32) -> u32 {
        a + (self.unit() * f64::from(b - a + 1)) as u32
    }
}

/// Where the device parameters are drawn from.
#[derive(Clone, Copy, Debug)]
pub struct Ranges {
    /// Mode 1 frequency (Hz), log-uniform.
    pub f_hz: (f64, f64),
    /// Mode 1 quality factor, log-uniform.
    pub q: (f64, f64),
}

/// The span: 10 kHz..10 MHz, Q 100..1e5.
pub const WIDE: Ranges = Ranges {
    f_hz: (1e4, 1e7),
    q: (100.0, 1e5),
};

/// The coverage test's span: small, fast devices (the cost of a point
/// grows as Q x clock / f), 10 kHz..10 MHz, Q 100..1e4.
pub const FAST: Ranges = Ranges {
    f_hz: (1e4, 1e7),
    q: (100.0, 1e4),
};

/// One drawn device and experiment.
#[derive(Clone, Debug)]
pub struct RandomDevice {
    /// The seed it came from.
    pub seed: u64,
    /// Mode frequencies (Hz).
    pub f_hz: [f64; 2],
    /// Quality factors.
    pub q: [f64; 2],
    /// Angular gain.
    pub lambda: f64,
    /// Carrier (Hz).
    pub carrier_hz: f64,
    /// Clock (Hz).
    pub clock_hz: f64,
    /// Readout rates (deg/s).
    pub rates_dps: Vec<f64>,
    /// Calibration frequencies (Hz).
    pub cal_hz: Vec<f64>,
}

/// Round to 7 significant digits (the nearest f64 to the decimal, which
/// prints short).
fn round7(x: f64) -> f64 {
    format!("{x:.6e}").parse().unwrap()
}

/// `n` values evenly spaced over [a, b].
fn spaced(a: f64, b: f64, n: u32) -> Vec<f64> {
    (0..n)
        .map(|i| round7(a + (b - a) * f64::from(i) / f64::from(n - 1)))
        .collect()
}

impl RandomDevice {
    /// The device of `seed` drawn from `ranges` (module header).
    pub fn draw(seed: u64, ranges: Ranges) -> Self {
        let mut g = Draw(Rng(seed));
        loop {
            if let Some(d) = Self::try_draw(&mut g, seed, ranges) {
                return d;
            }
        }
    }

    fn try_draw(g: &mut Draw, seed: u64, ranges: Ranges) -> Option<Self> {
        let f1 = round7(g.log_uniform(ranges.f_hz.0, ranges.f_hz.1));
        let q1 = round7(g.log_uniform(ranges.q.0, ranges.q.1));
        let q2 = round7(q1 * 2f64.powf(g.uniform(-1.0, 1.0)));
        let bandwidth = f1 / q1;
        let split = if g.int(0, 5) == 0 {
            0.0
        } else {
            g.uniform(-20.0, 20.0) * bandwidth
        };
        let f2 = round7(f1 + split);
        let carrier = match g.int(0, 9) {
            0..=3 => f1,
            4..=6 => f2,
            _ => round7(f1 + g.unit() * (f2 - f1)),
        };
        let clock = round7(carrier * 2f64.powf(g.uniform(2.6f64.log2(), 40f64.log2())));
        if !(1e5..=5e8).contains(&clock)
            || carrier < 1e3
            || f2 < 1e3
            || commensurate_period(carrier, clock).is_some()
        {
            return None;
        }
        let lambda = round7(g.uniform(0.3, 0.9));
        let r1 = g.log_uniform(5.0, 1000.0);
        let r0 = match g.int(0, 2) {
            0 => 0.0,
            1 => r1 / 10.0,
            _ => -r1,
        };
        let rates_dps = spaced(r0, r1, g.int(2, 8));
        let cal_max = (3.0 * bandwidth.min(f2 / q2))
            .min(clock * MAX_CAL_RATIO)
            .min(clock / (2.0 * SAMPLES_PER_RIPPLE * f64::from(MIN_DECIMATION)));
        let f_top = cal_max * g.log_uniform(0.05, 1.0) * 0.999;
        let f_low = f_top / f64::from(g.int(2, 3));
        let cal_hz = spaced(f_low, f_top, g.int(2, 6));
        Some(Self {
            seed,
            f_hz: [f1, f2],
            q: [q1, q2],
            lambda,
            carrier_hz: carrier,
            clock_hz: clock,
            rates_dps,
            cal_hz,
        })
    }

    /// One line of what matters about the device: mode 1, the Qs, the
    /// split in mode-1 bandwidths and the clock in carriers.
    pub fn summary(&self) -> String {
        format!(
            "f {:.4e} Q {:.0}/{:.0} split {:+.1} bw, clock/carrier {:.2}",
            self.f_hz[0],
            self.q[0],
            self.q[1],
            (self.f_hz[1] - self.f_hz[0]) * self.q[0] / self.f_hz[0],
            self.clock_hz / self.carrier_hz,
        )
    }

    /// The configuration file: required keys alone, then `extra` lines
    /// appended to `[experiment]` (e.g. "tolerance = 1e-3").
    pub fn toml(&self, extra: &str) -> String {
        format!(
            "# random device, seed {}\n[gyro]\nf1_hz = {:e}\nf2_hz = {:e}\nq1 = {:e}\nq2 = {:e}\n\
             angular_gain = {}\n[drive]\ncarrier_hz = {:e}\nclock_hz = {:e}\n\
             [experiment]\nreadout_rates_dps = {:?}\ncal_freqs_hz = {:?}\n{extra}",
            self.seed,
            self.f_hz[0],
            self.f_hz[1],
            self.q[0],
            self.q[1],
            self.lambda,
            self.carrier_hz,
            self.clock_hz,
            self.rates_dps,
            self.cal_hz,
        )
    }
}
