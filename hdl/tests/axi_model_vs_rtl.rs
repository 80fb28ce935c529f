//! The bit-true model of `gyro_interface_axi` against rust-hdl's simulation
//! of the design, on random bus traffic: AW, W, AR valids and B, R, stream
//! readies toggling at random (so AW and W come in either order or
//! together, B and R and the stream see backpressure), random addresses
//! (mapped, read-only and unmapped), random strobes and data, random ADC
//! words, and rare `aresetn` pulses. Every output on every cycle.

use gyrocal_hdl::host::model::{BusInputs, GyroInterfaceAxi};
use gyrocal_hdl::host::register_map;
use gyrocal_hdl::host::rtl::first_mismatch;
use gyrocal_hdl::host::traffic::{Bias, traffic};
use proptest::prelude::*;

/// Cycles per case: enough for more than 10 z samples at the least R
/// (`MIN_DECIMATION` = 166) between the traffic's random resets and rate
/// writes.
const CYCLES: usize = 5_000;

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
        let inputs = traffic(seed, Bias { valid, ready, tready }, CYCLES);
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
