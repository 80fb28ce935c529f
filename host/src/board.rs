//! A board as host code sees it: 32-bit registers at the byte offsets of
//! the register map (`gyrocal_regs::map`), coherent z snapshots, and time
//! measured in FPGA clocks.
//!
//! Every board implements [`Board`]: the simulator's in-process board
//! (`gyrocal_sim::field::board::SimBoard`, which steps its clock exactly),
//! and any transport that only reads and writes registers, through
//! [`Polled`], which measures time by `SAMPLE_COUNT` (one count per z
//! sample, every R clocks) and never by the wall clock: a board over
//! Etherbone ([`crate::transport::etherbone`]) or memory-mapped
//! ([`crate::transport::mmap`]).
//!
//! ```text
//!   host code ──► &mut dyn Board ──┬── SimBoard (in process, exact clocks)
//!                                  └── Polled<T: RegisterAccess> ──┬── Etherbone over TCP
//!                                                                  ├── /dev/uioN, /dev/mem
//!                                                                  └── a test's fake board
//! ```

use gyrocal_regs::Registers;
use gyrocal_regs::map::{
    self, BusError, CIC_DECIMATION, RegisterAccess, SAMPLE_COUNT, Z1_HI, Z1_LO, Z2_HI, Z2_LO,
};
use std::time::{Duration, Instant};

/// One coherent z snapshot: the count and both outputs, in z LSB
/// (2^-8 mixer LSB, the register's raw value over 256).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZSample {
    /// SAMPLE_COUNT at the snapshot (wraps at 2^32).
    pub count: u32,
    /// z1, z2 (z LSB).
    pub z: [f64; 2],
}

/// z in z LSB from its two register words (the high word sign-extended).
pub fn z_from_words(lo: u32, hi: u32) -> f64 {
    ((i64::from(hi as i32) << 32) | i64::from(lo)) as f64 / 256.0
}

/// The reads of one coherent snapshot, in order: SAMPLE_COUNT latches z.
pub const SNAPSHOT: [u32; 5] = [
    SAMPLE_COUNT.offset,
    Z1_LO.offset,
    Z1_HI.offset,
    Z2_LO.offset,
    Z2_HI.offset,
];

/// A gateware board: registers, z snapshots, time.
pub trait Board: RegisterAccess {
    /// Let at least `clocks` periods of the FPGA clock pass.
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError>;

    /// Read SAMPLE_COUNT (which latches z) then the four z words.
    fn read_z(&mut self) -> Result<ZSample, BusError> {
        let w = self.read_registers(&SNAPSHOT)?;
        Ok(ZSample {
            count: w[0],
            z: [z_from_words(w[1], w[2]), z_from_words(w[3], w[4])],
        })
    }

    /// The first z sample whose count differs from `after` (the count of
    /// the last sample read): the next one if the host keeps up, a later
    /// one if samples went by meanwhile (the count tells).
    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError>;

    /// Write every setting of `regs` (the register map's own encoding).
    fn program(&mut self, regs: &Registers) -> Result<(), BusError> {
        map::encode(regs)
            .into_iter()
            .try_for_each(|(offset, word)| self.write_register(offset, word))
    }
}

/// How long `Polled` waits for SAMPLE_COUNT to move before it reports the
/// board stopped (wall time: a hang detector, not a clock).
pub const STALL_TIMEOUT: Duration = Duration::from_secs(20);

/// A board reached only through its registers: time from SAMPLE_COUNT.
///
/// It keeps the decimation R it last wrote (or read at [`Polled::new`]),
/// so that "let N clocks pass" becomes "let ceil(N / R) + 1 samples pass"
/// (the first count change may come at once, so one more than N / R
/// guarantees N clocks).
///
/// ```
/// use gyrocal_host::board::{Board, Polled};
/// use gyrocal_regs::map::{BusError, CIC_DECIMATION, RegisterAccess, SAMPLE_COUNT};
///
/// /// A register file whose SAMPLE_COUNT moves by one sample at each read.
/// struct Ticking {
///     count: u32,
///     r: u32,
/// }
///
/// impl RegisterAccess for Ticking {
///     fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
///         if offset == CIC_DECIMATION.offset {
///             self.r = word;
///         }
///         Ok(())
///     }
///     fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
///         Ok(match offset {
///             o if o == SAMPLE_COUNT.offset => {
///                 self.count += 1;
///                 self.count
///             }
///             o if o == CIC_DECIMATION.offset => self.r,
///             _ => 0,
///         })
///     }
/// }
///
/// let mut board = Polled::new(Ticking { count: 0, r: 250 })?; // reads R = 250
/// board.wait_clocks(1000)?; // from count 1 until 1 + 1000 / 250 + 1 = 6
/// let s = board.read_z()?;
/// assert_eq!(s.count, 7);
/// # Ok::<(), BusError>(())
/// ```
pub struct Polled<T: RegisterAccess> {
    inner: T,
    decimation: u32,
}

impl<T: RegisterAccess> Polled<T> {
    /// Wraps a register transport; reads CIC_DECIMATION to know R.
    pub fn new(mut inner: T) -> Result<Self, BusError> {
        let decimation = inner.read_register(CIC_DECIMATION.offset)?.max(1);
        Ok(Self { inner, decimation })
    }

    /// The transport.
    pub fn inner_mut(&mut self) -> &mut T {
        &mut self.inner
    }

    /// Poll SAMPLE_COUNT until `done(count)` holds; an error if it stops
    /// moving for `STALL_TIMEOUT`.
    fn poll_until(&mut self, mut done: impl FnMut(u32) -> bool) -> Result<u32, BusError> {
        let mut last = self.inner.read_register(SAMPLE_COUNT.offset)?;
        let mut moved = Instant::now();
        loop {
            if done(last) {
                return Ok(last);
            }
            let c = self.inner.read_register(SAMPLE_COUNT.offset)?;
            if c != last {
                last = c;
                moved = Instant::now();
            } else if moved.elapsed() > STALL_TIMEOUT {
                return Err(BusError::Transport(format!(
                    "SAMPLE_COUNT stayed at {c} for {} s: is the core clocked and CIC_DECIMATION valid?",
                    STALL_TIMEOUT.as_secs()
                )));
            }
        }
    }
}

impl<T: RegisterAccess> RegisterAccess for Polled<T> {
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.inner.write_register(offset, word)?;
        if offset == CIC_DECIMATION.offset {
            self.decimation = (word & CIC_DECIMATION.mask()).max(1);
        }
        Ok(())
    }

    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        self.inner.read_register(offset)
    }

    fn read_registers(&mut self, offsets: &[u32]) -> Result<Vec<u32>, BusError> {
        self.inner.read_registers(offsets)
    }
}

impl<T: RegisterAccess> Board for Polled<T> {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        let samples = clocks.div_ceil(u64::from(self.decimation)) + 1;
        let start = self.inner.read_register(SAMPLE_COUNT.offset)?;
        self.poll_until(|c| u64::from(c.wrapping_sub(start)) >= samples)?;
        Ok(())
    }

    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
        let start = Instant::now();
        loop {
            let s = self.read_z()?;
            if s.count != after {
                return Ok(s);
            }
            if start.elapsed() > STALL_TIMEOUT {
                return Err(BusError::Transport(format!(
                    "SAMPLE_COUNT stayed at {after} for {} s: is the core clocked?",
                    STALL_TIMEOUT.as_secs()
                )));
            }
        }
    }
}
