//! The table core's carrier words as lines: which harmonics of the held
//! words a carrier step samples next to the carrier, and each one's size
//! against the fundamental. Both the operating point's spur bound
//! (`selfcal::spurs`) and identification's fine sweep
//! (`identify::spurs`) read them; this module imports neither.
//!
//! A table-core word is `round(E T(phase) / 2^15)`, T the 8192-word
//! quarter-wave table: a function of the phase, held over each of the
//! turn's N = 32768 intervals (`datapath::table_product_turn`). With D_m
//! the transform of those N words, the held words' harmonic m + kN is
//! (-1)^k D_m sinc(pi (m + kN) / N) for m < N; only odd harmonics exist
//! (the turn's second half is its first negated). Harmonic m is sampled
//! at m times the carrier's step, so it lands Omega from the carrier when
//! m step = +-step + Omega (mod 2^32). That is the fold of
//! `plan::nearest_fold` seen harmonic by harmonic: near n / q of the clock
//! the harmonics kq +- 1 land k eps from the carrier.

use crate::knowns::Derived;
use gyrocal_regs::datapath::table_product_turn;
use rustfft::{FftPlanner, num_complex::Complex};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// Phase intervals a turn of the table core's carrier.
const TURN: u64 = 32768;

/// Images m + kN of each odd harmonic m < N looked at, k below this. The
/// words' error other than the fundamental has a power P = mean(w^2) -
/// 2 |D_1|^2 (0.19 LSB^2 at E = 29490, this module's test), and an image k
/// keeps sinc^2 <= 1 / (pi k)^2 of its harmonic: all images beyond k =
/// 1024 carry at most P / (1023 pi^2), 1.9e-5 LSB^2, spread over the
/// whole band the clock folds, of which a passband of 1 kHz on 50 MHz
/// takes 2e-5 on average: 2e-5 LSB RMS, 1.3e-9 of the fundamental.
const IMAGES: u64 = 1024;

/// Images kN -+ 1 of the fundamental looked at: the k-th is 1 / (N k) of
/// it (the phase rounding's sawtooth), and those beyond k = 2^20 are below
/// 3e-11 of it each.
const FUNDAMENTAL_IMAGES: u64 = 1 << 20;

/// Butterworth corners out to which lines count: the biquad and the RC
/// pole pass less than 1 / 100 of a line beyond.
pub const SPUR_BAND_CORNERS: f64 = 10.0;

/// The output filter's gain at `omega_hz` from DC: the second-order
/// Butterworth's and the RC pole's magnitudes (`filter`'s design).
pub(crate) fn output_gain(filter: &Derived, omega_hz: f64) -> f64 {
    let b = omega_hz / filter.butterworth_hz;
    let r = omega_hz / filter.rc_hz;
    1.0 / ((1.0 + b.powi(4)) * (1.0 + r * r)).sqrt()
}

/// |sinc(pi offset record_s)|: a line's amplitude in a record's mean.
pub(crate) fn record_gain(offset_hz: f64, record_s: f64) -> f64 {
    let x = PI * offset_hz * record_s;
    if x == 0.0 { 1.0 } else { (x.sin() / x).abs() }
}

/// |D_m| for m < N of the table core's words for envelope `e`
/// (`datapath::table_product_turn`), by one transform, kept for the
/// process (a drive's envelope is one of a few).
pub(crate) fn harmonics(e: i32) -> Arc<Vec<f64>> {
    static KEPT: OnceLock<Mutex<HashMap<i32, Arc<Vec<f64>>>>> = OnceLock::new();
    let kept = KEPT.get_or_init(Default::default);
    if let Some(h) = kept.lock().expect("not poisoned").get(&e) {
        return h.clone();
    }
    let mut words: Vec<Complex<f64>> = table_product_turn(e)
        .into_iter()
        .map(|w| Complex::new(w, 0.0))
        .collect();
    FftPlanner::new()
        .plan_fft_forward(words.len())
        .process(&mut words);
    let n = words.len() as f64;
    let h = Arc::new(words.iter().map(|c| c.norm() / n).collect());
    kept.lock().expect("not poisoned").insert(e, Arc::clone(&h));
    h
}

/// |sinc(pi m / N)|: a held word's harmonic m against its sample's.
pub(crate) fn sinc(m: u64) -> f64 {
    let x = PI * m as f64 / TURN as f64;
    (x.sin() / x).abs()
}

/// How many images `candidates` looks at: (the fundamental's, the
/// other harmonics').
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Depth(u64, u64);

/// The whole bound: `FUNDAMENTAL_IMAGES` and `IMAGES`.
pub const FULL: Depth = Depth(FUNDAMENTAL_IMAGES, IMAGES);

/// The ranking of carriers in a search (`selfcal::operating`): the
/// fundamental's first 4096 images (the k-th 1 / (N k) of it) and the
/// others' first four, 1 / 100 of the full enumeration's work. The
/// images left out are those the full bound's constants bound as small;
/// the carrier chosen is then reported with the full bound.
pub const SEARCH: Depth = Depth(1 << 12, 4);

/// Harmonics m >= 2 (the fundamental's images to `depth.0`, the others'
/// to `depth.1`) that the carrier step `step` samples within `reach`
/// steps of +-step, each with its signed offset from the carrier (NCO
/// steps; the line at -step + delta is the carrier's at -delta), in the
/// order of m's enumeration: the fundamental's images kN -+ 1 by k, then
/// each odd m0 < N's images m0 + kN by k.
///
/// Every image of m0 is sampled at a + k S, a = m0 step and S = N step
/// (wrapping): S's low 15 bits are zero, so the image's top 17 bits step
/// by s = step mod 2^17 and its low 15 bits are a's. Only the top-17-bit
/// values of the two windows of +-`reach` around +-step can land there,
/// and each one's k solves h0 + k s = h (mod 2^17) directly
/// ([`images_within`]): some hundred values a harmonic instead of its
/// 1024 images (the brute enumeration was a fifth of a field step on a
/// slow clock). The test holds it to the brute enumeration, pair for pair.
pub(crate) fn candidates(step: u32, reach: u32, depth: Depth) -> Vec<(u64, i32)> {
    let mut found = vec![];
    let mut keep = |m: u64| {
        if let Some(s) = near(step, reach, m) {
            found.push((m, s));
        }
    };
    // kN - 1 is sampled at -step + k S, kN + 1 at step + k S.
    let mut ks = images_within(step.wrapping_neg(), step, reach, 1..depth.0);
    ks.extend(images_within(step, step, reach, 1..depth.0));
    ks.sort_unstable();
    ks.dedup();
    for k in ks {
        keep(k * TURN - 1);
        keep(k * TURN + 1);
    }
    // Odd harmonics only: the turn's second half is the first negated.
    for m0 in (3..TURN - 1).step_by(2) {
        let a = (m0 as u32).wrapping_mul(step);
        for k in images_within(a, step, reach, 0..depth.1) {
            keep(m0 + k * TURN);
        }
    }
    found
}

/// Harmonic m's signed offset from the carrier (NCO steps) when the
/// carrier step `step` samples it within `reach` of +-step.
fn near(step: u32, reach: u32, m: u64) -> Option<i32> {
    let nu = (m as u32).wrapping_mul(step);
    let above = nu.wrapping_sub(step) as i32;
    let below = nu.wrapping_add(step) as i32;
    if above.unsigned_abs() <= reach {
        Some(above)
    } else if below.unsigned_abs() <= reach {
        Some(-below)
    } else {
        None
    }
}

/// Top 17 bits of a 32-bit phase.
const TOP: u32 = (1 << 17) - 1;

/// The k of `ks`, ascending, whose image a + k S (S = `step` << 15,
/// wrapping) may lie within `reach` of +-`step`: every k that does, and
/// some that only share its top 17 bits with such a phase ([`candidates`]
/// tests each exactly).
fn images_within(a: u32, step: u32, reach: u32, ks: std::ops::Range<u64>) -> Vec<u64> {
    let all = || ks.clone().collect();
    let s = step & TOP;
    if s == 0 || reach >= 1 << 30 {
        return all();
    }
    // The top-17-bit values of each window [c - reach, c + reach].
    let windows = [step, step.wrapping_neg()].map(|c| {
        let low = c.wrapping_sub(reach) >> 15;
        let count = ((c.wrapping_add(reach) >> 15).wrapping_sub(low) & TOP) + 1;
        (low, count)
    });
    // s = 2^e u, u odd: h0 + k s = h has a solution iff 2^e divides
    // h - h0, and then one k in each period 2^(17 - e).
    let e = s.trailing_zeros();
    let period = 1u64 << (17 - e);
    let per_target = ks.end.div_ceil(period);
    let targets: u64 = windows.iter().map(|w| u64::from(w.1)).sum();
    if targets * per_target >= ks.end - ks.start {
        return all();
    }
    let inverse = odd_inverse(s >> e);
    let h0 = a >> 15;
    let mut found = vec![];
    for (low, count) in windows {
        for i in 0..count {
            let d = (low.wrapping_add(i).wrapping_sub(h0)) & TOP;
            if d & ((1 << e) - 1) != 0 {
                continue;
            }
            let first = (u64::from(d >> e) * u64::from(inverse)) & (period - 1);
            found.extend(
                (first..ks.end)
                    .step_by(period as usize)
                    .filter(|k| *k >= ks.start),
            );
        }
    }
    found.sort_unstable();
    found.dedup();
    found
}

/// The inverse of odd `u` modulo 2^32 (Newton's iteration, each step
/// doubling the bits that are right: 3, 6, 12, 24, 48).
fn odd_inverse(u: u32) -> u32 {
    let mut x = u;
    for _ in 0..4 {
        x = x.wrapping_mul(2u32.wrapping_sub(u.wrapping_mul(x)));
    }
    x
}

/// Harmonic m's line against the fundamental of the words whose
/// [`harmonics`] are `spectrum`: |D_(m mod N)| sinc(pi m / N) over |D_1|
/// sinc(pi / N).
pub(crate) fn relative(spectrum: &[f64], m: u64) -> f64 {
    spectrum[(m % TURN) as usize] * sinc(m) / (spectrum[1] * sinc(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrocal_regs::plan::nearest_fold;

    /// `IMAGES`' premise: the words' power outside the fundamental, P =
    /// mean(w^2) - 2 |D_1|^2, at the envelopes the field scenarios drive
    /// (0.9 of full scale and the smallest, 65). The table's own words
    /// carry 0.37 LSB RMS against the centre sines (`carrier_table_fill`)
    /// and the product's rounding 0.29 (1 / 12 LSB^2): P is at most their
    /// powers' sum, 0.22 LSB^2. Measured 0.19 and 0.08.
    #[test]
    fn the_words_error_power_is_what_the_image_count_assumes() {
        for e in [29490, 65] {
            let words = table_product_turn(e);
            let n = words.len() as f64;
            let power = words.iter().map(|w| w * w).sum::<f64>() / n;
            let d1 = harmonics(e)[1];
            let p = power - 2.0 * d1 * d1;
            eprintln!("E = {e}: P = {p:.4} LSB^2");
            assert!((0.0..0.22).contains(&p), "E = {e}: P = {p}");
        }
    }

    /// A carrier near n / q of the clock: harmonics kq -+ 1 land k eps
    /// from it (`plan::nearest_fold`), the odd ones among them (for q odd,
    /// even k) are the candidates. The paper device's 30 deg C carrier on
    /// 50 MHz, near 16 / 83.
    #[test]
    fn a_folds_harmonics_land_at_multiples_of_its_offset() {
        let clock = 50e6;
        let step = (9_638_553.73 / clock * 2f64.powi(32)).round() as u32;
        let carrier = f64::from(step) * clock / 2f64.powi(32);
        let (q, eps) = nearest_fold(carrier, clock);
        assert_eq!(q, 83);
        let per_step = clock / 2f64.powi(32);
        let found = candidates(step, (1000.0 / per_step) as u32, FULL);
        for k in 1..=12u64 {
            for m in [k * q - 1, k * q + 1].into_iter().filter(|m| m % 2 == 1) {
                let omega = found
                    .iter()
                    .find(|c| c.0 == m)
                    .map(|c| f64::from(c.1.unsigned_abs()) * per_step);
                let expected = k as f64 * eps;
                assert_eq!(
                    omega.map(|o| (o - expected).abs() < 1e-3),
                    (expected <= 1000.0).then_some(true),
                    "harmonic {m}: {omega:?} Hz, expected {expected} Hz"
                );
            }
        }
    }

    /// The brute enumeration `candidates` replaced: every image tested.
    fn candidates_by_brute_force(step: u32, reach: u32, depth: Depth) -> Vec<(u64, i32)> {
        let fundamental = (1..depth.0).flat_map(|k| [k * TURN - 1, k * TURN + 1]);
        let others = (3..TURN - 1)
            .step_by(2)
            .flat_map(move |m0| (0..depth.1).map(move |k| m0 + k * TURN));
        fundamental
            .chain(others)
            .filter_map(|m| near(step, reach, m).map(|s| (m, s)))
            .collect()
    }

    /// `candidates` finds what testing every image finds, in the same
    /// order: on the carriers of the field scenarios' clocks (the paper's
    /// 30 deg C carrier on 50 MHz, the consumer's on 1.2345 MHz), a step
    /// exactly on a fold (of period 64: s = 0, every image shares a's top
    /// bits), steps whose low bits are zero (s = 2^e u, e up to 15),
    /// reaches from one step to 2^30, and 60 random steps and reaches,
    /// at the search's depth and the full one.
    #[test]
    fn candidates_are_the_brute_enumerations() {
        use rand_xoshiro::Xoshiro256PlusPlus;
        use rand_xoshiro::rand_core::{Rng, SeedableRng};
        let of = |f: f64, clock: f64| (f / clock * 2f64.powi(32)).round() as u32;
        let mut cases = vec![
            (
                of(9_638_553.73, 50e6),
                (1000.0 / (50e6 / 2f64.powi(32))) as u32,
            ),
            (
                of(25_028.5, 1.2345e6),
                (480.0 / (1.2345e6 / 2f64.powi(32))) as u32,
            ),
            (3 << 26, 1 << 20),
            (0x8000_0000 / 24, 5000),
            (0x1234_0000, 1 << 18),
            (0x0002_0000 * 7, 1 << 16),
            (0x0001_8000, 1),
            (0x7fff_ffff, 1 << 30),
        ];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        for _ in 0..60 {
            let reach = 1u32 << (rng.next_u32() % 26);
            cases.push((rng.next_u32(), reach + rng.next_u32() % reach));
        }
        for (step, reach) in cases {
            for depth in [SEARCH, FULL] {
                assert_eq!(
                    candidates(step, reach, depth),
                    candidates_by_brute_force(step, reach, depth),
                    "step {step:#x}, reach {reach}, {depth:?}"
                );
            }
        }
    }
}
