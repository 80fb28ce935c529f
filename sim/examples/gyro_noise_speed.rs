//! Speed of the gyroscope model alone, with the Brownian noise off and on,
//! side by side in one process (a benchmark, not a test): clocks per second
//! of `GyroModel::step` on the paper's device at a 50 MHz clock, at rest
//! and rotating, median of 7 repetitions of 2e7 clocks each.
//!
//! `cargo run --release -p gyrocal-sim --example gyro_noise_speed`

use gyrocal_sim::gyro::{GyroModel, GyroParams};
use gyrocal_sim::noise::ThermalNoise;
use std::hint::black_box;
use std::time::Instant;

const CLOCKS: u64 = 20_000_000;
const REPETITIONS: usize = 7;

fn clocks_per_s(noise: &ThermalNoise, rate: f64) -> f64 {
    let p = GyroParams {
        f1_hz: 9.64e6,
        f2_hz: 9.64025e6,
        q1: 55_000.0,
        q2: 55_000.0,
        angular_gain: 0.6,
    };
    let mut samples: Vec<f64> = (0..REPETITIONS)
        .map(|_| {
            let mut g = GyroModel::new(&p, 50e6)
                .and_then(|g| g.with_thermal_noise(noise))
                .expect("valid device");
            g.set_rate(rate);
            let start = Instant::now();
            for n in 0..CLOCKS {
                let f = if n & 4 == 0 { 0.9 } else { -0.9 };
                g.step(black_box(f), black_box(-f));
            }
            black_box(g.state());
            CLOCKS as f64 / start.elapsed().as_secs_f64()
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[REPETITIONS / 2]
}

fn main() {
    let off = ThermalNoise::default();
    let on = ThermalNoise {
        temperature_k: 300.0,
        ..ThermalNoise::default()
    };
    println!("gyroscope model alone, median of {REPETITIONS} x {CLOCKS} clocks");
    for (what, rate) in [("at rest", 0.0), ("rotating", 0.1)] {
        let (a, b) = (clocks_per_s(&off, rate), clocks_per_s(&on, rate));
        println!(
            "{what:9} noise off {a:.3e} clocks/s, noise on {b:.3e} clocks/s (on/off {:.2})",
            b / a
        );
    }
}
