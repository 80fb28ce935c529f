//! The datasheet recovers a known noise model: `tests/data/datasheet_small.toml`
//! sets white (6 deg/sqrt(h)), flicker (B = 1800 deg/h) and random-walk
//! (K = 15000 deg/h/sqrt(h)) rate noise, injected through the board's rate
//! table; a 2048 s datasheet run must give them back.
//!
//! # What is asserted, and why the intervals are the tolerances
//!
//! The expected Allan variance at each tau is the generator's exact one
//! (`RateNoiseSource::allan_variance_terms`, the discrete processes as
//! held) plus the converters' white noise as predicted from the noise
//! model (`rate_noise::predict`, 5.3 and 1.5 deg/sqrt(h)).
//!
//! 1. At every tau of the fit (`tau >= fit_min_tau_s`) the measured
//!    deviation lies within its 99.73 % (three-sigma) chi-square interval
//!    of the expected one, with the datasheet's edf. The output filters
//!    lower the white part by at most 3 % of the variance at the shortest
//!    of these taus (`FIT_MIN_TAU_OVER_BANDWIDTH`), well inside three
//!    sigma (edf > 1000 there).
//! 2. The fit's B and K: the set values lie within the three-sigma
//!    intervals of the fitted ones (edf from the reported, conservative
//!    one-sigma interval; `noise_terms`).
//! 3. The IEEE 952 reading `min sigma / 0.664` estimates the minimum of
//!    the whole curve, which the white and random-walk terms lift above
//!    `0.664 B` (here by about 5 %: `2 N K / (sqrt 3 (0.664 B)^2)` = 0.10
//!    of the variance). So it is not compared with the set B, but with the
//!    same reading of the expected curve, which must lie within its
//!    three-sigma interval; the offset from B is printed.
//!
//! The seed (`[noise] seed = 7`) is fixed for repeatability; it was not
//! chosen. 2048 simulated seconds are 3.1e7 clocks of the 15 kHz device.

use gyrocal_sim::datasheet::{self, Options, OutputSheet};
use gyrocal_sim::edf;
use gyrocal_sim::rate_drift::{FLICKER_ADEV_PER_B, RateNoiseSource};
use gyrocal_sim::rate_noise;

const SMALL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/datasheet_small.toml"
);
const SECONDS: f64 = 2048.0;
/// Three sigma.
const CONFIDENCE: f64 = 0.9973;

/// The three-sigma interval of a one-sigma reading's value and edf.
fn three_sigma(value: f64, edf: f64) -> (f64, f64) {
    edf::interval(value, edf, CONFIDENCE).unwrap()
}

#[test]
fn a_known_noise_model_is_recovered() {
    let text = std::fs::read_to_string(SMALL).unwrap();
    let setup = datasheet::setup::parse(SMALL, &text).unwrap();
    let options = Options {
        seconds: SECONDS,
        full_scale_dps: None,
    };
    let start = std::time::Instant::now();
    let ds = datasheet::run(&setup, &options, &|_| {}).unwrap();
    eprintln!("datasheet run: {:.1} s wall", start.elapsed().as_secs_f64());
    let (_, prediction) = rate_noise::plan_and_predict(&setup.exp, 0.0).unwrap();
    let fs = ds.series.sample_rate_hz;
    let source = RateNoiseSource::new(&setup.rate_noise, 1.0 / fs, setup.exp.noise.seed).unwrap();
    let b_set = setup.rate_noise.bias_instability_deg_per_h;
    let k_set = setup.rate_noise.rrw_deg_per_h_per_sqrt_h;
    for (k, o) in ds.outputs.iter().enumerate() {
        let adc = prediction.outputs[k].arw_deg_per_sqrt_h / 60.0;
        let expected = |m: usize| {
            let tau = m as f64 / fs;
            (source.allan_variance(m as f64) + adc * adc / tau).sqrt() * 3600.0
        };
        every_tau_within_its_interval(o, &expected, ds.fit_min_tau_s);
        fit_recovers(o, b_set, k_set);
        ieee_reading_matches(o, b_set, &expected, ds.fit_min_tau_s);
    }
}

fn every_tau_within_its_interval(o: &OutputSheet, expected: &dyn Fn(usize) -> f64, tau_min: f64) {
    let a = &o.adev;
    let mut checked = 0;
    for i in (0..a.tau_s.len()).filter(|&i| a.tau_s[i] >= tau_min) {
        let want = expected(a.cluster[i]);
        let (lo, hi) = three_sigma(a.sigma_deg_per_h[i], a.edf[i]);
        assert!(
            lo <= want && want <= hi,
            "output {} tau {}: measured {} [{lo}, {hi}], expected {want}",
            o.output,
            a.tau_s[i],
            a.sigma_deg_per_h[i]
        );
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} taus in the fit");
}

fn fit_recovers(o: &OutputSheet, b_set: f64, k_set: f64) {
    for (r, set) in [
        (&o.noise_fit.bias_instability_deg_per_h, b_set),
        (&o.noise_fit.rrw_deg_per_h_per_sqrt_h, k_set),
    ] {
        let (v, e) = (r.value.expect("resolved"), r.edf.unwrap());
        let (lo, hi) = three_sigma(v, e);
        eprintln!(
            "output {}: fitted {v:.1} (one sigma [{:.1}, {:.1}], edf {e:.1}) against {set}",
            o.output,
            r.ci_low.unwrap(),
            r.ci_high.unwrap()
        );
        assert!(
            lo <= set && set <= hi,
            "output {}: {r:?} against {set}",
            o.output
        );
    }
    assert_eq!(
        o.rrw_deg_per_h_per_sqrt_h,
        o.noise_fit.rrw_deg_per_h_per_sqrt_h.value
    );
}

fn ieee_reading_matches(
    o: &OutputSheet,
    b_set: f64,
    expected: &dyn Fn(usize) -> f64,
    tau_min: f64,
) {
    let r = &o.bias_instability;
    assert!(r.note.is_none(), "{r:?}");
    let (v, e) = (r.value.unwrap(), r.edf.unwrap());
    let (lo, hi) = three_sigma(v, e);
    let a = &o.adev;
    let expected_min = (0..a.tau_s.len())
        .filter(|&i| a.tau_s[i] >= tau_min)
        .map(|i| expected(a.cluster[i]))
        .fold(f64::INFINITY, f64::min);
    let reading = expected_min / FLICKER_ADEV_PER_B;
    eprintln!(
        "output {}: IEEE B {v:.1} at {} s (one sigma [{:.1}, {:.1}]); the expected curve reads {reading:.1}, {:+.1} % off the set B",
        o.output,
        r.tau_s.unwrap(),
        r.ci_low.unwrap(),
        r.ci_high.unwrap(),
        100.0 * (reading / b_set - 1.0)
    );
    assert!(
        lo <= reading && reading <= hi,
        "output {}: {r:?} against {reading}",
        o.output
    );
}
