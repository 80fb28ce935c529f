//! The bit-true model of `gyro_interface_axi` against rust-hdl's simulation
//! of the design, on random bus traffic: AW, W, AR valids and B, R, stream
//! readies toggling at random (so AW and W come in either order or
//! together, B and R and the stream see backpressure), random addresses
//! (mapped, read-only and unmapped), random strobes and data, random ADC
//! words, and rare `aresetn` pulses. Every output on every cycle.

use gyrocal_hdl::host::model::{BusInputs, GyroInterfaceAxi};
use gyrocal_hdl::host::register_map::{self, CIC_DECIMATION, CIC_SHIFT, REGISTERS, STREAM_ENABLE};
use gyrocal_hdl::host::rtl::first_mismatch;
use proptest::prelude::*;

const CYCLES: usize = 2_500;

/// SplitMix64 stream for the cycle-by-cycle traffic of one case.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// True with probability `percent` / 100.
    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
}

/// Bias of one case: how often each valid and ready is high.
#[derive(Clone, Copy, Debug)]
struct Bias {
    valid: u64,
    ready: u64,
    tready: u64,
}

/// A byte address: a register of the map mostly (sometimes misaligned),
/// any byte address otherwise (unmapped ones included). Never
/// CIC_DECIMATION: R stays as the preamble set it (16), since a large R
/// written at random would stop the z samples for thousands of clocks (the
/// core's own model-vs-rtl test covers every R).
fn address(rng: &mut Rng) -> u8 {
    loop {
        let a = match rng.next() % 8 {
            0 => rng.next() as u8,
            _ => {
                let r = &REGISTERS[rng.next() as usize % REGISTERS.len()];
                r.offset as u8 | ((rng.next() % 4) as u8 * u8::from(rng.chance(10)))
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
        (16 + (rng.next() % 24) as u32) | 1
    } else {
        rng.next() as u32
    }
}

fn traffic(seed: u64, bias: Bias) -> Vec<BusInputs> {
    let mut rng = Rng(seed);
    // Start with R = 16 and the stream on, through the bus itself.
    let preamble = [
        (CIC_DECIMATION.offset, 16),
        (CIC_SHIFT.offset, 8),
        (STREAM_ENABLE.offset, 1),
    ];
    let mut out = Vec::with_capacity(CYCLES);
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
    while out.len() < CYCLES {
        if !aw.0 && rng.chance(bias.valid) {
            aw = (true, address(&mut rng));
            if rng.chance(70) {
                w = (
                    true,
                    data(&mut rng),
                    if rng.chance(80) {
                        0xf
                    } else {
                        rng.next() as u8 & 0xf
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
            adc: (rng.next() as i16, rng.next() as i16),
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

/// What the traffic exercised, counted on the model.
#[derive(Debug, Default)]
struct Coverage {
    okay: usize,
    slverr: usize,
    reads: usize,
    samples: usize,
    streamed: usize,
    stalled: usize,
}

fn coverage(inputs: &[BusInputs]) -> Coverage {
    let mut model = GyroInterfaceAxi::new();
    let mut seen = Coverage::default();
    for i in inputs {
        let before = model.outputs();
        seen.samples += model.core_outputs().z_valid as usize;
        if before.bvalid && i.bready {
            if before.bresp == 0 {
                seen.okay += 1
            } else {
                seen.slverr += 1
            }
        }
        seen.reads += (before.rvalid && i.rready) as usize;
        seen.streamed += (before.tvalid && i.tready) as usize;
        seen.stalled += (before.tvalid && !i.tready) as usize;
        model.step(i);
    }
    seen
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]
    #[test]
    fn model_matches_rtl_on_random_bus_traffic(
        seed in any::<u64>(),
        valid in 5u64..90,
        ready in 5u64..100,
        tready in 0u64..100,
    ) {
        let inputs = traffic(seed, Bias { valid, ready, tready });
        let seen = coverage(&inputs);
        prop_assert!(seen.okay > 0 && seen.slverr > 0 && seen.reads > 0, "{:?}", seen);
        prop_assert!(seen.samples > 10, "{:?}", seen);
        let found = first_mismatch(&inputs);
        prop_assert!(found.is_none(), "{:?}", found);
    }
}

#[test]
fn the_map_has_a_word_the_traffic_can_miss() {
    // The generator's unmapped addresses exist: the map leaves words free.
    assert!((0..64u32).any(|i| register_map::lookup(i * 4).is_none()));
}
