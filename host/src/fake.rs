//! A fake board for examples and tests without the simulator: two
//! Lorentzian modes behind the register map, z their exact steady state
//! (no transient) through the DAC hold's gain, each mode seen only
//! through its own drive as the gateware's readout sees it (`identify`
//! module header). It runs in microseconds per measurement, so the host's
//! logic can be shown and tested alone; the simulated board
//! (`gyrocal-sim`) is the real check.
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
use crate::theory::hold_gain;
use gyrocal_regs::datapath::{CarrierProfile, readout_word};
use gyrocal_regs::filter_design::cic_bit_growth;
use gyrocal_regs::map::{
    BusError, RegisterAccess, RegisterBank, SAMPLE_COUNT, Z1_HI, Z1_LO, Z2_HI, Z2_LO,
};
use nalgebra::Complex;
use std::f64::consts::TAU;

type C64 = Complex<f64>;

/// Two modes, each seen only through its own drive, behind the register map.
pub struct Lorentzian {
    bank: RegisterBank,
    clock_hz: f64,
    cycle: u64,
    /// (fk, bk, C): Y = C / ((fk - f)(fk + f) + j f bk), ADC LSB per drive LSB.
    modes: [(f64, f64, C64); 2],
    /// Additive noise on z (z LSB, uniform +-).
    pub noise: f64,
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
            state: 1,
            snapshot: [0.0; 2],
        }
    }

    fn z_now(&mut self) -> [f64; 2] {
        let r = self.bank.registers();
        let f = f64::from(r.carrier_step) * self.clock_hz / 2f64.powi(32);
        let theta =
            f64::from(r.ref_phase.wrapping_sub(r.carrier_step.div_ceil(2))) * TAU / 2f64.powi(32);
        let rr = f64::from(r.cic_decimation);
        let cic = rr.powi(4) / 2f64.powi(cic_bit_growth(u32::from(r.cic_decimation)) as i32);
        let k = r.iir;
        let dc = cic * 4.0 * f64::from(k.k0) / -(f64::from(k.k1) + f64::from(k.k2));
        let amps = [r.amp.0, r.amp.1];
        std::array::from_fn(|m| {
            let (fk, bk, c) = self.modes[m];
            let y = hold_gain(f, self.clock_hz) * c / C64::new((fk - f) * (fk + f), f * bk);
            // Exact products, as the fine core's words are.
            let w = readout_word(CarrierProfile::Fine, amps[m]);
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
        self.bank.write(offset, word, 0xf)
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
