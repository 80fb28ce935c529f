//! Bit-true model of `crate::carrier_nco::CarrierNco`, with its table fill
//! (`crate::carrier_table_fill`) and table sines (`crate::table_sine`).
//!
//! The table the hardware writes at power-up is built here once per
//! process from the sine generator's model (`super::sine::sine` at the ROM
//! interval centres, interpolated as the header of
//! `crate::carrier_table_fill` says): a fill that wrote other words, or
//! wrote them elsewhere, shows as a carrier mismatch. The model tracks only the fill's
//! progress (`fill_request` for the modulation NCO, and when the lookups
//! go live).
//!
//! With `CarrierProfile::Fine` it models `crate::fine_carrier_nco` instead:
//! the sines are `super::sine_pair`'s, nothing is filled (no request to the
//! modulation NCO), and the outputs go live at the same cycle.

use super::delay_ring::DelayRing;
use super::sine::sine;
use super::sine_pair::sine_pair;
use crate::carrier_table_fill::{FILL_CLOCKS, REQUESTS, rom_entry_phase};
use crate::quarter_wave::{PHASE_BELOW_INDEX, TABLE_ENTRIES};
use crate::table_sine::LATENCY;
use gyrocal_regs::datapath::CarrierProfile;
use std::sync::OnceLock;

/// The carriers' quarter-wave table: entry i is the sine at the centre of
/// interval i of 8192, interpolated from the sine generator's ROM words.
pub type Table = [i16; TABLE_ENTRIES];

/// The table the power-up fill writes, built once per process.
pub fn table() -> &'static Table {
    static TABLE: OnceLock<Box<Table>> = OnceLock::new();
    TABLE.get_or_init(|| Box::new(std::array::from_fn(entry)))
}

/// The carriers' table unfolded to a whole turn as (sine, cosine) pairs:
/// word `j` is `table_sine(table(), phase, 0)` and `(.., 1)` at the phase
/// `j << PHASE_BELOW_INDEX`. The words of a phase depend only on its top
/// `32 - PHASE_BELOW_INDEX` bits, so the four carriers of a clock are two
/// reads (`table_carriers`) instead of four lookups with the quadrant's
/// mirror and sign: the model's shortcut, not the hardware's (which stores
/// the quarter), equal word for word (a test reads every phase interval
/// both ways).
pub type Pairs = [(i16, i16); 4 * TABLE_ENTRIES];

/// The pairs, built once per process from `table()`.
pub fn pairs() -> &'static Pairs {
    static PAIRS: OnceLock<Box<Pairs>> = OnceLock::new();
    PAIRS.get_or_init(|| {
        let t = table();
        Box::new(std::array::from_fn(|j| {
            let phase = (j << PHASE_BELOW_INDEX) as u32;
            (table_sine(t, phase, 0), table_sine(t, phase, 1))
        }))
    })
}

/// Carrier table entry `i`: a quarter of a ROM step from ROM centre i / 2,
/// weights 3 : 1 towards it, rounded half to even.
fn entry(i: usize) -> i16 {
    let rom = |k: i32| i32::from(sine(rom_entry_phase(k), 0));
    let j = (i / 2) as i32;
    let (near, far) = if i.is_multiple_of(2) {
        (rom(j), rom(j - 1))
    } else {
        (rom(j), rom(j + 1))
    };
    let sum = 3 * near + far;
    ((sum + 1 + ((sum >> 2) & 1)) >> 2) as i16
}

/// `32767 sin` of a 32-bit phase plus `advance` quarter turns, as
/// `crate::table_sine::TableSine` looks it up in `table`.
#[inline(always)]
pub fn table_sine(table: &Table, phase: u32, advance: u8) -> i16 {
    super::quarter_wave::lookup(phase, advance, |index| table[index])
}

/// The drive sine word of the core with this profile at a 32-bit phase,
/// in `Carriers`' scale: the table core's 16-bit word or the fine core's
/// quarter-LSB one (`CarrierNco::step` makes the same words, four at a
/// time). The cosine is the same word a quarter turn on.
pub fn carrier_word(profile: CarrierProfile, phase: u32) -> i32 {
    match profile {
        CarrierProfile::Table => table_sine(table(), phase, 0).into(),
        CarrierProfile::Fine => sine_pair(phase).1,
    }
}

/// Outputs of the carrier NCO during one cycle: 16-bit words (peak
/// 32767) from the table core, 18-bit quarter-LSB words (peak 4 x 32767)
/// from the fine core.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Carriers {
    /// In-phase drive carrier.
    pub drive_cos: i32,
    /// Quadrature drive carrier.
    pub drive_sin: i32,
    /// In-phase reference carrier.
    pub ref_cos: i32,
    /// Quadrature reference carrier.
    pub ref_sin: i32,
}

/// Cycle-true model of the carrier NCO.
#[derive(Clone, Debug)]
pub struct CarrierNco {
    phase: u32,
    /// The fill counter: cycles since power-up, stopped at `FILL_CLOCKS`.
    count: u16,
    /// Outputs in flight.
    pipe: DelayRing<Carriers, LATENCY>,
    pairs: &'static Pairs,
    profile: CarrierProfile,
}

impl Default for CarrierNco {
    fn default() -> Self {
        Self::new(CarrierProfile::Table)
    }
}

impl CarrierNco {
    /// The carrier NCO of the core with this profile, at power-up.
    pub fn new(profile: CarrierProfile) -> Self {
        Self {
            phase: 0,
            count: 0,
            pipe: DelayRing::default(),
            pairs: pairs(),
            profile,
        }
    }

    /// The outputs during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> Carriers {
        self.pipe.output()
    }

    /// The phase the fill asks the modulation NCO's sine generator for
    /// during the current cycle, while it needs it.
    #[inline(always)]
    pub fn fill_request(&self) -> Option<u32> {
        let count = self.count as usize;
        (self.profile == CarrierProfile::Table && count < REQUESTS)
            .then(|| rom_entry_phase(count as i32 / 2 - 1))
    }

    /// One clock with the given step and reference offset; outputs after the edge.
    #[inline(always)]
    pub fn step(&mut self, step: u32, ref_offset: u32) -> Carriers {
        let live = self.count as usize == FILL_CLOCKS;
        let entering = if live {
            let reference = self.phase.wrapping_add(ref_offset);
            match self.profile {
                CarrierProfile::Table => table_carriers(self.pairs, self.phase, reference),
                CarrierProfile::Fine => {
                    let ((drive_cos, drive_sin), (ref_cos, ref_sin)) =
                        (sine_pair(self.phase), sine_pair(reference));
                    Carriers {
                        drive_cos,
                        drive_sin,
                        ref_cos,
                        ref_sin,
                    }
                }
            }
        } else {
            self.count += 1;
            Carriers::default()
        };
        self.phase = self.phase.wrapping_add(step);
        self.pipe.step(entering)
    }

    /// True when `block` may play the next clocks: the table core, its
    /// table filled.
    #[inline(always)]
    pub fn blocks(&self) -> bool {
        self.profile == CarrierProfile::Table && self.count as usize == FILL_CLOCKS
    }

    /// The carriers during the next `out.len()` cycles, then as many edges
    /// with `step` and `ref_offset` held: the same as `output` and `step`
    /// clock by clock, where `blocks()`. The phase at edge k is the
    /// arithmetic sequence `phase + k step`, so the lookups of a block
    /// carry no dependence from clock to clock.
    #[inline(always)]
    pub fn block(&mut self, step: u32, ref_offset: u32, out: &mut [Carriers]) {
        let entering = self.entering(step, ref_offset);
        self.play(step, out, entering);
    }

    /// The words entering the pipeline at edge k of the next clocks with
    /// `step` and `ref_offset` held, where `blocks()`: the four table
    /// words at `phase + k step`. A caller may look them up ahead, beside
    /// other work, and play the block with them (`block_entered`).
    #[inline(always)]
    pub fn entering(&self, step: u32, ref_offset: u32) -> impl Fn(usize) -> Carriers + use<> {
        debug_assert!(self.blocks());
        let (pairs, phase) = (self.pairs, self.phase);
        move |k| {
            let drive = phase.wrapping_add(step.wrapping_mul(k as u32));
            table_carriers(pairs, drive, drive.wrapping_add(ref_offset))
        }
    }

    /// `block` with the words `entering` gives looked up ahead:
    /// `entered[k]` for edge k, at least `out.len()` of them.
    #[inline(always)]
    pub fn block_entered(&mut self, step: u32, entered: &[Carriers], out: &mut [Carriers]) {
        debug_assert!(self.blocks() && entered.len() >= out.len());
        self.play(step, out, |k| entered[k]);
    }

    /// The block's pipeline with `entering(k)` entering at edge k, and the
    /// phase moved on by its edges.
    #[inline(always)]
    fn play(&mut self, step: u32, out: &mut [Carriers], entering: impl Fn(usize) -> Carriers) {
        self.pipe.block(out, entering);
        self.phase = self.phase.wrapping_add(step.wrapping_mul(out.len() as u32));
    }
}

/// The table core's four carrier words at the drive and reference phases:
/// `table_sine` at advance 1 (cosine) and 0 (sine) of each, read as pairs.
#[inline(always)]
fn table_carriers(p: &Pairs, drive: u32, reference: u32) -> Carriers {
    let pair = |phase: u32| p[(phase >> PHASE_BELOW_INDEX) as usize & (4 * TABLE_ENTRIES - 1)];
    let ((drive_sin, drive_cos), (ref_sin, ref_cos)) = (pair(drive), pair(reference));
    Carriers {
        drive_cos: drive_cos.into(),
        drive_sin: drive_sin.into(),
        ref_cos: ref_cos.into(),
        ref_sin: ref_sin.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::am_mixer::carrier_product;
    use crate::sine_table::PEAK;
    use gyrocal_regs::datapath::{
        CarrierProfile::{Fine, Table},
        calibration_word, carrier_table_word, q15_product, readout_word,
    };

    /// The pairs the block reads are, at every phase interval of a turn,
    /// the quarter table's sine and cosine (advance 0 and 1).
    #[test]
    fn the_pairs_are_the_quarter_tables_sine_and_cosine() {
        let (quarter, p) = (table(), pairs());
        for j in 0..4 * TABLE_ENTRIES as u32 {
            for low in [0, (1 << PHASE_BELOW_INDEX) - 1] {
                let phase = (j << PHASE_BELOW_INDEX) | low;
                let c = table_carriers(p, phase, phase.wrapping_add(1 << 30));
                assert_eq!(
                    (c.drive_sin, c.drive_cos, c.ref_sin, c.ref_cos),
                    (
                        table_sine(quarter, phase, 0).into(),
                        table_sine(quarter, phase, 1).into(),
                        table_sine(quarter, phase, 1).into(),
                        table_sine(quarter, phase, 2).into(),
                    ),
                    "phase {phase:#x}"
                );
            }
        }
    }

    #[test]
    fn the_hosts_carrier_table_is_the_fill_s() {
        for (i, &v) in table().iter().enumerate() {
            assert_eq!(carrier_table_word(i), i32::from(v), "entry {i}");
        }
    }

    /// The fundamental of the words `E x carrier` over 2^16 carrier phases,
    /// two in each of the table's intervals, through this model's words
    /// and the mixer model's rounding.
    fn model_fundamental(profile: CarrierProfile, envelope: i16) -> f64 {
        const PHASES: u64 = 1 << 16;
        let sum: f64 = (0..PHASES)
            .map(|i| {
                let phase = ((i << 32) / PHASES) as u32 + (1 << 15);
                let theta = f64::from(phase) * std::f64::consts::TAU / 2f64.powi(32);
                carrier_product(profile, envelope, carrier_word(profile, phase)) * theta.sin()
            })
            .sum();
        2.0 * sum / PHASES as f64
    }

    /// The host's drive words (`readout_word`, `calibration_word`) against
    /// the model's on both cores, at the small drives where the table
    /// core's rounding moves a fundamental (1e-4 at E = 100) and at 0.9 of
    /// full scale. The host sums the same words at each interval's centre,
    /// the model at its quarter points: a sine's difference of (pi /
    /// 32768)^2 / 2 = 5e-9. On the fine core the host takes the carrier's
    /// amplitude as PEAK; its interpolated words (within 0.65 of a quarter
    /// LSB) have a fundamental 4e-8 off that (measured). Asserted within
    /// 1e-7; the table core's rounding is 2e-4 at amp 65. The calibration word is
    /// each envelope's fundamental through the mixer, over the modulation
    /// ROM's turn (the carrier turns 1e5 times an envelope step at a
    /// calibration frequency), from the ROM model's words; the table core
    /// beyond 4096 takes E x PEAK / 2^15 (`EXACT_ENVELOPES`, within 1.4e-6).
    #[test]
    fn the_hosts_drive_words_are_the_models() {
        let crest = f64::from(PEAK) / 32768.0;
        for profile in [Table, Fine] {
            for amp in [37i16, 65, 260, 1000, 29491] {
                let e = q15_product(amp, PEAK as i16);
                let (host, model) = (readout_word(profile, amp), model_fundamental(profile, e));
                assert!(
                    (host / model - 1.0).abs() < 1e-7,
                    "{profile} readout, amp {amp}: {host} vs {model}"
                );
            }
            for amp in [37i16, 65, 260] {
                let mut cache = std::collections::HashMap::new();
                let n = 4 * crate::sine_table::ENTRIES;
                let sum: f64 = (0..n)
                    .map(|p| {
                        let phase = ((p as u64) << 32) / n as u64 + (1 << 16);
                        let a = crate::model::sine::sine(phase as u32, 0);
                        let e = q15_product(amp, a);
                        let f = *cache
                            .entry(e)
                            .or_insert_with(|| model_fundamental(profile, e));
                        f * (phase as f64 * std::f64::consts::TAU / 2f64.powi(32)).sin()
                    })
                    .sum();
                let model = 2.0 * sum / n as f64;
                let host = calibration_word(profile, amp);
                assert!(
                    (host / model - 1.0).abs() < 1e-7,
                    "{profile} calibration, amp {amp}: {host} vs {model}"
                );
                // What the table core's rounding is worth here, for the record.
                let ideal = calibration_word(Fine, amp);
                eprintln!(
                    "{profile} amp {amp}: calibration word over the exact product's {:+.2e}; readout {:+.2e}",
                    host / ideal - 1.0,
                    readout_word(profile, amp) / (f64::from(q15_product(amp, PEAK as i16)) * crest)
                        - 1.0
                );
            }
        }
    }

    #[test]
    fn table_words_are_within_1_lsb_of_the_centre_sines() {
        // The header's bound: ROM rounding 0.5, interpolation rounding 0.5,
        // curvature 4e-5 LSB.
        let d = std::f64::consts::FRAC_PI_2 / TABLE_ENTRIES as f64;
        for (i, &v) in table().iter().enumerate() {
            let exact = PEAK as f64 * ((i as f64 + 0.5) * d).sin();
            assert!((v as f64 - exact).abs() <= 1.0, "entry {i}: {v} vs {exact}");
        }
    }

    #[test]
    fn table_words_lie_in_the_first_quadrant_range() {
        // The negation in quadrants 2 and 3 cannot overflow.
        assert!(table().iter().all(|&v| (0..=PEAK as i16).contains(&v)));
    }

    #[test]
    fn error_against_the_exact_sine_is_at_most_4_2_lsb() {
        // The phase is rounded to an interval centre, at most half an
        // interval (pi / 2^15 rad) away: 32767 pi / 2^15 = 3.14 LSB; the
        // table words carry at most 1 LSB (`carrier_table_fill`).
        let t = table();
        let mut worst = 0.0f64;
        for k in 0u32..(1 << 20) {
            let phase = k.wrapping_mul(0x9e37_79b9);
            let angle = phase as f64 / 2f64.powi(32) * std::f64::consts::TAU;
            worst = worst.max((table_sine(t, phase, 0) as f64 - 32767.0 * angle.sin()).abs());
            worst = worst.max((table_sine(t, phase, 1) as f64 - 32767.0 * angle.cos()).abs());
        }
        assert!(worst <= 3.15 + 1.0, "worst error {worst} LSB");
    }

    #[test]
    fn outputs_are_zero_until_the_fill_is_over_then_lag_the_phase_by_5() {
        let mut nco = CarrierNco::default();
        let step = 0x1234_5679;
        // `step` returns the outputs of the next cycle: cycles 1..FILL_CLOCKS + 4.
        for n in 1..FILL_CLOCKS + LATENCY {
            assert_eq!(nco.step(step, 0), Carriers::default(), "cycle {n}");
        }
        // Cycle FILL_CLOCKS + 5: the phase of cycle FILL_CLOCKS.
        let phase = step.wrapping_mul(FILL_CLOCKS as u32);
        let first = nco.step(step, 0);
        assert_eq!(first.drive_sin, i32::from(table_sine(table(), phase, 0)));
        assert_eq!(first.drive_cos, i32::from(table_sine(table(), phase, 1)));
    }
}
