//! The table core's carrier spurs in the rate's passband: which of the
//! carrier words' harmonics the sampling folds next to the carrier at an
//! operating point, and the rate ripple each can put on an output.
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
//!
//! Each line ripples the demodulated output at Omega. Against a reference
//! R and an ADC signal H(f_c) D, whose product's full magnitude is M = |H
//! D R| / 2 (in-phase and quadrature: the line turns through both), a
//! reference line rho R ripples z by rho M and a drive line rho D by rho M
//! |H(f_c + Omega) / H(f_c)|, both through the output filter's gain at
//! Omega. Drive and reference read the table a `REF_PHASE` apart, so
//! their lines' phases are unrelated: the sum of the two amplitudes is
//! the bound. M and the readout scale factor come from the exact theory
//! at the identified device, so the ripple is in deg/s.

use super::Operating;
use super::predict::devices;
use crate::error::Error;
use crate::identify::Identified;
use crate::knowns::Knowns;
use crate::theory::{self, Device};
use gyrocal_regs::datapath::{CarrierProfile, PEAK, q15_product, table_product_turn};
use rustfft::{FftPlanner, num_complex::Complex};
use serde::Serialize;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::{Arc, Mutex, OnceLock};

/// Phase intervals a turn of the table core's carrier.
const TURN: u64 = 32768;

/// Butterworth corners out to which lines count: the biquad and the RC
/// pole pass less than 1 / 100 of a line beyond.
pub const SPUR_BAND_CORNERS: f64 = 10.0;

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

/// One line next to the carrier.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpurLine {
    /// Distance from the carrier (Hz, both sides folded together).
    pub offset_hz: f64,
    /// Bound on the ripple's amplitude per output at the filter's output
    /// (deg/s, peak).
    pub amplitude_dps: [f64; 2],
}

/// One line next to the carrier, its amplitude per output a fraction rho
/// of the output's full magnitude M (module header) as a mean over a
/// record leaves it ([`relative_lines_over_records`]): what the coupling's
/// uncertainty takes (`crate::coupling`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RelativeLine {
    /// Distance from the carrier (Hz, both sides folded together).
    pub offset_hz: f64,
    /// rho per output (peak), times the record's |sinc(pi offset
    /// record_s)|.
    pub rho: [f64; 2],
}

/// Points a mode bandwidth f / Q at which the drive lines' response is
/// taken from the exact theory and interpolated between (a field step on
/// a slow clock has some 1e5 lines). A Lorentzian's magnitude at its peak
/// bends as 1 - x^2 / 2, x the detuning in half-bandwidths: points 2 / 32
/// of a half-bandwidth apart interpolate within (2 / 32)^2 / 8 = 4.9e-4
/// (this module's test measures it).
const RESPONSE_GRID: f64 = 32.0;

/// Lines the report names, largest first.
pub const NAMED_LINES: usize = 8;

/// The table core's spur lines in the passband at an operating point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spurs {
    /// The lines, by offset (some thousands; not serialized).
    #[serde(skip)]
    pub lines: Vec<SpurLine>,
    /// The `NAMED_LINES` largest (by the larger output's amplitude).
    pub largest: Vec<SpurLine>,
    /// Bound on the rate's RMS ripple per output from all of them (deg/s).
    pub rms_dps: [f64; 2],
}

impl Spurs {
    /// The RMS of the lines after averaging over records of `record_s`
    /// seconds, each line's amplitude times |sinc(pi offset record_s)|.
    pub fn rms_over_records_dps(&self, record_s: f64) -> [f64; 2] {
        rms_over_records(&self.lines, record_s)
    }
}

impl std::fmt::Display for Spurs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "carrier table spurs in the passband: rate ripple at most {:.4} / {:.4} deg/s RMS",
            self.rms_dps[0], self.rms_dps[1]
        )?;
        if let Some(l) = self.largest.first() {
            write!(f, ", largest line {:.1} Hz from the carrier", l.offset_hz)?;
        }
        Ok(())
    }
}

/// The RMS of `lines` after averaging over records of `record_s` seconds,
/// each line's amplitude times |sinc(pi offset record_s)|.
fn rms_over_records(lines: &[SpurLine], record_s: f64) -> [f64; 2] {
    rms(lines.iter().map(|l| {
        let g = record_gain(l.offset_hz, record_s);
        l.amplitude_dps.map(|a| a * g)
    }))
}

/// |sinc(pi offset record_s)|: a line's amplitude in a record's mean.
fn record_gain(offset_hz: f64, record_s: f64) -> f64 {
    let x = PI * offset_hz * record_s;
    if x == 0.0 { 1.0 } else { (x.sin() / x).abs() }
}

/// Root mean square of lines of these amplitudes at distinct offsets.
fn rms(amplitudes: impl Iterator<Item = [f64; 2]>) -> [f64; 2] {
    let s = amplitudes.fold([0.0; 2], |s, a| [s[0] + a[0] * a[0], s[1] + a[1] * a[1]]);
    s.map(|v| (v / 2.0).sqrt())
}

/// The spur lines at `op` on the table core (`None` on the fine core,
/// whose rounding error is fed back away from the carrier).
pub fn spurs(knowns: &Knowns, id: &Identified, op: &Operating) -> Result<Option<Spurs>, Error> {
    let Some(lines) = spur_lines(knowns, id, op, FULL)? else {
        return Ok(None);
    };
    let rms_dps = rms(lines.iter().map(|l| l.amplitude_dps));
    // The largest by index: the lines themselves stay in offset order.
    let by_peak = |a: &usize, b: &usize| peak(&lines[*b]).total_cmp(&peak(&lines[*a]));
    let mut order: Vec<usize> = (0..lines.len()).collect();
    if order.len() > NAMED_LINES {
        order.select_nth_unstable_by(NAMED_LINES, by_peak);
        order.truncate(NAMED_LINES);
    }
    order.sort_by(by_peak);
    let largest = order.into_iter().map(|i| lines[i]).collect();
    Ok(Some(Spurs {
        lines,
        largest,
        rms_dps,
    }))
}

/// What a line's amplitude is given in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Unit {
    /// The rate ripple at the filter's output (deg/s, peak).
    Dps,
    /// The ripple at the filter's output as a fraction of the output's
    /// full magnitude M (module header).
    Relative,
}

/// The lines of [`spurs`] to `depth`, by offset.
fn spur_lines(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    depth: Depth,
) -> Result<Option<Vec<SpurLine>>, Error> {
    lines_in(
        knowns,
        id,
        op,
        depth,
        Unit::Dps,
        |offset_hz, amplitude_dps| SpurLine {
            offset_hz,
            amplitude_dps,
        },
    )
}

/// The lines at `op`, as a mean over a record of `record_s` seconds
/// leaves them (each amplitude times |sinc(pi offset record_s)|), in
/// fractions of their outputs' full magnitudes. `None` on the fine core.
pub(crate) fn relative_lines_over_records(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    record_s: f64,
) -> Result<Option<Vec<RelativeLine>>, Error> {
    lines_in(knowns, id, op, FULL, Unit::Relative, |offset_hz, rho| {
        RelativeLine {
            offset_hz,
            rho: rho.map(|a| a * record_gain(offset_hz, record_s)),
        }
    })
}

/// The lines of [`spurs`] to `depth`, by offset, each made by `line` from
/// its offset (Hz) and its amplitudes per output in `unit`.
fn lines_in<L>(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    depth: Depth,
    unit: Unit,
    line: impl Fn(f64, [f64; 2]) -> L,
) -> Result<Option<Vec<L>>, Error> {
    if knowns.carrier_profile != CarrierProfile::Table {
        return Ok(None);
    }
    let (regs, _) = knowns.registers(op.carrier_hz, None, op.amplitude, op.ref_lag_deg)?;
    let step = regs.carrier_step;
    let band = SPUR_BAND_CORNERS * knowns.filter.butterworth_hz;
    let per_step = knowns.clock_hz / 2f64.powi(32);
    let envelopes = [regs.amp.0, regs.amp.1].map(|a| i32::from(q15_product(a, PEAK as i16)));
    let spectra = envelopes.map(harmonics);
    let fundamental = [0, 1].map(|k| spectra[k][1] * sinc(1));
    let [read, _] = devices(knowns, &id.gyro(&knowns.nominal), op)?;
    let m_full = full(&read);
    let sf_dps = theory::sf_read_per_rad_s(&read).map(|s| (s * PI / 180.0).abs());
    let filter = |omega: f64| {
        let b = omega / knowns.filter.butterworth_hz;
        let r = omega / knowns.filter.rc_hz;
        1.0 / ((1.0 + b.powi(4)) * (1.0 + r * r)).sqrt()
    };
    // The drive lines' response |H(f_c + Omega)| in the full magnitude,
    // on a grid of RESPONSE_GRID points a mode bandwidth, interpolated.
    let spacing = (read.f1_hz / read.q1).min(read.f2_hz / read.q2) / RESPONSE_GRID;
    let mut grid: HashMap<i64, [f64; 2]> = HashMap::new();
    let mut at_grid = |i: i64| -> [f64; 2] {
        *grid.entry(i).or_insert_with(|| {
            full(&Device {
                carrier_hz: op.carrier_hz + i as f64 * spacing,
                ..read.clone()
            })
        })
    };
    let mut found: Vec<(u32, [f64; 2])> = candidates(step, (band / per_step) as u32, depth)
        .into_iter()
        .map(|(m, side)| {
            let omega = f64::from(side) * per_step;
            let x = omega / spacing;
            let i = x.floor() as i64;
            let (lo, hi, w) = (at_grid(i), at_grid(i + 1), x - x.floor());
            let m_moved: [f64; 2] = std::array::from_fn(|k| lo[k] + w * (hi[k] - lo[k]));
            let g = filter(omega.abs());
            let amp = std::array::from_fn(|k| {
                let rho = spectra[k][(m % TURN) as usize] * sinc(m) / fundamental[k];
                match unit {
                    Unit::Dps => m_full[k] * rho * (1.0 + m_moved[k] / m_full[k]) * g / sf_dps[k],
                    Unit::Relative => rho * (1.0 + m_moved[k] / m_full[k]) * g,
                }
            });
            (side.unsigned_abs(), amp)
        })
        .collect();
    // Lines by |offset| in NCO steps: the two sides of a fold and the
    // drive's and reference's lines at one offset add.
    found.sort_unstable_by_key(|f| f.0);
    let mut lines: Vec<(f64, [f64; 2])> = Vec::new();
    for (s, amp) in found {
        let offset_hz = f64::from(s) * per_step;
        match lines.last_mut() {
            Some((at, sum)) if *at == offset_hz => {
                sum[0] += amp[0];
                sum[1] += amp[1];
            }
            _ => lines.push((offset_hz, amp)),
        }
    }
    Ok(Some(lines.into_iter().map(|(o, a)| line(o, a)).collect()))
}

/// The bound of [`spurs`] alone, its RMS per output (deg/s), over the
/// images `depth` counts.
pub fn spur_rms(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    depth: Depth,
) -> Result<Option<[f64; 2]>, Error> {
    Ok(spur_lines(knowns, id, op, depth)?.map(|lines| rms(lines.iter().map(|l| l.amplitude_dps))))
}

/// A line's larger amplitude of the two outputs.
fn peak(l: &SpurLine) -> f64 {
    l.amplitude_dps[0].max(l.amplitude_dps[1])
}

/// The demodulated outputs' full magnitude at rest (in-phase and
/// quadrature), per output, from the exact theory.
fn full(dev: &Device) -> [f64; 2] {
    let (i, q) = (
        theory::readout_z_lagged(dev, 0.0, 0.0),
        theory::readout_z_lagged(dev, 0.0, FRAC_PI_2),
    );
    [i[0].hypot(q[0]), i[1].hypot(q[1])]
}

/// |D_m| for m < N of the table core's words for envelope `e`
/// (`datapath::table_product_turn`), by one transform, kept for the
/// process (a drive's envelope is one of a few).
fn harmonics(e: i32) -> Arc<Vec<f64>> {
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
fn sinc(m: u64) -> f64 {
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
/// steps; the line at -step + delta is the carrier's at -delta).
fn candidates(step: u32, reach: u32, depth: Depth) -> Vec<(u64, i32)> {
    let near = |m: u64| -> Option<i32> {
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
    };
    let fundamental = (1..depth.0).flat_map(|k| [k * TURN - 1, k * TURN + 1]);
    // Odd harmonics only: the turn's second half is the first negated.
    let others = (3..TURN - 1)
        .step_by(2)
        .flat_map(move |m0| (0..depth.1).map(move |k| m0 + k * TURN));
    fundamental
        .chain(others)
        .filter_map(|m| near(m).map(|s| (m, s)))
        .collect()
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

    /// `RESPONSE_GRID`'s premise: between grid points 1 / 32 of a mode
    /// bandwidth apart, the full magnitude interpolates within 5e-4, on
    /// the paper device driven at mode 1 (output 1 on its resonance,
    /// output 2 250 Hz off it), over two bandwidths either side.
    #[test]
    fn the_response_interpolates_within_5e_4_between_grid_points() {
        let dev = Device {
            f1_hz: 9.64e6,
            f2_hz: 9.640_25e6,
            q1: 55000.0,
            q2: 55000.0,
            angular_gain: 0.6,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
            carrier_hz: 9.64e6,
            f1_force: 1.0,
            f2_force: 1.0,
        };
        let spacing = dev.f1_hz / dev.q1 / RESPONSE_GRID;
        let at = |x: f64| {
            full(&Device {
                carrier_hz: dev.carrier_hz + x * spacing,
                ..dev.clone()
            })
        };
        let mut worst = 0.0f64;
        for i in -64..64 {
            let (lo, hi) = (at(f64::from(i)), at(f64::from(i + 1)));
            for w in [0.25, 0.5, 0.75] {
                let exact = at(f64::from(i) + w);
                for k in 0..2 {
                    let lerp = lo[k] + w * (hi[k] - lo[k]);
                    worst = worst.max((lerp / exact[k] - 1.0).abs());
                }
            }
        }
        eprintln!("worst interpolation error {worst:.2e}");
        assert!(worst < 5e-4, "{worst}");
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
}
