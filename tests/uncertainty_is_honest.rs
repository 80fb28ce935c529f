//! The uncertainties are honest: over many independent runs, the exact
//! theory lies within 1 and 2 sigma of the measured ratio about as often as
//! it should.
//!
//! Runs: a kHz-class device with a 1-LSB RMS dither at the ADC (a white
//! residue, where the batch-means estimate is the textbook one), 20 seeds,
//! both outputs: 40 ratios. Each uncertainty comes from 8 batches, so
//! (error / sigma) follows a t distribution with 7 degrees of freedom:
//! P(|t| <= 1) = 0.649, P(|t| <= 2) = 0.914. The bounds below are those
//! probabilities +- 3 binomial standard deviations over 40 trials
//! (sqrt(40 p (1 - p)) = 3.0 and 1.8): an estimate 2x too large fails
//! the first (it would cover 0.91 at 1 sigma) and one 2x too small fails
//! both (0.37 at 1 sigma, 0.65 at 2). The two outputs of one run share its noise only through the
//! drive, and their residues come from different ADCs.

use gyrocal_sim::config;
use gyrocal_sim::engine::EngineKind;
use gyrocal_sim::report::run;

const DEVICE: &str = "
[gyro]
f1_hz = 25.1e3
f2_hz = 25.8e3
q1 = 3000
q2 = 3000
angular_gain = 0.8
[drive]
carrier_hz = 25.1e3
clock_hz = 1.2345e6
[frontend]
noise_lsb = 1.0
[experiment]
readout_rates_dps = [50, 100, 150, 200]
cal_freqs_hz = [2, 4, 6]
tolerance = 1e-3
budget_s = 20
";

#[test]
fn the_exact_ratio_is_within_one_and_two_sigma_as_often_as_it_should() {
    let mut t = vec![];
    for seed in 1..=20 {
        let text = DEVICE.replace(
            "noise_lsb = 1.0",
            &format!("noise_lsb = 1.0\nseed = {seed}"),
        );
        let e = config::parse("dithered.toml", &text).unwrap();
        let r = run(&e, EngineKind::Model, &|_| {}).unwrap();
        for k in 0..2 {
            t.push((r.ratio[k] - r.theory.ratio[k]) / r.ratio_uncertainty[k]);
        }
    }
    let within = |n: f64| t.iter().filter(|x| x.abs() <= n).count();
    eprintln!("error / sigma: {t:.2?}");
    eprintln!(
        "within 1 sigma: {} of 40, within 2 sigma: {} of 40",
        within(1.0),
        within(2.0)
    );
    assert!((17..=35).contains(&within(1.0)), "{}", within(1.0));
    assert!(within(2.0) >= 31, "{}", within(2.0));
}
