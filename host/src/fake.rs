//! A fake board for examples and tests without the simulator: two
//! Lorentzian modes behind the register map, z their exact steady state
//! through the DAC hold's gain, each mode seen only through its own drive
//! as the gateware's readout sees it (`identify` module header). With
//! [`Lorentzian::ringing`] each mode also rings after a step of its drive,
//! from the state the step found, through the output filter of the
//! registers' coefficients (the filter's own transients are left out). It
//! runs in microseconds per measurement, so the host's logic can be shown
//! and tested alone; the simulated board (`gyrocal-sim`) is the real
//! check.
//!
//! ```
//! use gyrocal_host::fake::Lorentzian;
//! use gyrocal_host::board::Board;
//! use nalgebra::Complex;
//! let c = Complex::from_polar(2.0e9, -0.05);
//! let mut board = Lorentzian::new(50e6, [(9.64e6, 175.3, c), (9.64025e6, 175.3, c)], 0.0);
//! board.wait_clocks(1000).unwrap();
//! assert_eq!(board.read_z().unwrap().z, [0.0, 0.0]); // the drives are off at power-up
//! ```

use crate::board::{Board, ZSample};
use crate::device::GyroParams;
use crate::identify::settling::Resonance;
use crate::knowns::{Derived, Knowns};
use gyrocal_regs::datapath::{CIC_STAGES, COEFFICIENT_FRACTION_BITS, CarrierProfile, readout_word};
use gyrocal_regs::filter_design::cic_bit_growth;
use gyrocal_regs::map::{
    BusError, RegisterAccess, RegisterBank, SAMPLE_COUNT, Z1_HI, Z1_LO, Z2_HI, Z2_LO,
};
use nalgebra::Complex;
use std::f64::consts::TAU;

type C64 = Complex<f64>;

/// A datasheet like the paper's device's: modes at `f1_hz` and `f2_hz`,
/// Q 55,000 both, lambda 0.6, no couplings.
pub fn paper_datasheet(f1_hz: f64, f2_hz: f64) -> GyroParams {
    GyroParams {
        f1_hz,
        f2_hz,
        q1: 55e3,
        q2: 55e3,
        angular_gain: 0.6,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    }
}

/// What the host knows of a board like the paper's on this fake: the
/// `datasheet`, a 50 MHz clock with the carrier at 9.64 MHz, the paper's
/// filter (R 1000, Butterworth 500 Hz, RC 2 kHz) and the fine core, whose
/// words are the exact products this board takes.
pub fn paper_knowns(datasheet: GyroParams) -> Knowns {
    Knowns {
        filter: Derived {
            decimation: 1000,
            butterworth_hz: 500.0,
            rc_hz: 2000.0,
            min_window_s: 0.05,
        },
        carrier_profile: CarrierProfile::Fine,
        ..Knowns::exact(datasheet, 50e6, 9.64e6)
    }
}

/// Two modes, each seen only through its own drive, behind the register map.
pub struct Lorentzian {
    bank: RegisterBank,
    clock_hz: f64,
    cycle: u64,
    /// (fk, bk, C): Y = C / ((fk - f)(fk + f) + j f bk), ADC LSB per drive LSB.
    modes: [(f64, f64, C64); 2],
    /// Additive noise on z (z LSB, uniform +-).
    pub noise: f64,
    /// Each mode rings after a step of its drive (module header).
    pub ringing: bool,
    /// Per mode: the carrier (Hz) and readout word since its last step,
    /// the ringing's amplitude then (z's units over the word and dc / 2)
    /// and the step's cycle.
    rings: [(f64, f64, C64, u64); 2],
    state: u64,
    snapshot: [f64; 2],
}

impl Lorentzian {
    /// A board at power-up on a `clock_hz` clock whose modes are `modes`,
    /// each (fk Hz, bandwidth bk Hz, C), with `noise` z LSB of uniform noise.
    pub fn new(clock_hz: f64, modes: [(f64, f64, C64); 2], noise: f64) -> Self {
        Self {
            bank: RegisterBank::power_up_for(CarrierProfile::Fine),
            clock_hz,
            cycle: 0,
            modes,
            noise,
            ringing: false,
            rings: [(0.0, 0.0, C64::new(0.0, 0.0), 0); 2],
            state: 1,
            snapshot: [0.0; 2],
        }
    }

    /// The carrier (Hz) and each drive's readout word the registers set.
    fn drives(&self) -> (f64, [f64; 2]) {
        let r = self.bank.registers();
        let f = f64::from(r.carrier_step) * self.clock_hz / 2f64.powi(32);
        let w = [r.amp.0, r.amp.1].map(|a| readout_word(CarrierProfile::Fine, a));
        (f, w)
    }

    /// Mode m's steady response at `f` per drive LSB.
    fn steady(&self, m: usize, f: f64) -> C64 {
        let (f_hz, bandwidth_hz, c) = self.modes[m];
        let mode = Resonance {
            f_hz,
            bandwidth_hz,
            c,
        };
        mode.at(f, self.clock_hz)
    }

    /// Mode m's ringing now, in its carrier's frame (z's units over the
    /// word and dc / 2), and its complex frequency there (1/s).
    fn ring(&self, m: usize) -> (C64, C64) {
        let (fk, bk, _) = self.modes[m];
        let (f, _, a, t0) = self.rings[m];
        let s = C64::new(-std::f64::consts::PI * bk, TAU * (fk - f));
        let t = (self.cycle - t0) as f64 / self.clock_hz;
        (a * (s * t).exp(), s)
    }

    /// A step of the drives: each mode's state now, its new steady
    /// response and its ringing the difference (the carrier's phase goes
    /// on through the step, so its frame does too).
    fn stepped(&mut self) {
        let (f, w) = self.drives();
        for (m, w) in w.into_iter().enumerate() {
            let (f0, w0, _, _) = self.rings[m];
            let driven = if w0 > 0.0 {
                self.steady(m, f0) * w0
            } else {
                C64::new(0.0, 0.0)
            };
            let now = driven + self.ring(m).0;
            self.rings[m] = (f, w, now - self.steady(m, f) * w, self.cycle);
        }
    }

    /// The output filter's response at `s` (1/s) over its DC gain, from
    /// the registers: the CIC's four stages of R at the clock, the biquad
    /// 1 + z^-1 squared over 1 + a1 z^-1 + a2 z^-2 (a1 = -2 - k1, a2 = 1 -
    /// k2), written apart from `identify::filter_response`, which it checks,
    /// and the RC pole alpha / (1 - (1 - alpha) z^-1) at the output
    /// rate.
    fn filter_at(&self, s: C64) -> C64 {
        let r = self.bank.registers();
        let rr = f64::from(r.cic_decimation);
        let one = C64::new(1.0, 0.0);
        let x = s / self.clock_hz;
        let cic = if x.norm() == 0.0 {
            one
        } else {
            (one - (-x * rr).exp()) / ((one - (-x).exp()) * rr)
        };
        let scale = f64::from(1u32 << COEFFICIENT_FRACTION_BITS);
        let (a1, a2) = (
            -2.0 - f64::from(r.iir.k1) / scale,
            1.0 - f64::from(r.iir.k2) / scale,
        );
        let alpha = f64::from(r.iir.alpha) / scale;
        let zi = (-x * rr).exp();
        let biquad = (one + zi).powi(2) / (one + zi * a1 + zi * zi * a2) * ((1.0 + a1 + a2) / 4.0);
        let rc = alpha / (one - zi * (1.0 - alpha));
        cic.powi(CIC_STAGES as i32) * biquad * rc
    }

    fn z_now(&mut self) -> [f64; 2] {
        let r = self.bank.registers();
        // Exact products, as the fine core's words are.
        let (f, words) = self.drives();
        let theta =
            f64::from(r.ref_phase.wrapping_sub(r.carrier_step.div_ceil(2))) * TAU / 2f64.powi(32);
        let rr = f64::from(r.cic_decimation);
        let cic = rr.powi(4) / 2f64.powi(cic_bit_growth(u32::from(r.cic_decimation)) as i32);
        let k = r.iir;
        let dc = cic * 4.0 * f64::from(k.k0) / -(f64::from(k.k1) + f64::from(k.k2));
        std::array::from_fn(|m| {
            let mut y = self.steady(m, f);
            let w = words[m];
            if self.ringing && w > 0.0 {
                let (ring, s) = self.ring(m);
                y += ring * self.filter_at(s) / w;
            }
            self.state = self.state.wrapping_mul(6364136223846793005).wrapping_add(1);
            let n = ((self.state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * self.noise;
            dc / 2.0 * w * w * (y * C64::from_polar(1.0, -theta)).re + n
        })
    }

    fn count(&self) -> u32 {
        (self.cycle / u64::from(self.bank.registers().cic_decimation.max(1))) as u32
    }
}

fn words(z: f64) -> (u32, u32) {
    let raw = (z * 256.0).round() as i64;
    (raw as u32, (raw >> 32) as u32)
}

impl RegisterAccess for Lorentzian {
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        let before = self.drives();
        self.bank.write(offset, word, 0xf)?;
        if self.drives() != before {
            self.stepped();
        }
        Ok(())
    }

    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        let [z1, z2] = self.snapshot;
        Ok(match offset {
            o if o == SAMPLE_COUNT.offset => {
                self.snapshot = self.z_now();
                self.count()
            }
            o if o == Z1_LO.offset => words(z1).0,
            o if o == Z1_HI.offset => words(z1).1,
            o if o == Z2_LO.offset => words(z2).0,
            o if o == Z2_HI.offset => words(z2).1,
            o => match self.bank.read(o) {
                Ok(w) => w,
                Err(BusError::Unmapped) => return Err(BusError::Unmapped),
                Err(_) => 0,
            },
        })
    }
}

impl Board for Lorentzian {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        self.cycle += clocks;
        Ok(())
    }

    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
        let r = u64::from(self.bank.registers().cic_decimation.max(1));
        while self.count() == after {
            self.cycle += r - self.cycle % r;
        }
        self.read_z()
    }
}
