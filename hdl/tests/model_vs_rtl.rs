//! The bit-true model against rust-hdl's simulation of the design: random
//! register settings (any value a register can hold, valid or not) and
//! random ADC stimulus, every output on every cycle, both modes, full-scale
//! and most-negative words included. 12 cases of 9,000 cycles: 108,000
//! cycles per run (about 15 s in release).

use gyrocal_hdl::filter_design::MIN_DECIMATION;
use gyrocal_hdl::model::gyro_interface::Registers;
use gyrocal_hdl::model::iir_lowpass::Coefficients;
use gyrocal_hdl::rtl::{RtlGyroInterface, first_mismatch};
use gyrocal_hdl::settings::{FrequencyPlan, registers};
use proptest::prelude::*;

const CYCLES: usize = 9_000;

/// Registers as a register bank could hold them: a valid plan half the
/// time (so the filters produce meaningful output), raw words otherwise.
fn any_registers() -> impl Strategy<Value = Registers> {
    let raw = (
        any::<bool>(),
        any::<u32>(),
        any::<u32>(),
        // Narrow ports get any word of the Rust type too: every engine must
        // keep only the port's low bits (`Registers::at_ports`).
        prop_oneof![0u8..64, any::<u8>()],
        prop_oneof![0u64..(1 << 48), any::<u64>()],
        any::<(i16, i16)>(),
        prop_oneof![1u16..40, 16u16..=4096, 0u16..8192, any::<u16>()],
        prop_oneof![0u8..64, any::<u8>()],
        any::<(i32, i32, i32, i32)>(),
    )
        .prop_map(
            |(select, carrier_step, ref_phase, ref_delay, mod_step, amp, r, shift, k)| Registers {
                select,
                carrier_step,
                ref_phase,
                ref_delay,
                mod_step,
                amp,
                cic_decimation: r,
                cic_shift: shift,
                iir: Coefficients {
                    k0: k.0,
                    k1: k.1,
                    k2: k.2,
                    alpha: k.3,
                },
            },
        );
    let valid = (
        any::<bool>(),
        0.01f64..0.49,
        1.0f64..5e4,
        -0.99f64..0.99,
        MIN_DECIMATION..MIN_DECIMATION + 48,
        0u32..30,
    )
        .prop_map(|(calibration, carrier, cal_hz, amp, r, latency)| {
            let plan = FrequencyPlan {
                clock_hz: 10e6,
                carrier_hz: carrier * 10e6,
                cal_hz: cal_hz.min(1e4),
                calibration,
                amplitude: (amp, -amp * 0.7),
                decimation: r,
                butterworth_hz: 10e6 / r as f64 / 20.0,
                rc_hz: 10e6 / r as f64 / 10.0,
                dac_latency: latency,
                adc_latency: latency / 2,
            };
            registers(&plan).unwrap().0
        });
    prop_oneof![raw, valid]
}

/// ADC words: uniform, full-scale bursts, most-negative bursts, a slow sine.
fn stimulus(seed: u64) -> Vec<(i16, i16)> {
    let mut s = seed | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    (0..CYCLES)
        .map(|n| match (n / 500) % 4 {
            0 => (next() as i16, next() as i16),
            1 => (i16::MAX, i16::MIN),
            2 => (i16::MIN, if n % 2 == 0 { i16::MIN } else { i16::MAX }),
            _ => {
                let v = (32767.0 * (n as f64 * 0.0123).sin()) as i16;
                (v, v.saturating_neg())
            }
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, max_shrink_iters: 0, ..ProptestConfig::default() })]

    #[test]
    fn model_equals_rtl_on_every_cycle(first in any_registers(), second in any_registers(), switch in 1000usize..8000, seed in any::<u64>()) {
        // The registers change once mid-run (mode switch included half the
        // time), as a user reprogramming the bank would.
        let regs: Vec<Registers> = (0..CYCLES).map(|n| if n < switch { first } else { second }).collect();
        let adc = stimulus(seed);
        let mismatch = first_mismatch(&mut RtlGyroInterface::new(), &adc, &regs);
        prop_assert!(mismatch.is_none(), "{:?}", mismatch);
    }
}

/// Named case: register words wider than their ports (`cic_shift = 64`
/// holds 0 at the 6-bit port, `ref_delay = 200` holds 8, `cic_decimation =
/// 8192 + R` holds R, `mod_step` with bits above 48). Before the model
/// masked its words, `cic_shift = 64` alone made it differ from clock 50.
#[test]
fn words_wider_than_their_ports_are_cut_as_the_ports_cut_them() {
    let plan = FrequencyPlan {
        clock_hz: 10e6,
        carrier_hz: 1.0123e6,
        cal_hz: 12.5,
        calibration: true,
        amplitude: (0.9, 0.9),
        decimation: MIN_DECIMATION,
        butterworth_hz: 10e6 / MIN_DECIMATION as f64 / 20.0,
        rc_hz: 10e6 / MIN_DECIMATION as f64 / 10.0,
        dac_latency: 2,
        adc_latency: 3,
    };
    let base = registers(&plan).unwrap().0;
    let wide = [
        Registers {
            cic_shift: 64,
            ..base
        },
        Registers {
            ref_delay: 200,
            ..base
        },
        Registers {
            cic_decimation: 8192 + MIN_DECIMATION as u16,
            ..base
        },
        Registers {
            mod_step: base.mod_step | (0xffff << 48),
            ..base
        },
    ];
    let adc = stimulus(7);
    for regs in wide {
        let regs = vec![regs; 3000];
        let mismatch = first_mismatch(&mut RtlGyroInterface::new(), &adc[..3000], &regs);
        assert!(mismatch.is_none(), "{regs:?}: {mismatch:?}", regs = regs[0]);
    }
}
