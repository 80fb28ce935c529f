//! Bit-true, cycle-true model of `crate::gyro_interface::GyroInterface`:
//! the blocks' models wired as in the hardware. This is the `model` engine.

use super::am_mixer::{AmMixer, Drives};
use super::carrier_nco::{CarrierNco, Carriers};
use super::cic_decimator::CicDecimator;
use super::demod_mux::DemodMux;
use super::iir_lowpass::{Factors, IirLowpass};
use super::isa::Isa;
use super::lanes::One;
use super::modulation_nco::ModulationNco;
use super::reference_alignment::ReferenceAlignment;
pub use gyrocal_regs::Registers;
pub use gyrocal_regs::datapath::CarrierProfile;

/// The output ports of `GyroInterface` during one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Outputs {
    /// DAC words.
    pub dac: (i16, i16),
    /// Filtered outputs z1, z2 (40 bits, 8 fractional bits).
    pub z: (i64, i64),
    /// New z this cycle.
    pub z_valid: bool,
}

/// Internal signals worth watching (waveform dumps).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Probes {
    /// Reference copies of the drives, before alignment.
    pub reference: (i16, i16),
    /// Mixer outputs w1, w2.
    pub w: (i32, i32),
    /// CIC outputs.
    pub cic: (i64, i64),
    /// CIC output strobe.
    pub cic_valid: bool,
    /// Modulation factors A1, A2.
    pub am: (i16, i16),
}

/// Cycle-true model of the whole datapath.
#[derive(Clone, Debug, Default)]
pub struct GyroInterface {
    pub(super) carrier_nco: CarrierNco,
    pub(super) modulation_nco: ModulationNco,
    pub(super) am_mixer: AmMixer,
    pub(super) reference_alignment: ReferenceAlignment,
    pub(super) demod_mux: DemodMux,
    pub(super) cic: CicDecimator,
    pub(super) iir: IirLowpass,
}

impl GyroInterface {
    /// The datapath at its power-up state (the table core).
    pub fn new() -> Self {
        Self::default()
    }

    /// The datapath of the core with this carrier profile, at power-up.
    pub fn with_profile(profile: CarrierProfile) -> Self {
        Self {
            carrier_nco: CarrierNco::new(profile),
            am_mixer: AmMixer::new(profile),
            ..Self::default()
        }
    }

    /// The output ports during the current cycle.
    #[inline(always)]
    pub fn outputs(&self) -> Outputs {
        let drives = self.am_mixer.output();
        let (z1, z2, z_valid) = self.iir.output();
        Outputs {
            dac: (drives.dac1, drives.dac2),
            z: (z1, z2),
            z_valid,
        }
    }

    /// Internal signals during the current cycle.
    pub fn probes(&self) -> Probes {
        let drives = self.am_mixer.output();
        let (cic, cic_valid) = self.cic.output();
        Probes {
            reference: (drives.ref1, drives.ref2),
            w: self.demod_mux.output(),
            cic,
            cic_valid,
            am: self.modulation_nco.output(),
        }
    }

    /// One clock: `adc` and `regs` are the inputs during the current cycle;
    /// returns the outputs after the rising edge.
    #[inline(always)]
    pub fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs {
        let regs = &regs.at_ports();
        let drives = self.am_mixer.output();
        self.step_drives(regs);
        self.step_readout(adc, (drives.ref1, drives.ref2), regs);
        self.outputs()
    }

    /// `clocks` clocks with `regs` held, in blocks of `BLOCK`: the same
    /// clocks as `step` that many times, with `analog` closing the loop.
    /// The DAC words do not depend on the ADC words (no path in the
    /// datapath leads from the demodulators back to the drives), and
    /// nothing after the IIR's input feeds back either, so each half runs
    /// a block at a time, stage by stage. Per block:
    ///
    /// ```text
    /// 1. `analog.advance_block` with the block's DAC words, the next
    ///    block's carrier lookups beside its clocks (integer work beside
    ///    the gyroscope's floating-point recursion, which would otherwise
    ///    wait on its own latency);
    /// 2. `analog.convert`: the block's ADC words;
    /// 3. the readout half on them (`readout_block`), z as it comes;
    /// 4. the drive half of the next block (`drive_block`).
    /// ```
    ///
    /// `on_z(i, z)` is called when clock `i` (from 0) publishes z, in the
    /// order of the clocks. Returns the outputs after the last edge.
    ///
    /// The block loop is [`super::lanes`]'s, this datapath its only lane
    /// (lanes run datapaths that differ only in their ADC words together).
    /// Compiled for the instruction set `Isa::selected` names (the widest
    /// this processor runs, [`super::isa`]): the same results on every one.
    #[inline(always)]
    pub fn run<A, Z>(&mut self, regs: &Registers, clocks: u64, analog: &mut A, on_z: Z) -> Outputs
    where
        A: AnalogSide,
        Z: FnMut(u64, (i64, i64)),
    {
        self.run_on(Isa::selected(), regs, clocks, analog, on_z)
    }

    /// `run` as compiled for `isa` ([`super::isa`]); the portable build
    /// when this processor lacks `isa`. The same outputs and calls.
    #[inline(always)]
    pub fn run_on<A, Z>(
        &mut self,
        isa: Isa,
        regs: &Registers,
        clocks: u64,
        analog: &mut A,
        mut on_z: Z,
    ) -> Outputs
    where
        A: AnalogSide,
        Z: FnMut(u64, (i64, i64)),
    {
        let lanes = std::slice::from_mut(self);
        let on_z = |_: usize, i: u64, z: (i64, i64)| on_z(i, z);
        super::lanes::run_on(isa, lanes, regs, clocks, &mut One(analog), on_z);
        self.outputs()
    }

    /// The readout half over a block, stage by stage, with the block's
    /// drive words (their reference copies) and ADC words (`stages.adc`):
    /// `on_z(i, z)` when clock `i` of the block publishes z. The CIC tells
    /// its samples as events; the IIR steps through its schedules and
    /// skips its idle clocks to the next sample (an idle step changes
    /// nothing but clearing z_valid, so one stands for them all).
    ///
    /// `WEIGHTED`: the CIC's inputs integrated as weighted sums
    /// (`CicDecimator::block`), for a build with vector multiplies.
    #[inline(always)]
    pub(super) fn readout_block<const WEIGHTED: bool>(
        &mut self,
        drives: &[Drives],
        stages: &mut ReadoutStages,
        regs: &Registers,
        mut on_z: impl FnMut(u64, (i64, i64)),
    ) {
        let n = drives.len();
        let (aligned, w) = (&mut stages.aligned[..n], &mut stages.w[..n]);
        let references = |i: usize| (drives[i].ref1, drives[i].ref2);
        self.reference_alignment
            .block(references, regs.ref_delay, aligned);
        self.demod_mux
            .block(&stages.adc[..n], aligned, regs.select, w);
        let (r, shift) = (regs.cic_decimation as u32, regs.cic_shift as u32);
        let samples = &mut stages.samples;
        samples.clear();
        self.cic
            .block::<WEIGHTED>(w, r, shift, |t, y| samples.push((t, y)));
        let mut next = samples.iter().peekable();
        let mut t = 0;
        while t < n {
            let at = next.peek().map_or(n, |&&(at, _)| at);
            if self.iir.idle() {
                // Idle until the next sample, if any in this block.
                if at > t {
                    self.iir.step((0, 0), false, &regs.iir);
                    t = at;
                    continue;
                }
            } else if at > t {
                // Busy, no sample before `at`: the schedule runs on.
                let from = t;
                let on = |i: usize, z| on_z((from + i) as u64, z);
                t += self.iir.run_without_input(at - t, &stages.factors, on);
                continue;
            }
            let sample = next.next_if(|&&(at, _)| at == t);
            let (x, valid) = sample.map_or(((0, 0), false), |&(_, y)| (y, true));
            let (z1, z2, z_valid) = self.iir.step(x, valid, &regs.iir);
            if z_valid {
                on_z(t as u64, (z1, z2));
            }
            t += 1;
        }
    }

    /// The drive words during the next `drives.len()` cycles, then the
    /// drive half's edges: stage by stage over the block where every stage
    /// can (`CarrierNco::blocks`: the table core after its fill), else
    /// clock by clock. `entered`: `stages.entered` holds the block's
    /// carrier words, looked up ahead.
    #[inline(always)]
    pub(super) fn drive_block(
        &mut self,
        drives: &mut [Drives],
        stages: &mut DriveStages,
        regs: &Registers,
        entered: bool,
    ) {
        let n = drives.len();
        if self.carrier_nco.blocks() && self.am_mixer.blocks() {
            let carriers = &mut stages.carriers[..n];
            let am = &mut stages.am[..n];
            if entered {
                let entered = &stages.entered[..n];
                self.carrier_nco
                    .block_entered(regs.carrier_step, entered, carriers);
            } else {
                self.carrier_nco
                    .block(regs.carrier_step, regs.ref_phase, carriers);
            }
            self.modulation_nco.block(regs.mod_step, regs.select, am);
            self.am_mixer.block(regs.amp, am, carriers, drives);
        } else {
            for d in drives {
                *d = self.am_mixer.output();
                self.step_drives(regs);
            }
        }
    }

    /// Edges from now none of which can publish z, with the registers
    /// held: those before the edge that publishes the next z. A running
    /// IIR schedule publishes at its last word
    /// (`IirLowpass::edges_to_publish`; it drops the CIC samples that come
    /// meanwhile). An idle IIR takes a waiting CIC sample at the next edge,
    /// or else the next one, valid after `CicDecimator::edges_to_valid`
    /// edges, at the edge after; it publishes z `crate::iir_lowpass::LATENCY`
    /// edges after the one that takes the sample.
    pub fn quiet_clocks(&self) -> u64 {
        let latency = crate::iir_lowpass::LATENCY as u64;
        let publish = match self.iir.edges_to_publish() {
            Some(edges) => edges,
            None if self.cic.output().1 => latency,
            None => self.cic.edges_to_valid() + latency,
        };
        publish - 1
    }

    /// The drive half of one clock (carrier NCO, modulation NCO, AM
    /// mixers): nothing in it reads the ADC words.
    #[inline(always)]
    fn step_drives(&mut self, regs: &Registers) {
        // Read every block's current outputs before any register moves.
        let carriers = self.carrier_nco.output();
        let am = self.modulation_nco.output();
        let fill = self.carrier_nco.fill_request();
        self.carrier_nco.step(regs.carrier_step, regs.ref_phase);
        self.modulation_nco.step(regs.mod_step, regs.select, fill);
        self.am_mixer.step(regs.amp, am, carriers);
    }

    /// The readout half of one clock (reference alignment, demodulators,
    /// CIC, IIR) with the ADC words and the reference copies of the
    /// drives during the current cycle.
    #[inline(always)]
    fn step_readout(&mut self, adc: (i16, i16), references: (i16, i16), regs: &Registers) {
        let aligned = self.reference_alignment.output();
        let w = self.demod_mux.output();
        let (cic, cic_valid) = self.cic.output();
        self.reference_alignment
            .step(references.0, references.1, regs.ref_delay);
        self.demod_mux.step(adc, aligned, regs.select);
        let r = regs.cic_decimation as u32;
        let shift = regs.cic_shift as u32;
        self.cic.step(w, r, shift);
        self.iir.step(cic, cic_valid, &regs.iir);
    }
}

/// A converter word per channel (DAC or ADC; channel 1, channel 2).
pub type Words = (i16, i16);

/// What closes `GyroInterface::run`'s loop: the DACs, the sensor and the
/// ADCs, a clock at a time on the DAC side and a block at a time on the
/// ADC side.
pub trait AnalogSide {
    /// One clock with the DAC words during it: the ADCs sample at its
    /// start, then the sensor advances under the words' forces.
    fn advance(&mut self, dac: Words);
    /// `advance` with each of these DAC words in turn, calling
    /// `beside(t)` at clock t: an analog side may play them faster
    /// together, and the caller's independent work in `beside` runs in
    /// the same loop, where a core overlaps it with the analog side's
    /// chains of dependent operations.
    #[inline(always)]
    fn advance_block(&mut self, dac: impl Iterator<Item = Words>, mut beside: impl FnMut(usize)) {
        for (t, d) in dac.enumerate() {
            self.advance(d);
            beside(t);
        }
    }
    /// The ADC words during the clocks advanced since the last call, in
    /// order (`adc.len()` of them).
    fn convert(&mut self, adc: &mut [Words]);
}

/// The drive half's stages' outputs over a block, on the way to the
/// drive words (`GyroInterface::drive_block`).
pub(super) struct DriveStages {
    /// The carrier words entering the pipeline at the next block's edges,
    /// when looked up ahead.
    pub(super) entered: [Carriers; BLOCK],
    carriers: [Carriers; BLOCK],
    am: [(i16, i16); BLOCK],
}

impl Default for DriveStages {
    fn default() -> Self {
        Self {
            entered: [Carriers::default(); BLOCK],
            carriers: [Carriers::default(); BLOCK],
            am: [(0, 0); BLOCK],
        }
    }
}

/// The readout half's stages over a block, on the way from the ADC words
/// to the IIR (`GyroInterface::readout_block`).
pub(super) struct ReadoutStages {
    pub(super) adc: [Words; BLOCK],
    aligned: [Words; BLOCK],
    w: [(i32, i32); BLOCK],
    /// The CIC's samples over the block: cycle, words.
    samples: Vec<(usize, (i64, i64))>,
    /// The IIR's operands for the run's coefficients.
    factors: Factors,
}

impl ReadoutStages {
    /// The stages of a run that holds `regs`.
    pub(super) fn new(regs: &Registers) -> Self {
        Self {
            adc: [(0, 0); BLOCK],
            aligned: [(0, 0); BLOCK],
            w: [(0, 0); BLOCK],
            samples: Vec::with_capacity(BLOCK),
            factors: Factors::new(&regs.iir),
        }
    }
}

/// Clocks per block of `GyroInterface::run`: its three buffers (12 bytes a
/// clock) stay in the first-level cache.
pub const BLOCK: usize = 256;

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::gyro_interface::DRIVE_START_CLOCKS;
    use crate::test_util::Rng;

    #[test]
    fn the_drives_leave_zero_at_drive_start_clocks() {
        // Readout at full envelope: the DAC words are 0 while the carrier
        // tables fill (or, on the fine core, for as long), and not during
        // cycle DRIVE_START_CLOCKS.
        let regs = Registers {
            carrier_step: 0x1234_5679,
            amp: (20000, -20000),
            ..Default::default()
        };
        for profile in CarrierProfile::ALL {
            let mut m = GyroInterface::with_profile(profile);
            // `step` returns the outputs of the next cycle.
            for cycle in 1..DRIVE_START_CLOCKS {
                assert_eq!(
                    m.step((0, 0), &regs).dac,
                    (0, 0),
                    "{profile}, cycle {cycle}"
                );
            }
            let first = m.step((0, 0), &regs).dac;
            assert!(
                first.0 != 0 && first.1 != 0,
                "{profile}, cycle {DRIVE_START_CLOCKS}: {first:?}"
            );
        }
    }

    #[test]
    fn the_profiles_differ_only_in_the_carriers() {
        // Same settings, same ADC words: the two cores' carriers differ by
        // at most 4.2 + 0.65 LSB (their error bounds), which an envelope of
        // 20000 / 32767 scales to 3.0 LSB; with the two products' roundings
        // (0.5 each) the DAC words differ by at most 4. They do differ, and
        // nothing else in the datapath sees the profile.
        let regs = Registers {
            carrier_step: 0x1234_5679,
            amp: (20000, -20000),
            ..Default::default()
        };
        let mut table = GyroInterface::with_profile(CarrierProfile::Table);
        let mut fine = GyroInterface::with_profile(CarrierProfile::Fine);
        let mut differ = 0;
        for _ in 0..DRIVE_START_CLOCKS + 5000 {
            let (a, b) = (table.step((0, 0), &regs).dac, fine.step((0, 0), &regs).dac);
            assert!(
                (a.0 - b.0).abs() <= 4 && (a.1 - b.1).abs() <= 4,
                "{a:?} {b:?}"
            );
            differ += usize::from(a != b);
        }
        assert!(differ > 100, "the fine carriers never differed: {differ}");
    }

    /// Registers of one run: readout or calibration (a modulation step of
    /// any width), a filter designed for a decimation from the shortest
    /// to the longest, now and then with a decimation too short for the
    /// IIR (which then drops CIC samples), any reference delay.
    pub(in crate::model) fn run_registers(rng: &mut Rng) -> Registers {
        let designed = [166u32, 200, 397, 1000, 4096][rng.range(0, 4) as usize];
        let fz = 1e6 / f64::from(designed);
        let design = gyrocal_regs::filter_design::design(1e6, designed, fz / 40.0, fz / 20.0)
            .expect("a valid design");
        let decimation = if rng.range(0, 5) == 0 {
            rng.range(2, 165) as u32
        } else {
            designed
        };
        Registers {
            select: rng.range(0, 1) == 1,
            carrier_step: rng.next_u64() as u32,
            ref_phase: rng.next_u64() as u32,
            ref_delay: rng.range(0, 63) as u8,
            // Any width: calibration frequencies (a ROM interval every
            // few hundred clocks) as well as steps across the turn.
            mod_step: rng.next_u64() & ((1 << rng.range(1, Registers::MOD_STEP_BITS as i64)) - 1),
            amp: (rng.word16(), rng.word16()),
            cic_decimation: decimation as u16,
            cic_shift: design.cic_shift as u8,
            iir: design.coefficients,
        }
    }

    /// The ADC words a run sees: `analog_word` of each clock's DAC words.
    struct Hashed<'a> {
        word: Box<dyn FnMut(Words) -> Words + 'a>,
        pending: Vec<Words>,
    }

    impl AnalogSide for Hashed<'_> {
        fn advance(&mut self, dac: Words) {
            let w = (self.word)(dac);
            self.pending.push(w);
        }
        fn convert(&mut self, adc: &mut [Words]) {
            assert_eq!(adc.len(), self.pending.len(), "a block converted whole");
            adc.copy_from_slice(&self.pending);
            self.pending.clear();
        }
    }

    fn analog(count: &mut u64) -> Hashed<'_> {
        Hashed {
            word: Box::new(analog_word(count)),
            pending: vec![],
        }
    }

    /// The ADC word of one clock: a hash of the DAC words and a counter,
    /// so that a word taken at the wrong cycle shows.
    fn analog_word(count: &mut u64) -> impl FnMut((i16, i16)) -> (i16, i16) + '_ {
        move |dac| {
            *count += 1;
            let key = *count ^ (dac.0 as u16 as u64) << 32 ^ (dac.1 as u16 as u64) << 48;
            let h = key.wrapping_mul(0x9e37_79b9_7f4a_7c15);
            ((h >> 48) as i16, (h >> 32) as i16)
        }
    }

    /// `run` plays the clocks `step` plays, on both cores and compiled for
    /// every instruction set this processor runs: runs of every length
    /// around a block's (1, BLOCK - 1, BLOCK, BLOCK + 1, long), with the
    /// registers changed between them, give the same z at the same clocks
    /// and the same ports and internal signals after.
    #[test]
    fn a_run_is_step_clock_by_clock() {
        let lengths = [
            1,
            BLOCK as u64 - 1,
            BLOCK as u64,
            BLOCK as u64 + 1,
            3,
            20_000,
            777,
        ];
        let isas = Isa::supported_all();
        for (profile, isa) in CarrierProfile::ALL
            .into_iter()
            .flat_map(|p| isas.iter().map(move |&i| (p, i)))
        {
            let mut rng = Rng::new(11);
            let (mut blocked, mut stepped) = (
                GyroInterface::with_profile(profile),
                GyroInterface::with_profile(profile),
            );
            let (mut count_b, mut count_s) = (0, 0);
            let mut clock = 0u64;
            for (run, &clocks) in lengths.iter().cycle().take(40).enumerate() {
                let regs = run_registers(&mut rng);
                let mut z_blocked = vec![];
                let analog = &mut analog(&mut count_b);
                let out = blocked.run_on(isa, &regs, clocks, analog, |i, z| {
                    z_blocked.push((clock + i, z))
                });
                let mut z_stepped = vec![];
                let mut feed = analog_word(&mut count_s);
                let mut o = stepped.outputs();
                for i in 0..clocks {
                    o = stepped.step(feed(o.dac), &regs);
                    if o.z_valid {
                        z_stepped.push((clock + i, o.z));
                    }
                }
                assert_eq!(
                    z_blocked, z_stepped,
                    "{profile} ({isa}), run {run} of {clocks} clocks"
                );
                assert_eq!(out, o, "{profile} ({isa}), run {run}");
                let probes = (blocked.probes(), stepped.probes());
                assert_eq!(probes.0, probes.1, "{profile} ({isa}), run {run}");
                clock += clocks;
            }
            assert!(clock > 100_000);
        }
    }

    /// Runs and single steps mixed on one model play the clocks of steps
    /// alone: runs of 1 to 400 clocks (ending anywhere in the IIR's
    /// schedules) with 1 to 5 steps after each, on both cores, against a
    /// model stepped throughout. A run's shortcuts may keep their own
    /// bookkeeping only if they leave the state a step reads.
    #[test]
    fn runs_and_steps_mixed_are_the_steps() {
        for profile in CarrierProfile::ALL {
            let mut rng = Rng::new(23);
            let (mut mixed, mut stepped) = (
                GyroInterface::with_profile(profile),
                GyroInterface::with_profile(profile),
            );
            let (mut count_m, mut count_s) = (0, 0);
            let (mut z_mixed, mut z_stepped) = (vec![], vec![]);
            let mut clock = 0u64;
            for run in 0..8 {
                let regs = run_registers(&mut rng);
                for _ in 0..40 {
                    let clocks = rng.range(1, 400) as u64;
                    let mut o = mixed.run(&regs, clocks, &mut analog(&mut count_m), |i, z| {
                        z_mixed.push((clock + i, z))
                    });
                    let steps = rng.range(1, 5) as u64;
                    let mut feed = analog_word(&mut count_m);
                    for i in 0..steps {
                        o = mixed.step(feed(o.dac), &regs);
                        if o.z_valid {
                            z_mixed.push((clock + clocks + i, o.z));
                        }
                    }
                    let mut feed = analog_word(&mut count_s);
                    let mut p = stepped.outputs();
                    for i in 0..clocks + steps {
                        p = stepped.step(feed(p.dac), &regs);
                        if p.z_valid {
                            z_stepped.push((clock + i, p.z));
                        }
                    }
                    assert_eq!(o, p, "{profile}, run {run}, clock {clock}");
                    clock += clocks + steps;
                }
                assert_eq!(z_mixed, z_stepped, "{profile}, run {run}");
            }
            assert!(z_stepped.len() > 50, "{profile}: {} z", z_stepped.len());
        }
    }

    /// `quiet_clocks` is exact: from any cycle of runs with changing
    /// registers, the next z comes at the edge after the quiet ones (0
    /// quiet: at the next edge), through busy schedules, dropped samples
    /// and idle stretches alike.
    #[test]
    fn the_next_z_comes_right_after_the_quiet_clocks() {
        let mut rng = Rng::new(5);
        let mut model = GyroInterface::new();
        let mut count = 0;
        let mut busy = 0;
        for run in 0..20 {
            let regs = run_registers(&mut rng);
            for cycle in 0..2000 {
                let quiet = model.quiet_clocks();
                let mut ahead = model.clone();
                let mut c = count;
                let mut feed = analog_word(&mut c);
                let mut o = ahead.outputs();
                let mut edges = 0;
                loop {
                    o = ahead.step(feed(o.dac), &regs);
                    edges += 1;
                    if o.z_valid {
                        break;
                    }
                    // A CIC schedule, the longest decimation and the IIR.
                    assert!(edges < 10_000, "run {run}, cycle {cycle}: no z");
                }
                assert_eq!(edges, quiet + 1, "run {run}, cycle {cycle}");
                busy += u32::from(model.iir.busy());
                let o = model.outputs();
                model.step(analog_word(&mut count)(o.dac), &regs);
            }
        }
        // The premise: cycles inside busy schedules were among them.
        assert!(busy > 10_000, "{busy} of 40000 cycles busy");
    }
}
