//! Lanes: datapaths that play the same clocks with the same registers from
//! the same state, and differ only in their ADC words (one device on a
//! rate table, a board per rate). Nothing in the drive half reads an ADC
//! word, so their drive halves stay equal clock for clock: one drive half
//! plays for all of them, and each lane's readout half runs on its own ADC
//! words. Each lane's outputs are those `GyroInterface::run` gives it
//! alone.
//!
//! Per block of `BLOCK` clocks (as `GyroInterface::run`, module
//! `gyro_interface`, which is the one-lane case of this file):
//!
//! ```text
//! 1. `analog.advance_block` with the block's DAC words, once for every
//!    lane, the next block's carrier lookups beside its clocks;
//! 2. per lane: `analog.convert(lane, ..)`, its ADC words, then its
//!    readout half (`readout_block`), z as it comes;
//! 3. the drive half of the next block (`drive_block`), once.
//! ```
//!
//! After a run the other lanes' drive halves are set to the first's, so
//! that each lane is a whole datapath again, the one its own run would
//! have left.

use super::am_mixer::Drives;
use super::gyro_interface::{
    AnalogSide, BLOCK, DriveStages, GyroInterface, ReadoutStages, Registers, Words,
};
use super::isa::{Isa, x86_64_v3_features, x86_64_v4_features};

/// What closes the loop of every lane: one set of DAC words for all of
/// them (their drive halves are one), an ADC word pair per lane.
pub trait AnalogLanes {
    /// How many lanes.
    fn lanes(&self) -> usize;
    /// Every lane's analog side through the clocks of these DAC words,
    /// calling `beside(t)` once at clock t (`AnalogSide::advance_block`).
    fn advance_block(&mut self, dac: impl Iterator<Item = Words>, beside: impl FnMut(usize));
    /// Lane `lane`'s ADC words during the clocks advanced since its last
    /// call, in order. Each block converts every lane once, lane 0 first.
    fn convert(&mut self, lane: usize, adc: &mut [Words]);
}

/// One analog side as the only lane.
pub(super) struct One<'a, A>(pub &'a mut A);

impl<A: AnalogSide> AnalogLanes for One<'_, A> {
    #[inline(always)]
    fn lanes(&self) -> usize {
        1
    }

    #[inline(always)]
    fn advance_block(&mut self, dac: impl Iterator<Item = Words>, beside: impl FnMut(usize)) {
        self.0.advance_block(dac, beside);
    }

    #[inline(always)]
    fn convert(&mut self, _lane: usize, adc: &mut [Words]) {
        self.0.convert(adc);
    }
}

/// Datapaths in lanes, their drive halves equal by construction: copies of
/// one datapath, only ever run together.
#[derive(Clone, Debug)]
pub struct Lanes {
    lanes: Vec<GyroInterface>,
}

/// Why lanes cannot be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoLane;

impl std::fmt::Display for NoLane {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "lanes: a count of 0 (allowed 1 or more)")
    }
}

impl std::error::Error for NoLane {}

impl Lanes {
    /// `count` copies of `datapath`, each a lane.
    ///
    /// ```
    /// use gyrocal_hdl::model::gyro_interface::GyroInterface;
    /// use gyrocal_hdl::model::lanes::Lanes;
    /// let lanes = Lanes::new(GyroInterface::new(), 3).unwrap();
    /// assert_eq!(lanes.lanes().len(), 3);
    /// assert!(Lanes::new(GyroInterface::new(), 0).is_err());
    /// ```
    pub fn new(datapath: GyroInterface, count: usize) -> Result<Self, NoLane> {
        if count == 0 {
            return Err(NoLane);
        }
        Ok(Self {
            lanes: vec![datapath; count],
        })
    }

    /// The lanes' datapaths, each whole.
    pub fn lanes(&self) -> &[GyroInterface] {
        &self.lanes
    }

    /// The datapaths, each whole.
    pub fn into_inner(self) -> Vec<GyroInterface> {
        self.lanes
    }

    /// `clocks` clocks with `regs` held on every lane, as
    /// `GyroInterface::run` on each with its own analog side (lane l's
    /// `analog.convert(l, ..)`): `on_z(l, i, z)` when clock `i` (from 0)
    /// of lane `l` publishes z, in the order of the clocks within a lane.
    /// `analog` must have as many lanes (a panic otherwise: a caller's
    /// bug, not an input).
    #[inline(always)]
    pub fn run<A, Z>(&mut self, isa: Isa, regs: &Registers, clocks: u64, analog: &mut A, on_z: Z)
    where
        A: AnalogLanes,
        Z: FnMut(usize, u64, (i64, i64)),
    {
        assert_eq!(analog.lanes(), self.lanes.len(), "lanes and analog sides");
        run_on(isa, &mut self.lanes, regs, clocks, analog, on_z);
    }
}

/// `run_blocks` compiled for the target features `[$feature, ...]`
/// (given by [`super::isa`]'s lists, which its processor check reads
/// too), named `$name`.
macro_rules! run_compiled_for {
    ($(#[$doc:meta])* $name:ident, [$($feature:tt),*]) => {
        $(#[$doc])*
        #[cfg(target_arch = "x86_64")]
        $(#[target_feature(enable = $feature)])*
        unsafe fn $name<A, Z>(
            lanes: &mut [GyroInterface],
            regs: &Registers,
            clocks: u64,
            analog: &mut A,
            on_z: Z,
        )
        where
            A: AnalogLanes,
            Z: FnMut(usize, u64, (i64, i64)),
        {
            // Both have vector multiplies: the CIC integrates by weighted
            // sums (`CicDecimator::block`).
            run_blocks::<true, _, _>(lanes, regs, clocks, analog, on_z)
        }
    };
}

x86_64_v4_features!(run_compiled_for!(
    /// `run_blocks` compiled for x86-64-v4.
    ///
    /// # Safety
    /// The processor must have its features (`Isa::X86_64V4.supported()`).
    run_x86_64_v4,
));

x86_64_v3_features!(run_compiled_for!(
    /// `run_blocks` compiled for x86-64-v3.
    ///
    /// # Safety
    /// The processor must have its features (`Isa::X86_64V3.supported()`).
    run_x86_64_v3,
));

/// `run_blocks` as compiled for `isa`; the portable build when this
/// processor lacks `isa`. The same outputs and calls.
#[inline(always)]
pub(super) fn run_on<A, Z>(
    isa: Isa,
    lanes: &mut [GyroInterface],
    regs: &Registers,
    clocks: u64,
    analog: &mut A,
    on_z: Z,
) where
    A: AnalogLanes,
    Z: FnMut(usize, u64, (i64, i64)),
{
    #[cfg(target_arch = "x86_64")]
    if isa.supported() {
        // SAFETY: the processor has every feature each function is
        // compiled for (checked just above).
        match isa {
            Isa::X86_64V4 => return unsafe { run_x86_64_v4(lanes, regs, clocks, analog, on_z) },
            Isa::X86_64V3 => return unsafe { run_x86_64_v3(lanes, regs, clocks, analog, on_z) },
            Isa::Portable => {}
        }
    }
    let _ = isa;
    run_blocks::<false, _, _>(lanes, regs, clocks, analog, on_z)
}

/// The blocks of the module header, on `lanes` (whose drive halves are
/// equal: the first plays for all). `WEIGHTED`: the CIC integrates by
/// weighted sums (`CicDecimator::block`), for a build with vector
/// multiplies; the same outputs either way.
#[inline(always)]
fn run_blocks<const WEIGHTED: bool, A, Z>(
    lanes: &mut [GyroInterface],
    regs: &Registers,
    clocks: u64,
    analog: &mut A,
    mut on_z: Z,
) where
    A: AnalogLanes,
    Z: FnMut(usize, u64, (i64, i64)),
{
    let regs = &regs.at_ports();
    let block = |done: u64| (clocks - done).min(BLOCK as u64) as usize;
    let mut drives = [Drives::default(); BLOCK];
    let mut stages = DriveStages::default();
    let mut readout = ReadoutStages::new(regs);
    let mut n = block(0);
    lanes[0].drive_block(&mut drives[..n], &mut stages, regs, false);
    let mut done = 0u64;
    while n > 0 {
        // The next block's carrier lookups, beside the analog side's
        // clocks of this one (the next block is never longer).
        let ahead = block(done + n as u64);
        let dac = drives[..n].iter().map(|d| (d.dac1, d.dac2));
        let lead = &lanes[0];
        let looked_up = lead.carrier_nco.blocks();
        if looked_up {
            let entering = lead.carrier_nco.entering(regs.carrier_step, regs.ref_phase);
            let entered = &mut stages.entered;
            analog.advance_block(dac, |t| {
                if t < ahead {
                    entered[t] = entering(t);
                }
            });
        } else {
            analog.advance_block(dac, |_| {});
        }
        for (l, lane) in lanes.iter_mut().enumerate() {
            analog.convert(l, &mut readout.adc[..n]);
            let on_z = |i, z| on_z(l, done + i, z);
            lane.readout_block::<WEIGHTED>(&drives[..n], &mut readout, regs, on_z);
        }
        done += n as u64;
        n = block(done);
        lanes[0].drive_block(&mut drives[..n], &mut stages, regs, looked_up);
    }
    if let Some((lead, rest)) = lanes.split_first_mut() {
        for lane in rest {
            lane.carrier_nco = lead.carrier_nco.clone();
            lane.modulation_nco = lead.modulation_nco.clone();
            lane.am_mixer = lead.am_mixer.clone();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::gyro_interface::CarrierProfile;
    use crate::model::gyro_interface::tests::run_registers;
    use crate::test_util::Rng;

    /// The ADC word of lane `lane`'s clock: a hash of the lane, the DAC
    /// words and a counter, so that a word taken at the wrong cycle or
    /// from another lane shows.
    fn word(lane: usize, count: &mut u64, dac: Words) -> Words {
        *count += 1;
        let key = *count
            ^ (lane as u64) << 20
            ^ (dac.0 as u16 as u64) << 32
            ^ (dac.1 as u16 as u64) << 48;
        let h = key.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        ((h >> 48) as i16, (h >> 32) as i16)
    }

    /// Each lane's ADC words from `word`, kept until converted.
    struct Hashed {
        counts: Vec<u64>,
        pending: Vec<Vec<Words>>,
        /// Lanes converted this block, in order.
        converted: Vec<usize>,
    }

    impl AnalogLanes for Hashed {
        fn lanes(&self) -> usize {
            self.counts.len()
        }
        fn advance_block(
            &mut self,
            dac: impl Iterator<Item = Words>,
            mut beside: impl FnMut(usize),
        ) {
            assert_eq!(self.converted, (0..self.lanes()).collect::<Vec<_>>());
            self.converted.clear();
            for (t, d) in dac.enumerate() {
                for (l, (count, pending)) in
                    self.counts.iter_mut().zip(&mut self.pending).enumerate()
                {
                    pending.push(word(l, count, d));
                }
                beside(t);
            }
        }
        fn convert(&mut self, lane: usize, adc: &mut [Words]) {
            assert_eq!(
                adc.len(),
                self.pending[lane].len(),
                "a block converted whole"
            );
            adc.copy_from_slice(&self.pending[lane]);
            self.pending[lane].clear();
            self.converted.push(lane);
        }
    }

    /// Lanes play what each lane's datapath plays alone, clock by clock,
    /// on its own ADC words: 1 to 4 lanes, both cores, every instruction
    /// set this processor runs, runs of every length around a block's
    /// with the registers changed between them; the same z at the same
    /// clocks, then the same ports and internal signals, and single steps
    /// after the runs (each lane is a whole datapath again).
    #[test]
    fn each_lane_plays_its_own_datapath() {
        let lengths = [1, BLOCK as u64 - 1, BLOCK as u64 + 1, 3, 9000, 777];
        for (profile, isa) in CarrierProfile::ALL
            .into_iter()
            .flat_map(|p| Isa::supported_all().into_iter().map(move |i| (p, i)))
        {
            for count in 1..=4 {
                let mut rng = Rng::new(31 + count as u64);
                let mut lanes = Lanes::new(GyroInterface::with_profile(profile), count).unwrap();
                let mut alone = vec![GyroInterface::with_profile(profile); count];
                let mut analog = Hashed {
                    counts: vec![0; count],
                    pending: vec![vec![]; count],
                    converted: (0..count).collect(),
                };
                let mut counts = vec![0u64; count];
                let mut clock = 0u64;
                for (run, &clocks) in lengths.iter().cycle().take(14).enumerate() {
                    let regs = run_registers(&mut rng);
                    let mut z_lanes = vec![vec![]; count];
                    lanes.run(isa, &regs, clocks, &mut analog, |l, i, z| {
                        z_lanes[l].push((clock + i, z))
                    });
                    let at = format!("{profile} ({isa}), {count} lanes, run {run} of {clocks}");
                    for (l, model) in alone.iter_mut().enumerate() {
                        let mut z = vec![];
                        let mut o = model.outputs();
                        for i in 0..clocks {
                            o = model.step(word(l, &mut counts[l], o.dac), &regs);
                            if o.z_valid {
                                z.push((clock + i, o.z));
                            }
                        }
                        assert_eq!(z_lanes[l], z, "{at}: lane {l}'s z");
                        let lane = &lanes.lanes()[l];
                        assert_eq!(lane.outputs(), o, "{at}: lane {l}'s ports");
                        assert_eq!(lane.probes(), model.probes(), "{at}: lane {l}'s signals");
                    }
                    clock += clocks;
                }
                let regs = run_registers(&mut rng);
                for (l, (mut lane, mut model)) in
                    lanes.into_inner().into_iter().zip(alone).enumerate()
                {
                    let (mut c, mut o) = (counts[l], model.outputs());
                    for i in 0..3000 {
                        o = model.step(word(l, &mut counts[l], o.dac), &regs);
                        let p = lane.step(word(l, &mut c, lane.outputs().dac), &regs);
                        assert_eq!(p, o, "{profile} ({isa}), lane {l}, step {i} after the runs");
                    }
                }
            }
        }
    }
}
