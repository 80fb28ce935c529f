//! The simulated board: a datapath engine (the bit-true model by default),
//! the converters and the gyroscope at one temperature behind the register
//! map, as host code (`gyrocal_host`, through its [`Board`] trait) sees a
//! real one.
//!
//! [`SimBoard`] closes the loop of an engine over the gyroscope at
//! one temperature ([`crate::drift::DeviceAt`]): drive gains scale the DAC
//! forces, ADC gains the pick-offs, and an unmodelled phase lag
//! ([`crate::frontend::PickoffPhase`]) sits before both ADCs. Per clock,
//! as in [`crate::cosim`]: the ADCs sample, the engine plays an edge, the
//! gyroscope advances under the held force. Register writes act from the
//! next clock on; the settings are decoded from the bank once per write.
//!
//! The rotation rate is not a register: [`SimBoard::set_rate`] is the rate
//! table of the simulation harness, which host code (that sees a
//! `&mut dyn Board`) cannot reach.

use crate::analog::{Analog, Watched};
use crate::cosim::HostRegisters;
use crate::drift::DeviceAt;
use crate::engine::{Engine, ModelEngine};
use crate::error::RunError;
use crate::frontend::{Converters, FrontEnd, PickoffPhase};
use crate::gyro::GyroModel;
use crate::noise::ThermalNoise;
use gyrocal_hdl::host::clip_counter::{ClipCount, clip_word};
use gyrocal_hdl::model::gyro_interface::{CarrierProfile, Outputs, Words};
pub use gyrocal_host::board::{Board, ZSample};
use gyrocal_regs::map::{ADC_CLIP, BusError, RegisterAccess};

/// An engine (`E`: the model engine unless asked otherwise, e.g.
/// `crate::verilator::VerilatorEngine`), converters and gyroscope behind
/// the register map.
pub struct SimBoard<E: Engine = ModelEngine> {
    engine: E,
    analog: Analog,
    host: HostRegisters,
    outputs: Outputs,
    samples: u32,
    cycle: u64,
    clip: [ClipCount; 2],
}

impl<E: Engine> SimBoard<E> {
    /// A board at power-up with the device and front end of `at`:
    /// `front_end` holds the converters as built (gains at T0), which
    /// `at`'s drive and ADC multipliers scale; the front-end phase lag is
    /// exact at `phase_reference_hz`; `noise` is the Brownian force noise.
    pub fn new(
        at: &DeviceAt,
        front_end: &FrontEnd,
        noise: &ThermalNoise,
        clock_hz: f64,
        phase_reference_hz: f64,
        profile: CarrierProfile,
    ) -> Result<Self, RunError> {
        Ok(Self {
            engine: E::power_up(profile)?,
            analog: analog_at(at, front_end, noise, clock_hz, phase_reference_hz)?,
            host: HostRegisters::power_up(profile),
            outputs: Outputs::default(),
            samples: 0,
            cycle: 0,
            clip: [ClipCount::default(); 2],
        })
    }

    /// The rate table: rotation rate (rad/s) from the next clock on.
    pub fn set_rate(&mut self, omz_rad_s: f64) {
        self.analog.gyro.set_rate(omz_rad_s);
    }

    /// Clocks played since power-up.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// One clock; returns the ADC words the core read during it.
    #[inline(always)]
    fn step(&mut self) -> Words {
        let adc = self.analog.step(self.outputs.dac);
        self.clip[0].step(adc.0, false);
        self.clip[1].step(adc.1, false);
        self.outputs = self.engine.step(adc, self.host.registers());
        self.samples = self.samples.wrapping_add(self.outputs.z_valid as u32);
        self.cycle += 1;
        adc
    }

    /// `step` `clocks` times, in the engine's blocks (`Engine::run`).
    fn run(&mut self, clocks: u64) {
        if clocks == 0 {
            return;
        }
        let Self {
            engine,
            analog,
            host,
            outputs,
            samples,
            cycle,
            clip,
        } = self;
        let mut analog = Watched {
            analog,
            watch: |adc: &[Words]| {
                clip[0].steps(adc.iter().map(|a| a.0));
                clip[1].steps(adc.iter().map(|a| a.1));
            },
        };
        let on_z = |_, _| *samples = samples.wrapping_add(1);
        *outputs = engine.run(outputs.dac, host.registers(), clocks, &mut analog, on_z);
        *cycle += clocks;
    }
}

/// A board's analog side at `at` (`SimBoard::new`): `front_end` as built,
/// scaled by `at`'s drive and ADC multipliers, the pick-off's phase lag
/// exact at `phase_reference_hz`, the gyroscope with the Brownian `noise`.
pub fn analog_at(
    at: &DeviceAt,
    front_end: &FrontEnd,
    noise: &ThermalNoise,
    clock_hz: f64,
    phase_reference_hz: f64,
) -> Result<Analog, RunError> {
    let mut fe = front_end.clone();
    for k in 0..2 {
        fe.force_per_lsb[k] *= at.drive_gain[k];
        fe.adc_per_meter[k] *= at.adc_gain[k];
    }
    let p = at.front_end_phase_deg;
    let phase = if p == 0.0 {
        None
    } else {
        Some(PickoffPhase::new(p, phase_reference_hz)?)
    };
    Ok(Analog::new(
        Converters::new(&fe)?,
        GyroModel::new(&at.gyro, clock_hz)?.with_thermal_noise(noise)?,
        phase,
    ))
}

impl<E: Engine> Board for SimBoard<E> {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        self.run(clocks);
        Ok(())
    }

    /// Plays the clock until the count moves past `after` (at most R
    /// clocks when `after` is the current count), then reads the snapshot:
    /// the edges that cannot publish (`Engine::quiet_clocks`) in one run,
    /// the rest one at a time.
    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
        while self.samples == after {
            match self.engine.quiet_clocks() {
                0 => {
                    self.step();
                }
                quiet => self.run(quiet),
            }
        }
        self.read_z()
    }
}

impl<E: Engine> RegisterAccess for SimBoard<E> {
    /// A write between two clocks: acts from the next clock on.
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.host.write(offset, word)
    }

    /// A read between two clocks; SAMPLE_COUNT latches z, ADC_CLIP returns
    /// the over-range counts and restarts them. STREAM_OVERFLOW is 0: the
    /// board has no stream consumer.
    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        if offset & !3 == ADC_CLIP.offset {
            let word = clip_word(self.clip);
            self.clip = [ClipCount::default(); 2];
            return Ok(word);
        }
        self.host.read(offset, self.outputs.z, self.samples)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::config::Experiment;
    use crate::field::scenario;
    use gyrocal_hdl::host::clip_counter::at_rail;

    /// The paper's board in readout at 50 deg/s, ADC noise on, with a
    /// front-end phase lag (the path `run` takes through `PickoffPhase`)
    /// and ADC 1's gain 4 times too high, so that it clips.
    /// `exp`'s board as built, its readout registers at the configured
    /// carrier, and the device at 25 deg C behind a 3 deg pick-off lag
    /// with ADC gains `adc_gain` times the board's.
    pub(in crate::field) fn readout_setting(
        exp: &Experiment,
        adc_gain: [f64; 2],
    ) -> (
        FrontEnd,
        gyrocal_hdl::model::gyro_interface::Registers,
        DeviceAt,
    ) {
        let (fe, knowns) = scenario::build(exp).unwrap();
        let (regs, _) = knowns
            .registers(exp.drive.carrier_hz, None, knowns.amplitude, 0.0)
            .unwrap();
        let at = DeviceAt {
            temperature_c: 25.0,
            delta_k: 0.0,
            gyro: exp.gyro.clone(),
            adc_gain,
            drive_gain: [1.0; 2],
            front_end_phase_deg: 3.0,
        };
        (fe, regs, at)
    }

    fn readout_board() -> SimBoard {
        readout_board_of(Experiment::paper())
    }

    fn readout_board_of(exp: Experiment) -> SimBoard {
        let (fe, regs, at) = readout_setting(&exp, [4.0, 1.0]);
        let mut board = scenario::board_at(&exp, &fe, &at).unwrap();
        board.program(&regs).unwrap();
        board.set_rate(50f64.to_radians());
        board
    }

    /// `wait_clocks` and `next_sample` (which play the engine's blocks)
    /// leave the board where `step` one clock at a time does: the same
    /// samples with the same counts, the same clip counts, the same
    /// gyroscope state and clock, over waits of odd lengths.
    #[test]
    fn waits_and_samples_play_the_clocks_one_by_one() {
        let (mut blocked, mut stepped) = (readout_board(), readout_board());
        let mut after = (0, 0);
        for (k, wait) in [0u64, 1, 255, 256, 257, 10_000, 3, 40_000]
            .iter()
            .cycle()
            .take(40)
            .enumerate()
        {
            blocked.wait_clocks(*wait).unwrap();
            for _ in 0..*wait {
                stepped.step();
            }
            let a = blocked.next_sample(after.0).unwrap();
            while stepped.samples == after.1 {
                stepped.step();
            }
            let b = stepped.read_z().unwrap();
            assert_eq!(a, b, "sample {k}");
            assert_eq!(blocked.cycle(), stepped.cycle(), "sample {k}");
            after = (a.count, b.count);
        }
        assert!(after.0 > 100, "{} samples", after.0);
        assert_eq!(blocked.analog.gyro.state(), stepped.analog.gyro.state());
        let clip = blocked.read_register(ADC_CLIP.offset).unwrap();
        assert_ne!(clip, 0, "ADC 1 never clipped");
        assert_eq!(Ok(clip), stepped.read_register(ADC_CLIP.offset));
    }

    /// A 12-bit ADC driven past its range: ADC_CLIP counts the clocks at
    /// both its rails, the positive one +32752 (left-justified; a compare
    /// with +32767 counted none of them), and at its codes within 1/128
    /// of full scale beside them, and no others.
    #[test]
    fn a_12_bit_adc_is_counted_at_both_rails() {
        let mut exp = Experiment::paper();
        exp.frontend.adc_bits = 12;
        let mut board = readout_board_of(exp);
        board.wait_clocks(100_000).unwrap();
        board.read_register(ADC_CLIP.offset).unwrap();
        let rails = [32_752i16, i16::MIN];
        let (mut at, mut band) = ([0u32; 2], 0);
        for _ in 0..20_000 {
            let adc = board.step().0;
            for (n, rail) in at.iter_mut().zip(rails) {
                *n += u32::from(adc == rail);
            }
            band += u32::from(at_rail(adc));
        }
        assert!(at[0] > 100 && at[1] > 100, "rails reached {at:?} times");
        let clip = board.read_register(ADC_CLIP.offset).unwrap();
        assert_eq!(clip & 0xffff, band);
        // The band beside the rails: 12-bit codes from +32512 up, and
        // the negative rail's word alone.
        assert!(
            band > at[0] + at[1] && band < 2 * (at[0] + at[1]),
            "{band} in the band"
        );
    }
}
