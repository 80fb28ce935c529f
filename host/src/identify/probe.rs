//! One measurement of identification: mode k's complex response at one
//! carrier through drive k alone, I then Q, with the drive amplitude kept
//! below clipping (module header of `super`).

use super::settling::Arrival;
use super::{ADC_NEAR_CLIP, ADC_TARGET, C64, SAMPLES_PER_PHASE, SETTLE_TAUS, readout_word};
use crate::board::{Board, ZSample};
use crate::error::Error;
use crate::knowns::Knowns;
use crate::sampling::{collect, mean};
use gyrocal_regs::datapath::{CONVERTER_FULL_SCALE, PEAK};
use gyrocal_regs::map::{ADC_CLIP, SAMPLE_COUNT};

/// Measures mode k's complex response through one drive.
pub(super) struct Prober<'a> {
    board: &'a mut dyn Board,
    knowns: &'a Knowns,
    k: usize,
    /// Drive amplitude in use (fraction of full scale).
    amplitude: f64,
    /// Amplitude time constant waited on (s): the datasheet's until the
    /// coarse search has measured the mode's bandwidth.
    pub(super) tau_s: f64,
    /// Clocks spent.
    pub(super) clocks: u64,
    /// The carrier (Hz) and readout word of drive k's last measurement
    /// (0 for both before any: this prober found the drive off).
    last: (f64, f64),
}

impl Prober<'_> {
    /// Clocks waited after a carrier step before the I window: the
    /// resonator's `SETTLE_TAUS` time constants and the filter's settling.
    fn settle_clocks(&self) -> u64 {
        let kn = self.knowns;
        (SETTLE_TAUS * self.tau_s * kn.clock_hz).ceil() as u64 + kn.filter_settle_clocks()
    }

    /// The same in seconds.
    pub(super) fn waited_s(&self) -> f64 {
        self.settle_clocks() as f64 / self.knowns.clock_hz
    }

    /// Seconds from a point's I window's start to its Q window's: the I
    /// window and the filter's wait after the REF_PHASE step
    /// (`measure_once`).
    pub(super) fn quarter_s(&self) -> f64 {
        let kn = self.knowns;
        super::window_s(kn) + kn.filter_settle_clocks() as f64 / kn.clock_hz
    }
}

/// What one measurement saw.
struct Seen {
    /// Realized carrier (Hz).
    carrier_hz: f64,
    /// Y (ADC LSB per drive LSB).
    y: C64,
    /// The response's amplitude at the ADC over full scale.
    full_scale: f64,
    /// Clocks on which ADC k read a rail code.
    clipped: u32,
    /// What the resonator carried into it, and when its windows saw it.
    arrival: Arrival,
}

impl<'a> Prober<'a> {
    /// A prober of mode `k` starting at `amplitude` (fraction of full scale).
    pub(super) fn new(
        board: &'a mut dyn Board,
        knowns: &'a Knowns,
        k: usize,
        amplitude: f64,
    ) -> Self {
        Self {
            board,
            knowns,
            k,
            amplitude,
            tau_s: knowns.tau_s(k),
            clocks: 0,
            last: (0.0, 0.0),
        }
    }

    /// The drive amplitude in use (fraction of full scale).
    pub(super) fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// The mode (1 or 2), for messages.
    pub(super) fn mode(&self) -> usize {
        self.k + 1
    }

    /// The Q of the mode the search starts from: the datasheet's, or a
    /// second try's (`super::identify_mode`).
    pub(super) fn q_guess(&self) -> f64 {
        self.knowns.nominal.q(self.k)
    }

    /// What the host knows of the board.
    pub(super) fn knowns(&self) -> &'a Knowns {
        self.knowns
    }

    /// The clock (Hz).
    pub(super) fn clock_hz(&self) -> f64 {
        self.knowns.clock_hz
    }

    /// ADC k's clip count since the last read of ADC_CLIP.
    fn clip_count(&mut self) -> Result<u32, Error> {
        let word = self.board.read_register(ADC_CLIP.offset)?;
        Ok((word >> (16 * self.k)) & 0xffff)
    }

    /// Y at `carrier_hz`: I, then Q a quarter turn later, with SAMPLE_COUNT
    /// read either side of the carrier step, which brackets it
    /// (`Arrival::from_counts`).
    fn measure_once(&mut self, carrier_hz: f64) -> Result<Seen, Error> {
        let kn = self.knowns;
        let amps = if self.k == 0 {
            (self.amplitude, 0.0)
        } else {
            (0.0, self.amplitude)
        };
        let (regs, real) = kn.registers(carrier_hz, None, amps, 0.0)?;
        let before = self.board.read_register(SAMPLE_COUNT.offset)?;
        self.board.program(&regs)?;
        let after = self.board.read_register(SAMPLE_COUNT.offset)?;
        let r = kn.filter.decimation;
        let settle = self.settle_clocks();
        self.board.wait_clocks(settle)?;
        self.clip_count()?;
        let i = collect(self.board, 0, SAMPLES_PER_PHASE)?;
        let mut quarter = regs;
        quarter.ref_phase = regs.ref_phase.wrapping_add(1 << 30);
        self.board.program(&quarter)?;
        let filter = kn.filter_settle_clocks();
        let q = collect(self.board, filter, SAMPLES_PER_PHASE)?;
        let clipped = self.clip_count()?;
        self.clocks += settle + filter + 2 * SAMPLES_PER_PHASE * u64::from(r);
        let amp_word = [regs.amp.0, regs.amp.1][self.k];
        let w = readout_word(kn.carrier_profile, amp_word);
        let y =
            C64::new(mean(&i)[self.k], mean(&q)[self.k]) * (2.0 / (real.filter.dc_gain * w * w));
        let counts = |s: &[ZSample]| -> Vec<u32> { s.iter().map(|s| s.count).collect() };
        let arrival = Arrival::from_counts(
            (self.last.0, self.last.1 / w),
            (before, after),
            (&counts(&i), &counts(&q)),
            f64::from(r) / kn.clock_hz,
        );
        self.last = (real.carrier_hz, w);
        Ok(Seen {
            carrier_hz: real.carrier_hz,
            y,
            full_scale: y.norm() * w / CONVERTER_FULL_SCALE,
            clipped,
            arrival,
        })
    }

    /// `measure_once`, again at a quarter of the amplitude while the ADC
    /// clips or comes near it; returns the realized carrier and Y.
    pub(super) fn measure(&mut self, carrier_hz: f64) -> Result<(f64, C64), Error> {
        self.measure_arriving(carrier_hz).map(|(f, y, _)| (f, y))
    }

    /// [`Prober::measure`], with what the resonator carried into the
    /// measurement that was kept (after a clipped one, the same carrier
    /// at four times the drive).
    pub(super) fn measure_arriving(
        &mut self,
        carrier_hz: f64,
    ) -> Result<(f64, C64, Arrival), Error> {
        loop {
            let seen = self.measure_once(carrier_hz)?;
            if seen.clipped == 0 && seen.full_scale <= ADC_NEAR_CLIP {
                return Ok((seen.carrier_hz, seen.y, seen.arrival));
            }
            self.amplitude /= 4.0;
            if self.amplitude * 32768.0 < 1.0 {
                return Err(Error::Identification {
                    mode: self.mode(),
                    reason: format!(
                        "the response at {carrier_hz:.3} Hz clips ADC {} even at one DAC LSB ({} clipped clocks)",
                        self.mode(),
                        seen.clipped
                    ),
                });
            }
        }
    }

    /// Drive amplitude that puts a peak response `peak` (per drive LSB) at
    /// `ADC_TARGET` of full scale, at most the readout amplitude.
    pub(super) fn set_amplitude_for_peak(&mut self, peak: f64) {
        let max = [self.knowns.amplitude.0, self.knowns.amplitude.1][self.k].abs();
        // Word amplitude ~ a x PEAK^2 / 2^15 per unit amplitude.
        let per_unit = f64::from(PEAK) * f64::from(PEAK) / 32768.0;
        let wanted = ADC_TARGET * CONVERTER_FULL_SCALE / (peak * per_unit);
        if wanted.is_finite() && wanted > 0.0 {
            self.amplitude = wanted.min(max);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::board::ZSample;
    use crate::fake::{Lorentzian, paper_datasheet, paper_knowns};
    use gyrocal_regs::Registers;
    use gyrocal_regs::map::{BusError, RegisterAccess};

    /// A fake board that notes the count of the first sample read after
    /// each programming: the start of each window a measurement reads.
    struct Timed {
        board: Lorentzian,
        programs: usize,
        firsts: Vec<u32>,
    }

    impl RegisterAccess for Timed {
        fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
            self.board.write_register(offset, word)
        }
        fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
            self.board.read_register(offset)
        }
    }

    impl Board for Timed {
        fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
            self.board.wait_clocks(clocks)
        }
        fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
            let s = self.board.next_sample(after)?;
            if self.firsts.len() < self.programs {
                self.firsts.push(s.count);
            }
            Ok(s)
        }
        fn program(&mut self, regs: &Registers) -> Result<(), BusError> {
            self.programs += 1;
            self.board.program(regs)
        }
    }

    /// `measure_arriving` notes what each measurement's step came from
    /// (the drive off before the first; the last carrier and its readout
    /// word over this one's after) and when the windows' samples came after
    /// it: the I window's first `waited_s` after, within the step's place
    /// in its sample (the times are the middle's, +-half a sample) and the
    /// sample the window waits for (up to one more), the Q window's
    /// `quarter_s` after that (within a sample, as
    /// `the_q_window_starts_quarter_s_after_the_i_window` finds), one sample
    /// between each.
    #[test]
    fn each_measurement_arrives_from_the_last() {
        let c = C64::from_polar(2.0e9, -0.05);
        let (f1, clock_hz) = (9.64e6, 50e6);
        let mut board = Lorentzian::new(clock_hz, [(f1, 175.3, c), (f1 + 250.0, 175.3, c)], 0.0);
        let knowns = paper_knowns(paper_datasheet(f1, f1 + 250.0));
        let sample = f64::from(knowns.filter.decimation) / clock_hz;
        let mut prober = Prober::new(&mut board, &knowns, 0, 0.1);
        let (below, _, first) = prober.measure_arriving(f1 - 100.0).unwrap();
        assert_eq!(first.from_scale, 0.0);
        let (above, _, second) = prober.measure_arriving(f1 + 100.0).unwrap();
        assert_eq!((second.from_hz, second.from_scale), (below, 1.0));
        let late = second.i_s[0] - prober.waited_s();
        assert!(
            (-0.5 * sample..=1.5 * sample).contains(&late),
            "{late} s late"
        );
        assert_eq!((second.i_s.len(), second.q_s.len()), (128, 128));
        for times in [&second.i_s, &second.q_s] {
            assert!(
                times
                    .windows(2)
                    .all(|w| (w[1] - w[0] - sample).abs() < 1e-12)
            );
        }
        let quarter = second.q_s[0] - second.i_s[0] - prober.quarter_s();
        assert!(quarter.abs() <= sample, "{quarter} s");
        prober.amplitude = 0.025;
        let (_, _, third) = prober.measure_arriving(f1 + 100.0).unwrap();
        let scale = readout_word(knowns.carrier_profile, (0.1 * 32768.0) as i16)
            / readout_word(knowns.carrier_profile, (0.025 * 32768.0) as i16);
        assert_eq!(third.from_hz, above);
        assert!(
            (third.from_scale / scale - 1.0).abs() < 1e-3,
            "{}",
            third.from_scale
        );
    }

    /// `Prober::quarter_s`, which the settling sigma reads
    /// (`super::super::settle_sd`), is the time a board sees from a
    /// point's I window's first sample to its Q window's, within one
    /// sample (R clocks): both windows' samples counted on a fake board
    /// while `measure_once` reads them.
    #[test]
    fn the_q_window_starts_quarter_s_after_the_i_window() {
        let c = C64::from_polar(2.0e9, -0.05);
        let (f1, f2, clock_hz) = (9.64e6, 9.64025e6, 50e6);
        let board = Lorentzian::new(clock_hz, [(f1, 175.3, c), (f2, 175.3, c)], 0.0);
        let mut board = Timed {
            board,
            programs: 0,
            firsts: vec![],
        };
        let knowns = paper_knowns(paper_datasheet(f1, f2));
        let mut prober = Prober::new(&mut board, &knowns, 0, 0.1);
        prober.measure_once(f1).unwrap();
        let quarter = prober.quarter_s() * clock_hz;
        let r = f64::from(knowns.filter.decimation);
        let firsts = &board.firsts;
        assert_eq!(firsts.len(), 2, "two windows: {firsts:?}");
        let seen = f64::from(firsts[1] - firsts[0]) * r;
        assert!(
            (seen - quarter).abs() <= r,
            "the board saw {seen} clocks, quarter_s says {quarter}"
        );
    }
}
