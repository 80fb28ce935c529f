//! The rate output's noise floor: the angle random walk measured on a
//! noisy co-simulation matches the one predicted from the noise model
//! (`gyrocal_sim::rate_noise`) within 10 %, once with the Brownian force
//! noise dominating and once with the ADC's noise alone.
//!
//! # Why 10 % and 310 s
//!
//! The measured ARW is `60 sigma(tau_m) sqrt(tau_m)`, the overlapping Allan
//! deviation at the cluster nearest 1 s (`allan::arw_at`). For white rate
//! noise its variance estimate scatters as chi^2 with the equivalent
//! degrees of freedom `edf = (3 (N-1) / (2m) - 2 (N-2) / N) 4m^2 / (4m^2 +
//! 5)` (Howe, Allan, Barnes 1981; NIST SP 1065 table 5), about `1.5 T /
//! tau`: 463 for T = 310 s of series at tau = 1 s (300 s would give 448,
//! just short of 3 sigma). The deviation then has a relative standard
//! deviation `1 / sqrt(2 edf)` = 3.29 %: 10 % is 3.04 sigma (a false
//! failure about 2 times in 1000 per output). The test
//! asserts that the run is long enough for this (relative sigma <= 10 %
//! / 3), so the tolerance stays justified if the device changes.
//!
//! The prediction compared against is the prediction's own Allan
//! deviation at the same tau (the whole spectrum, resonator roll-off
//! included), which on this device is within 0.5 % of the white-density
//! line `N / sqrt(tau)` (asserted below): the 10 % is the estimator's, not
//! the model's. The seeds are fixed for repeatability; they were not
//! chosen.
//!
//! The device (`tests/data/allan_small.toml`): 30.123 kHz modes 100 Hz
//! apart, Q 500, on a 151.23 kHz clock, so 310 simulated seconds are 4.7e7
//! clocks, about 15 s in release on one core.

use gyrocal_sim::config::{self, Experiment};
use gyrocal_sim::rate_noise::{self, RateNoisePrediction};

const SMALL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/allan_small.toml");

/// Simulated seconds of each run (module header).
const SECONDS: f64 = 310.0;

/// Measured over predicted ARW at 1 s may be off by this much (3 sigma).
const TOLERANCE: f64 = 0.10;

fn small_device() -> Experiment {
    let text = std::fs::read_to_string(SMALL).unwrap();
    config::parse(SMALL, &text).unwrap()
}

/// Run at `rate_dps` and check both outputs; returns the prediction.
fn measured_matches_predicted(exp: &Experiment, rate_dps: f64) -> RateNoisePrediction {
    let (plan, prediction) = rate_noise::plan_and_predict(exp, rate_dps).unwrap();
    let run = rate_noise::run_noisy(exp, &plan, rate_dps, SECONDS, &|_| {}).unwrap();
    for k in 0..2 {
        let reading = &run.outputs[k].arw_at_1s;
        assert!((reading.tau_s - 1.0).abs() < 1e-3, "{reading:?}");
        assert!(
            reading.relative_sigma <= TOLERANCE / 3.0,
            "the run is too short for a 3-sigma tolerance: {reading:?}"
        );
        let predicted = 60.0 * prediction.adev(k, reading.tau_s) * reading.tau_s.sqrt();
        let white = prediction.outputs[k].arw_deg_per_sqrt_h;
        assert!(
            (predicted / white - 1.0).abs() < 0.005,
            "output {}: sigma(1 s) {predicted} vs white line {white}",
            k + 1
        );
        let error = reading.deg_per_sqrt_h / predicted - 1.0;
        println!(
            "output {}: measured {:.4} deg/sqrt(h), predicted {predicted:.4} ({:+.2} %, {:+.2} sigma)",
            k + 1,
            reading.deg_per_sqrt_h,
            100.0 * error,
            error / reading.relative_sigma
        );
        assert!(
            error.abs() < TOLERANCE,
            "output {}: measured ARW {} deg/sqrt(h) against {predicted} predicted ({:+.1} %)",
            k + 1,
            reading.deg_per_sqrt_h,
            100.0 * error
        );
    }
    prediction
}

#[test]
fn brownian_noise_gives_the_predicted_angle_random_walk() {
    let exp = small_device();
    let prediction = measured_matches_predicted(&exp, 50.0);
    for o in &prediction.outputs {
        assert!(o.thermal_rate_psd > 100.0 * o.adc_rate_psd, "{o:?}");
    }
}

#[test]
fn adc_noise_alone_gives_the_predicted_angle_random_walk() {
    // No Brownian noise; 2 LSB of ADC noise, which also dithers the
    // quantizer (its D^2 / 12 is then 2 % of the density, included).
    let mut exp = small_device();
    exp.noise.temperature_k = 0.0;
    exp.frontend.noise_lsb = 2.0;
    exp.frontend.seed = 5;
    let prediction = measured_matches_predicted(&exp, 0.0);
    for o in &prediction.outputs {
        assert_eq!(o.thermal_rate_psd, 0.0);
        assert!(o.adc_rate_psd > 0.0);
    }
}
