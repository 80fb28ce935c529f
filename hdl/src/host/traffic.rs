//! Random bus traffic for `gyro_interface_axi`: the stimulus of the
//! model-vs-rtl comparison and of the golden vectors the exported Verilog
//! is replayed against. AW, W, AR valids and B, R, stream readies toggle at
//! random (AW and W come in either order or together; B, R and the stream
//! see backpressure), addresses are mapped, misaligned, read-only or
//! unmapped, strobes and data random, ADC words random, and `aresetn`
//! pulses low now and then. Valids drop at random whether taken or not:
//! the comparisons cover any input sequence, not only AXI-legal ones.

use super::model::BusInputs;
use super::register_map::{CIC_DECIMATION, CIC_SHIFT, REGISTERS, STREAM_ENABLE};

/// SplitMix64 stream for the cycle-by-cycle traffic of one case.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// True with probability `percent` / 100.
    pub fn chance(&mut self, percent: u64) -> bool {
        self.next_u64() % 100 < percent
    }
}

/// Bias of one case: how often each valid and ready is high.
#[derive(Clone, Copy, Debug)]
pub struct Bias {
    /// Percent of cycles a valid is raised when low.
    pub valid: u64,
    /// Percent of cycles B and R are ready.
    pub ready: u64,
    /// Percent of cycles the stream is ready.
    pub tready: u64,
}

/// A byte address: a register of the map mostly (sometimes misaligned),
/// any byte address otherwise (unmapped ones included). Never
/// CIC_DECIMATION: R stays as the preamble set it (16), since a large R
/// written at random would stop the z samples for thousands of clocks (the
/// core's own model-vs-rtl test covers every R).
fn address(rng: &mut Rng) -> u8 {
    loop {
        let a = match rng.next_u64() % 8 {
            0 => rng.next_u64() as u8,
            _ => {
                let r = &REGISTERS[rng.next_u64() as usize % REGISTERS.len()];
                r.offset as u8 | ((rng.next_u64() % 4) as u8 * u8::from(rng.chance(10)))
            }
        };
        if u32::from(a) & !3 != CIC_DECIMATION.offset {
            return a;
        }
    }
}

/// Write data: mostly a small odd number (STREAM_ENABLE then stays on),
/// any word otherwise. W may pair with any AW, so the data does not know
/// its register.
fn data(rng: &mut Rng) -> u32 {
    if rng.chance(70) {
        (16 + (rng.next_u64() % 24) as u32) | 1
    } else {
        rng.next_u64() as u32
    }
}

/// `cycles` cycles of traffic after a preamble that sets the least R
/// (`MIN_DECIMATION`, the fastest z) and turns the stream on through the
/// bus.
pub fn traffic(seed: u64, bias: Bias, cycles: usize) -> Vec<BusInputs> {
    let mut rng = Rng(seed);
    // Start with the least R and the stream on, through the bus itself.
    let r = crate::filter_design::MIN_DECIMATION;
    let shift = (4.0 * f64::from(r).log2()).ceil() as u32 - 8;
    let preamble = [
        (CIC_DECIMATION.offset, r),
        (CIC_SHIFT.offset, shift),
        (STREAM_ENABLE.offset, 1),
    ];
    let mut out = Vec::with_capacity(cycles);
    for (offset, word) in preamble {
        for _ in 0..3 {
            out.push(BusInputs {
                awvalid: true,
                awaddr: offset as u8,
                wvalid: true,
                wdata: word,
                ..BusInputs::default()
            });
        }
        out.push(BusInputs::default());
    }
    let mut aw = (false, 0u8);
    let mut w = (false, 0u32, 0xfu8);
    let mut ar = (false, 0u8);
    while out.len() < cycles {
        if !aw.0 && rng.chance(bias.valid) {
            aw = (true, address(&mut rng));
            if rng.chance(70) {
                w = (
                    true,
                    data(&mut rng),
                    if rng.chance(80) {
                        0xf
                    } else {
                        rng.next_u64() as u8 & 0xf
                    },
                );
            }
        }
        if !w.0 && rng.chance(bias.valid / 2) {
            w = (true, data(&mut rng), 0xf);
        }
        if !ar.0 && rng.chance(bias.valid) {
            ar = (true, address(&mut rng));
        }
        let i = BusInputs {
            aresetn: !rng.chance(1) || rng.chance(50),
            adc: (rng.next_u64() as i16, rng.next_u64() as i16),
            awvalid: aw.0,
            awaddr: aw.1,
            wvalid: w.0,
            wdata: w.1,
            wstrb: w.2,
            bready: rng.chance(bias.ready),
            arvalid: ar.0,
            araddr: ar.1,
            rready: rng.chance(bias.ready),
            tready: rng.chance(bias.tready),
        };
        out.push(i);
        // Valids drop at random, taken or not: the comparison covers any
        // input sequence, not only AXI-legal ones.
        if rng.chance(40) {
            aw.0 = false;
        }
        if rng.chance(40) {
            w.0 = false;
        }
        if rng.chance(40) {
            ar.0 = false;
        }
    }
    out
}
