//! A fake board for the host's tests: a register bank whose SAMPLE_COUNT
//! moves by a scripted amount at every read, and whose z is the count
//! (z1 = count, z2 = -count, in z LSB), latched by the SAMPLE_COUNT read.
//! No simulator: time is whatever the script says.

#![allow(dead_code)] // reason: each test crate uses part of it

use gyrocal_regs::map::{
    BusError, ID, ID_WORD, RegisterAccess, RegisterBank, SAMPLE_COUNT, STREAM_OVERFLOW, VERSION,
    VERSION_WORD, Z1_HI, Z1_LO, Z2_HI, Z2_LO,
};
use std::time::Instant;

/// The fake board.
pub struct Fake {
    /// The settings.
    pub bank: RegisterBank,
    /// SAMPLE_COUNT now.
    pub count: u32,
    /// How far the count moves at each SAMPLE_COUNT read, cycled.
    pub steps: Vec<u32>,
    /// SAMPLE_COUNT reads so far.
    pub count_reads: usize,
    /// A board clocked in wall time instead: one sample per millisecond
    /// since this instant.
    pub clocked: Option<Instant>,
    latched: u32,
}

impl Fake {
    /// A fake starting at `count` whose count moves by `steps` (cycled).
    pub fn new(count: u32, steps: &[u32]) -> Self {
        Self {
            bank: RegisterBank::power_up(),
            count,
            steps: steps.to_vec(),
            count_reads: 0,
            clocked: None,
            latched: count,
        }
    }

    /// A fake whose count moves one sample per millisecond of wall time.
    pub fn clocked() -> Self {
        Self {
            clocked: Some(Instant::now()),
            ..Self::new(0, &[0])
        }
    }

    fn z_words(z: i64) -> (u32, u32) {
        let raw = z * 256;
        (raw as u32, (raw >> 32) as u32)
    }
}

impl RegisterAccess for Fake {
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.bank.write(offset, word, 0xf)
    }

    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        let z1 = Self::z_words(i64::from(self.latched));
        let z2 = Self::z_words(-i64::from(self.latched));
        match offset {
            o if o == SAMPLE_COUNT.offset => {
                let step = self.steps[self.count_reads % self.steps.len()];
                self.count_reads += 1;
                self.count = match self.clocked {
                    Some(t0) => t0.elapsed().as_millis() as u32,
                    None => self.count.wrapping_add(step),
                };
                self.latched = self.count;
                Ok(self.count)
            }
            o if o == ID.offset => Ok(ID_WORD),
            o if o == VERSION.offset => Ok(VERSION_WORD),
            o if o == STREAM_OVERFLOW.offset => Ok(0),
            o if o == Z1_LO.offset => Ok(z1.0),
            o if o == Z1_HI.offset => Ok(z1.1),
            o if o == Z2_LO.offset => Ok(z2.0),
            o if o == Z2_HI.offset => Ok(z2.1),
            o => self.bank.read(o),
        }
    }
}
