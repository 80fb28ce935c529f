//! The carriers' slow error at one clock and carrier, for the built table
//! and for the profiles a larger part could hold.
//!
//! ```sh
//! cargo run --release --example carrier_profiles -- 50e6 9638553.9975
//! ```
//!
//! A carrier near `n / q` of the clock shows the tables only `q` phases
//! at a time, drifting slowly, so the lookup's errors at those phases do
//! not average out at once: they come back as an error of the carrier's
//! own amplitude and phase that wanders at the fold's rate, inside the
//! output filter's band (docs/field.md, "The ripple on the calibrated
//! rate"). This prints, for the drive sine `32767 sin(phase)` of each
//! profile, that error's baseband: the error against the exact sine,
//! projected on the carrier (I and Q, in LSB), averaged over blocks of
//! `BLOCK_S` (1 ms, a 500 Hz output's scale), and the RMS of the block
//! means about their mean, |I + jQ|. It is what the rate ripples with:
//! on the paper device at 30 deg C the profiles rank as the field's rate
//! RMS error does (the table in docs/field.md).
//!
//! Profiles: `built` is the gateware's (2^15 phases a turn, the power-up
//! fill's words, `gyrocal_hdl::model::carrier_nco`). The others are
//! `T/E/F`: a table of 2^T interval centres a turn whose words carry F
//! fractional bits (`round(32767 sin * 2^F) / 2^F`), E more phase bits
//! interpolated to first order (`+ delta * d_phase * cos`, the cosine
//! word of the same table), one rounding to the integer output at the
//! end; `exact` rounds `32767 sin` of the whole 32-bit phase.
//!
//! The last rows are the DAC words themselves, F x carrier as the cores'
//! mixers make them clock by clock at the default envelope F = 0.9
//! (29490), scaled back by 32768 / F (the model's
//! `gyrocal_hdl::model::am_mixer::CarrierMultiplier`): the table core
//! rounds its 16-bit carrier and then the product
//! (`gyrocal_hdl::am_mixer::AmMixer`), a second rounding at the carrier
//! rate, with a slow error of its own at a fold; the fine core rounds the
//! pair's quarter-LSB carrier times F once and feeds that rounding's error
//! back with zeros at the carrier (`FineAmMixer`), so only the pair's own
//! error stays.

use gyrocal_hdl::model::am_mixer::{CarrierMultiplier, carrier_fraction_bits};
use gyrocal_hdl::model::carrier_nco::{carrier_word, table, table_sine};
use gyrocal_hdl::model::notch_coefficient::NotchCoefficient;
use gyrocal_hdl::model::sine_pair::sine_pair;
use gyrocal_regs::datapath::CarrierProfile;
use std::f64::consts::TAU;

/// The averaging block (s): a 500 Hz output's time scale.
const BLOCK_S: f64 = 1e-3;
/// The span analysed (s).
const SPAN_S: f64 = 0.2;

/// A carrier profile: how `32767 sin` of a 32-bit phase is made.
#[derive(Clone, Copy)]
enum Profile {
    Built,
    Pair,
    Table {
        bits: u32,
        interpolated: u32,
        fraction: i32,
    },
    Exact,
    /// The DAC word at envelope `F` of a core, scaled back by 32768 / F.
    Dac(CarrierProfile, i16),
}

impl Profile {
    fn name(self) -> String {
        match self {
            Profile::Built => "built (15/0, fill words)".into(),
            Profile::Pair => "sine pair (15/3/2, ECP5)".into(),
            Profile::Table {
                bits,
                interpolated,
                fraction,
            } => {
                format!("{bits}/{interpolated}/{fraction}")
            }
            Profile::Exact => "exact (32-bit phase)".into(),
            Profile::Dac(core, f) => format!("{core} core, DAC word at F = {f}"),
        }
    }

    fn sine(self, phase: u32) -> f64 {
        match self {
            Profile::Built => f64::from(table_sine(table(), phase, 0)),
            // The pair's output is in quarter LSB.
            Profile::Pair => f64::from(sine_pair(phase).1) / 4.0,
            Profile::Dac(..) => unreachable!("a core's DAC words are a stream: `Profile::words`"),
            Profile::Exact => (32767.0 * (f64::from(phase) / 2f64.powi(32) * TAU).sin()).round(),
            Profile::Table {
                bits,
                interpolated,
                fraction,
            } => {
                let scale = 2f64.powi(fraction);
                let interval = TAU / 2f64.powi(bits as i32);
                let index = phase >> (32 - bits);
                let centre = (f64::from(index) + 0.5) * interval;
                let word = |x: f64| (32767.0 * x * scale).round() / scale;
                let (s, c) = (word(centre.sin()), word(centre.cos()));
                if interpolated == 0 {
                    return s.round();
                }
                let below = 32 - bits - interpolated;
                let sub = (phase >> below) & ((1 << interpolated) - 1);
                let delta = (f64::from(sub) + 0.5) / 2f64.powi(interpolated as i32) - 0.5;
                (s + delta * interval * c).round()
            }
        }
    }

    /// The profile's sine at the phases `0, step, 2 step, ...`, called in
    /// that order.
    fn words(self, step: u32) -> Box<dyn FnMut(u32) -> f64> {
        let Profile::Dac(core, f) = self else {
            return Box::new(move |phase| self.sine(phase));
        };
        // The carrier product's words leave two edges after their factors:
        // run the carriers two steps ahead of the phase asked for.
        let mut product = CarrierMultiplier::new(carrier_fraction_bits(core));
        let mut notch = NotchCoefficient::default();
        let mut feed = move |phase: u32| {
            let sin = carrier_word(core, phase);
            let cos = carrier_word(core, phase.wrapping_add(1 << 30));
            let k = notch.output();
            notch.step(cos, sin);
            product.step(f, sin, k)
        };
        feed(0);
        feed(step);
        Box::new(move |phase| {
            f64::from(feed(phase.wrapping_add(step.wrapping_mul(2)))) * 32768.0 / f64::from(f)
        })
    }
}

/// RMS of the block means of the error's baseband about their mean (LSB).
fn slow_error(profile: Profile, step: u32, clock_hz: f64) -> f64 {
    let mut sine = profile.words(step);
    let block = (BLOCK_S * clock_hz).round() as usize;
    let blocks = (SPAN_S / BLOCK_S) as usize;
    let mut means = Vec::with_capacity(blocks);
    let mut phase = 0u32;
    for _ in 0..blocks {
        let (mut i, mut q) = (0.0, 0.0);
        for _ in 0..block {
            let angle = f64::from(phase) / 2f64.powi(32) * TAU;
            let error = sine(phase) - 32767.0 * angle.sin();
            i += error * angle.sin();
            q += error * angle.cos();
            phase = phase.wrapping_add(step);
        }
        means.push((2.0 * i / block as f64, 2.0 * q / block as f64));
    }
    let n = means.len() as f64;
    let (mi, mq) = means
        .iter()
        .fold((0.0, 0.0), |a, m| (a.0 + m.0 / n, a.1 + m.1 / n));
    (means
        .iter()
        .map(|m| (m.0 - mi).powi(2) + (m.1 - mq).powi(2))
        .sum::<f64>()
        / n)
        .sqrt()
}

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse::<f64>())
        .collect::<Result<_, _>>()
        .unwrap_or_default();
    let [clock_hz, carrier_hz] = args[..] else {
        eprintln!(
            "usage: carrier_profiles CLOCK_HZ CARRIER_HZ (two positive numbers, the carrier below half the clock)"
        );
        std::process::exit(2);
    };
    if !(clock_hz > 0.0 && carrier_hz > 0.0 && carrier_hz < clock_hz / 2.0) {
        eprintln!(
            "clock {clock_hz} Hz, carrier {carrier_hz} Hz: both must be positive and the carrier below half the clock"
        );
        std::process::exit(2);
    }
    let step = (carrier_hz / clock_hz * 2f64.powi(32)).round() as u32;
    println!(
        "clock {clock_hz} Hz, carrier {carrier_hz} Hz (step {step}); slow error, RMS of {BLOCK_S} s means over {SPAN_S} s, LSB of 32767:"
    );
    let table = |bits, interpolated, fraction| Profile::Table {
        bits,
        interpolated,
        fraction,
    };
    let profiles = [
        Profile::Built,
        table(15, 0, 0),
        table(16, 0, 0),
        table(17, 0, 0),
        table(18, 0, 0),
        table(15, 3, 0),
        table(15, 1, 1),
        table(15, 3, 1),
        table(15, 3, 2),
        table(15, 3, 3),
        Profile::Pair,
        Profile::Exact,
        Profile::Dac(CarrierProfile::Table, 29490),
        Profile::Dac(CarrierProfile::Fine, 29490),
    ];
    for p in profiles {
        println!("{:>28}  {:.4}", p.name(), slow_error(p, step, clock_hz));
    }
}
