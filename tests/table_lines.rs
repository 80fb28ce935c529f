//! The table core's carrier lines are in identification's sigmas: the
//! consumer sweep's part 54 (`tests/data/part54_fold.toml`), mode 2 half
//! a bandwidth above the clock's 1 / 48 and driven at 0.28% of full
//! scale, where the words' rounding is some 1e-6 of the response
//! (`gyrocal_host::identify::point_spur_sd`), identified under 40 ADC
//! noise seeds.
//!
//! Before the lines were in the sigma (`identify::sweep_uncertainty`),
//! f2 read mean t -0.58 +- 0.16 with a spread of 1.01 over these seeds:
//! RMS t 1.16, and seed 1021 at -3.20. Now: mean -0.48, spread 0.82,
//! RMS 0.94, largest |t| 2.34. On the fine core, whose rounding is fed
//! back away from the carrier, the spread was 0.41 (docs/sweep.md).
//!
//! Asserted, and why each can fail:
//! - every |t| of f1, f2, Q1, Q2 within 3: an honest sigma leaves a
//!   figure beyond 3 with probability 0.27%, so 160 figures hold none
//!   beyond in 65% of draws; these draws are fixed, and seed 1021's f2
//!   at -3.2 is the failure this guards against;
//! - f2's RMS t at most 1: the sigma covers the error's RMS, bias
//!   included (1.16 before);
//! - f2's RMS t at least 0.5: the lines, which dominate f2's sigma here,
//!   are not counted twice (adding them to the residuals' and the
//!   jackknife's sigma in quadrature read 0.74, with the waits then at
//!   their bounds; an honest set about 1).

use gyrocal_sim::coverage::{Figure, Parameter};
use gyrocal_sim::field::scenario;
use rayon::prelude::*;

/// Noise seeds 1000 .. 1000 + SEEDS.
const SEEDS: u64 = 40;

#[test]
fn the_table_cores_lines_are_in_identifications_sigmas() {
    let text = include_str!("data/part54_fold.toml");
    let by_seed: Vec<Vec<(Parameter, f64)>> = (1000..1000 + SEEDS)
        .into_par_iter()
        .map(|seed| {
            let at = text.find("seed = ").expect("[frontend] seed");
            let end = at + text[at..].find('\n').unwrap();
            let text = format!("{}seed = {seed}{}", &text[..at], &text[end..]);
            let sc = scenario::parse("part54_fold.toml", &text).unwrap();
            let r = scenario::run(&sc, &|_| {}).unwrap();
            assert!(r.failed.is_empty(), "seed {seed}: {:?}", r.failed);
            r.steps
                .iter()
                .flat_map(|s| s.identified.scored(None, s.temperature_c, &s.truth.gyro))
                .filter_map(|s| match s.figure {
                    Figure::Parameter(p) if (p as usize) < 4 => Some((p, s.t)),
                    _ => None,
                })
                .collect()
        })
        .collect();
    for (i, figures) in by_seed.iter().enumerate() {
        for (p, t) in figures {
            assert!(t.abs() <= 3.0, "seed {}: {p:?} at {t:.2} sigma", 1000 + i);
        }
    }
    let f2: Vec<f64> = by_seed
        .iter()
        .flat_map(|f| f.iter().filter(|(p, _)| *p == Parameter::F2).map(|x| x.1))
        .collect();
    assert_eq!(f2.len() as u64, SEEDS);
    let mean = f2.iter().sum::<f64>() / f2.len() as f64;
    let rms = (f2.iter().map(|t| t * t).sum::<f64>() / f2.len() as f64).sqrt();
    eprintln!("f2 over {SEEDS} seeds: mean t {mean:.2}, RMS t {rms:.2}");
    assert!(rms <= 1.0, "f2: RMS t {rms:.2}, beyond its sigma");
    assert!(rms >= 0.5, "f2: RMS t {rms:.2}, its sigma inflated");
}
