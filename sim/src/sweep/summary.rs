//! A sweep's summary: the yield at the tolerance, the error percentiles and
//! how often the reported sigma covered the error.
//!
//! - **Yield** (per output, and both): the fraction of *all* devices whose
//!   every step finished with |error| within the tolerance. A device that
//!   failed (its identification found no resonance, its drive would clip)
//!   counts against the yield, as a part that cannot be calibrated does.
//! - **Percentiles** of each finished device's worst |error| (over its
//!   steps), per output, by nearest rank: the smallest value with at least
//!   p of the devices at or below it.
//! - **Coverage**: over every finished step and output, the fraction of
//!   |error| within 2 of its reported sigmas (`selfcal_error_uncertainty`),
//!   and how many lie beyond 3.
//! - **Per output**, the same and the RMS of error / sigma
//!   ([`Coverage`]); where that RMS lies outside the band honest
//!   sigmas leave it in, a line says so and names the budget's term that
//!   was largest at most steps: a warning where the sigmas are narrower
//!   than the errors, a note where they are wider (they cover, and promise
//!   less than the parts do: the consumer example's output 2, whose sigma
//!   allows for a rate or a damping coupling too small to see, which
//!   parts at rest do not have).
//! - **Warnings**, one line each: every distinct warning of the parts'
//!   field runs (an input no sigma covers, as `gyrocal field` prints it)
//!   with how many parts and which carry it, and the errors that lie
//!   beyond 3 of their sigmas, each named. A sigma that does not cover its
//!   error is never left to a fraction alone.
//! - **Identified parameters** (f1, f2, Q1, Q2, the couplings) against
//!   each step's device ([`IdentifiedJson::scored`]): per parameter the
//!   same coverage, the ones beyond 3 sigma named in a warning, and a line
//!   where a parameter's sigmas are not the size of its errors.
//!
//! [`IdentifiedJson::scored`]: crate::field::scenario::IdentifiedJson::scored

use super::DeviceResult;
pub use crate::coverage::{
    Coverage, Figure, NAMED, Parameter, Scored, SigmaFit, beyond_three_sigma, named,
    uncovered_errors, uncovered_parameters,
};
use gyrocal_host::selfcal::SfUncertainty;
use serde::{Deserialize, Serialize};

/// The percentiles reported, in percent.
pub const PERCENTILES: [f64; 4] = [50.0, 90.0, 95.0, 99.0];

/// A sweep's figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Devices in the report.
    pub devices: u32,
    /// Devices with a failed step (or that could not start).
    pub failed: u32,
    /// The tolerance on |self-cal error| (relative).
    pub tolerance: f64,
    /// Fraction of the devices within the tolerance, per output.
    pub yield_per_output: [f64; 2],
    /// Fraction within the tolerance at both outputs.
    pub yield_both: f64,
    /// `PERCENTILES` of the worst |error| per output: `[p, output 1,
    /// output 2]` rows; empty when no device finished.
    pub error_percentiles: Vec<[f64; 3]>,
    /// Largest |error| per output (null when no device finished).
    pub max_error: Option<[f64; 2]>,
    /// Fraction of |error| within 2 reported sigmas (null when none).
    pub within_2_sigma: Option<f64>,
    /// How many |error| lie beyond 3 reported sigmas.
    pub beyond_3_sigma: u32,
    /// Each output's coverage (null when none of its steps finished).
    pub coverage_per_output: [Option<Coverage>; 2],
    /// Each identified parameter's coverage against the truth, for the
    /// parameters that have figures ([`Parameter::ALL`] order).
    pub coverage_per_parameter: Vec<Coverage>,
    /// How many identified parameters lie beyond 3 of their sigmas.
    pub parameters_beyond_3_sigma: u32,
    /// One line each: the parts' distinct warnings ([`carried_warnings`]),
    /// then the errors beyond 3 sigma ([`uncovered_errors`]), then an
    /// output whose sigmas are narrower than its errors
    /// ([`Coverage::line`]), then the same of the identified parameters
    /// ([`uncovered_parameters`]).
    pub warnings: Vec<String>,
    /// One line each: an output, or an identified parameter, whose sigmas
    /// are wider than its errors ([`Coverage::line`]).
    pub notes: Vec<String>,
}

/// The name of the largest term of a step's error sigma for output `k`:
/// one of `budget`'s sources ([`SfUncertainty::TERMS`]) or "truth", the
/// rate table's own sigma (`error_sigma`'s part beyond `budget.total`).
fn largest_term(budget: &SfUncertainty, error_sigma: f64, k: usize) -> &'static str {
    let truth = (error_sigma.powi(2) - budget.total[k].powi(2))
        .max(0.0)
        .sqrt();
    budget
        .terms(k)
        .into_iter()
        .chain([("truth", truth)])
        .fold(("truth", -1.0), |a, b| if b.1 > a.1 { b } else { a })
        .0
}

/// For output `k`, each term that was the largest ([`largest_term`]) at
/// some finished step, and at how many, most first.
fn largest_terms(devices: &[DeviceResult], k: usize) -> Vec<(&'static str, u32)> {
    let mut counts: Vec<(&'static str, u32)> = vec![];
    for st in devices.iter().flat_map(|d| &d.steps) {
        let name = largest_term(&st.sf_selfcal_budget, st.selfcal_error_uncertainty[k], k);
        match counts.iter_mut().find(|(n, _)| *n == name) {
            Some((_, c)) => *c += 1,
            None => counts.push((name, 1)),
        }
    }
    counts.sort_by_key(|c| std::cmp::Reverse(c.1));
    counts
}

/// Each distinct warning of `parts` (index, the warnings of its field run)
/// once, in the order first met, as one line: how many of the `total`
/// parts carry it, and which. Lines that differ only in the figures
/// inside their parentheses (a part's own counts, as the profile's clip
/// line gives them) are one warning, told in the first part's words and
/// saying so; figures outside them (the temperatures a line names) keep
/// lines apart.
pub fn carried_warnings<'a>(
    parts: impl IntoIterator<Item = (u32, &'a [String])>,
    total: usize,
) -> Vec<String> {
    // (key, the first part's text, whether another part's text differs, parts)
    let mut distinct: Vec<(String, &str, bool, Vec<u32>)> = vec![];
    for (index, lines) in parts {
        for line in lines {
            let text = line.strip_prefix("warning: ").unwrap_or(line);
            let key = figures_in_parentheses_blanked(text);
            match distinct.iter_mut().find(|(k, ..)| *k == key) {
                Some((_, first, differs, parts)) => {
                    *differs |= *first != text;
                    parts.push(index);
                }
                None => distinct.push((key, text, false, vec![index])),
            }
        }
    }
    distinct
        .into_iter()
        .map(|(_, text, differs, parts)| {
            let words = if differs {
                format!(", in device {}'s figures", parts[0])
            } else {
                String::new()
            };
            format!(
                "warning: {} of {total} parts (device {}){words}: {text}",
                parts.len(),
                named(&parts)
            )
        })
        .collect()
}

/// `text` with every run of digits (and the points between them) inside
/// parentheses replaced by `#`.
fn figures_in_parentheses_blanked(text: &str) -> String {
    let mut depth = 0usize;
    let mut out = String::with_capacity(text.len());
    let mut in_figure = false;
    for c in text.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ => {}
        }
        let figure = depth > 0 && (c.is_ascii_digit() || (in_figure && c == '.'));
        if !figure {
            out.push(c);
        } else if !in_figure {
            out.push('#');
        }
        in_figure = figure;
    }
    out
}

/// Nearest-rank percentile `p` (0 < p <= 100) of sorted values.
fn nearest_rank(sorted: &[f64], p: f64) -> f64 {
    let rank = ((p / 100.0) * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

impl Summary {
    /// The summary of `devices` at `tolerance`.
    pub fn of(devices: &[DeviceResult], tolerance: f64) -> Self {
        let n = devices.len().max(1) as f64;
        let finished: Vec<&DeviceResult> = devices.iter().filter(|d| d.failed.is_empty()).collect();
        let worst = |k: usize| -> Vec<f64> {
            let mut v: Vec<f64> = finished.iter().map(|d| d.worst_error(k)).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let sorted = [worst(0), worst(1)];
        let within = |k: usize| sorted[k].iter().filter(|&&e| e <= tolerance).count() as f64 / n;
        let scored: Vec<Scored> = devices
            .iter()
            .flat_map(|d| d.steps.iter().map(move |s| (d.index, s)))
            .flat_map(|(device, s)| {
                Scored::outputs(
                    Some(device),
                    s.temperature_c,
                    s.sf_selfcal_error,
                    s.selfcal_error_uncertainty,
                )
            })
            .collect();
        let beyond = beyond_three_sigma(&scored);
        let mut warnings = carried_warnings(
            devices.iter().map(|d| (d.index, d.warnings.as_slice())),
            devices.len(),
        );
        warnings.extend(uncovered_errors(&beyond, scored.len()));
        let coverage_per_output = [0, 1].map(|k| Coverage::of(&scored, Figure::Output(k)));
        let mut notes = vec![];
        for (k, c) in coverage_per_output.iter().enumerate() {
            if let Some(c) = c {
                sort_line(c, &largest_terms(devices, k), &mut warnings, &mut notes);
            }
        }
        let parameters = ParameterScores::of(devices);
        warnings.extend(parameters.uncovered);
        for c in &parameters.coverage {
            sort_line(c, &[], &mut warnings, &mut notes);
        }
        let has = !sorted[0].is_empty();
        Self {
            devices: devices.len() as u32,
            failed: (devices.len() - finished.len()) as u32,
            tolerance,
            yield_per_output: [within(0), within(1)],
            yield_both: devices.iter().filter(|d| d.within_tolerance).count() as f64 / n,
            error_percentiles: if has {
                PERCENTILES
                    .iter()
                    .map(|&p| [p, nearest_rank(&sorted[0], p), nearest_rank(&sorted[1], p)])
                    .collect()
            } else {
                vec![]
            },
            max_error: has.then(|| {
                [
                    sorted[0][sorted[0].len() - 1],
                    sorted[1][sorted[1].len() - 1],
                ]
            }),
            within_2_sigma: (!scored.is_empty()).then(|| {
                let within = scored.iter().filter(|s| s.t.abs() <= 2.0).count();
                within as f64 / scored.len() as f64
            }),
            beyond_3_sigma: beyond.len() as u32,
            coverage_per_output,
            coverage_per_parameter: parameters.coverage,
            parameters_beyond_3_sigma: parameters.beyond,
            warnings,
            notes,
        }
    }
}

/// `c`'s line ([`Coverage::line`]), if any, into `warnings` where its
/// sigmas are narrower than its errors, into `notes` where wider.
fn sort_line(
    c: &Coverage,
    largest: &[(&str, u32)],
    warnings: &mut Vec<String>,
    notes: &mut Vec<String>,
) {
    let line = c.line(largest);
    match c.fit() {
        SigmaFit::Fits => {}
        SigmaFit::Wider => notes.extend(line),
        SigmaFit::Narrower => warnings.extend(line),
    }
}

/// The identified parameters of every finished step against its truth.
struct ParameterScores {
    /// Per parameter with figures, in [`Parameter::ALL`] order.
    coverage: Vec<Coverage>,
    /// How many lie beyond 3 sigma.
    beyond: u32,
    /// The line naming them.
    uncovered: Option<String>,
}

impl ParameterScores {
    fn of(devices: &[DeviceResult]) -> Self {
        let scored: Vec<Scored> = devices
            .iter()
            .flat_map(|d| {
                d.steps.iter().flat_map(|s| {
                    s.identified
                        .scored(Some(d.index), s.temperature_c, &s.truth)
                })
            })
            .collect();
        let beyond = beyond_three_sigma(&scored);
        Self {
            coverage: Parameter::ALL
                .iter()
                .filter_map(|&p| Coverage::of(&scored, Figure::Parameter(p)))
                .collect(),
            beyond: beyond.len() as u32,
            uncovered: uncovered_parameters(&beyond, scored.len()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_is_the_smallest_value_with_p_at_or_below() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        assert_eq!(nearest_rank(&v, 50.0), 5.0);
        assert_eq!(nearest_rank(&v, 90.0), 9.0);
        assert_eq!(nearest_rank(&v, 95.0), 10.0);
        assert_eq!(nearest_rank(&v, 100.0), 10.0);
        assert_eq!(nearest_rank(&[3.0], 50.0), 3.0);
    }

    #[test]
    fn each_distinct_warning_is_one_line_with_its_parts() {
        let line = |t: &str| format!("warning: at {t} deg C the ratio is the design's");
        let parts: Vec<(u32, Vec<String>)> = vec![
            (0, vec![line("25, 5")]),
            (1, vec![]),
            (2, vec![line("25, 5"), "warning: undithered".into()]),
            (3, vec![line("5")]),
        ];
        let lines = carried_warnings(parts.iter().map(|(i, w)| (*i, w.as_slice())), 4);
        assert_eq!(
            lines,
            [
                "warning: 2 of 4 parts (device 0, 2): at 25, 5 deg C the ratio is the design's",
                "warning: 1 of 4 parts (device 2): undithered",
                "warning: 1 of 4 parts (device 3): at 5 deg C the ratio is the design's",
            ]
        );
        // Past `NAMED` parts the line says there are more.
        let many: Vec<(u32, Vec<String>)> = (0..10).map(|i| (i, vec![line("5")])).collect();
        let lines = carried_warnings(many.iter().map(|(i, w)| (*i, w.as_slice())), 10);
        assert_eq!(
            lines,
            [
                "warning: 10 of 10 parts (device 0, 1, 2, 3, 4, 5, 6, 7, ...): at 5 deg C the ratio is the design's"
            ]
        );
        assert!(carried_warnings(std::iter::empty(), 3).is_empty());
    }

    #[test]
    fn lines_that_differ_in_their_parenthesized_figures_are_one_warning() {
        let clip = |n: u32| {
            format!(
                "warning: an ADC clipped at 25 deg C (ADC 2 in {n} of 96 records; up to 1e5 deg/s): left out"
            )
        };
        let parts: Vec<(u32, Vec<String>)> = vec![
            (3, vec![clip(64)]),
            (4, vec![clip(64)]),
            (7, vec![clip(12)]),
            (8, vec!["warning: an ADC clipped at 5 deg C (ADC 2 in 9 of 96 records; up to 1e5 deg/s): left out".into()]),
        ];
        let lines = carried_warnings(parts.iter().map(|(i, w)| (*i, w.as_slice())), 9);
        assert_eq!(
            lines,
            [
                "warning: 3 of 9 parts (device 3, 4, 7), in device 3's figures: an ADC clipped at 25 deg C (ADC 2 in 64 of 96 records; up to 1e5 deg/s): left out",
                "warning: 1 of 9 parts (device 8): an ADC clipped at 5 deg C (ADC 2 in 9 of 96 records; up to 1e5 deg/s): left out",
            ]
        );
        assert_eq!(
            figures_in_parentheses_blanked("at 2.5 K (x 1.25 of 3, [a] 7)."),
            "at 2.5 K (x # of #, [a] #)."
        );
    }

    /// A finished part with one step at 5 deg C: errors `t` times a sigma
    /// of 1e-4, and its field run's `warnings`. Its identified parameters
    /// lie one sigma off the truth, high on an even part, low on an odd
    /// one: honest sigmas, without a line.
    fn part(index: u32, t: [f64; 2], warnings: &[&str]) -> DeviceResult {
        let off = if index.is_multiple_of(2) { 0.1 } else { -0.1 };
        part_identified(index, t, warnings, [off; 5])
    }

    /// `part` whose f1, f2, Q1, Q2 and quadrature lie `off` from the
    /// truth, each with a sigma of 0.1.
    fn part_identified(index: u32, t: [f64; 2], warnings: &[&str], off: [f64; 5]) -> DeviceResult {
        let truth = [1e4, 1.01e4, 1e3, 1e3, 0.0, 0.0, 0.0];
        let identified: serde_json::Map<String, serde_json::Value> = [
            "f1_hz",
            "f2_hz",
            "q1",
            "q2",
            "quadrature_dps",
            "loop_phase_deg",
            "damping_coupling_dps",
        ]
        .iter()
        .zip(truth)
        .zip(off.iter().chain(&[0.0; 2]))
        .flat_map(|((k, v), off)| [(k.to_string(), v + off), (format!("{k}_uncertainty"), 0.1)])
        .map(|(k, v)| (k, serde_json::json!(v)))
        .chain(
            ["drive_gain_ratio", "drive_gain_ratio_uncertainty"]
                .map(|k| (k.into(), serde_json::Value::Null)),
        )
        .collect();
        let step = serde_json::json!({
            "temperature_c": 5.0,
            "sf_selfcal_error": [1e-4 * t[0], 1e-4 * t[1]],
            "sf_selfcal_uncertainty": [1e-4, 1e-4],
            "selfcal_error_uncertainty": [1e-4, 1e-4],
            "sf_selfcal_budget": SfUncertainty { staircase: [1e-4; 2], ..Default::default() }.with_total(),
            "sf_true_per_dps": [1.0, 1.0],
            "identified": identified,
            "truth": { "f1_hz": 1e4, "f2_hz": 1.01e4, "q1": 1e3, "q2": 1e3, "angular_gain": 0.8 },
        });
        serde_json::from_value(serde_json::json!({
            "index": index,
            "device": { "f1_hz": 1e4, "f2_hz": 1.01e4, "q1": 1e3, "q2": 1e3, "angular_gain": 0.8 },
            "frontend_seed": 1, "noise_seed": 2,
            "worst_temperature_c": 5.0,
            "sf_selfcal_error": step["sf_selfcal_error"],
            "sf_selfcal_uncertainty": step["sf_selfcal_uncertainty"],
            "identified": identified,
            "within_tolerance": true,
            "steps": [step],
            "failed": [],
            "warnings": warnings,
            "clocks": 0,
        }))
        .unwrap()
    }

    #[test]
    fn the_summary_keeps_the_parts_warnings_and_names_the_uncovered_errors() {
        let parts = [
            part(0, [0.5, -1.0], &["warning: ratio"]),
            part(1, [3.5, -0.2], &[]),
            part(2, [1.0, -3.2], &["warning: ratio"]),
        ];
        let sm = Summary::of(&parts, 1e-3);
        assert_eq!(sm.beyond_3_sigma, 2);
        assert_eq!(
            sm.warnings,
            [
                "warning: 2 of 3 parts (device 0, 2): ratio",
                "warning: 2 of 6 errors lie beyond 3 of their reported sigmas, which do not cover \
                 them: device 1 at 5 deg C output 1 (+3.500 sigma), device 2 at 5 deg C output 2 \
                 (-3.200 sigma)",
            ]
        );
        // Output 1's RMS error/sigma, 2.12 over three parts, is within
        // what three honest sigmas give (up to 2.18): no line.
        let one = sm.coverage_per_output[0].unwrap();
        assert!((one.rms_t - 2.1213).abs() < 1e-4);
        assert!(
            (one.rms_band().1 - 2.18).abs() < 0.01,
            "{:?}",
            one.rms_band()
        );
        assert!(sm.notes.is_empty());
        assert!(
            Summary::of(&[part(0, [0.5, 2.9], &[])], 1e-3)
                .warnings
                .is_empty()
        );
    }

    /// Forty parts whose output 2 errors are a tenth of their sigmas: a
    /// note names the output and the term, and output 1 (errors the size
    /// of their sigmas) has no line.
    #[test]
    fn an_output_whose_sigmas_are_wider_than_its_errors_is_noted() {
        let parts: Vec<DeviceResult> = (0..40)
            .map(|i| {
                let t = if i % 2 == 0 { 1.0 } else { -1.0 };
                part(i, [t, 0.1 * t], &[])
            })
            .collect();
        let sm = Summary::of(&parts, 1e-3);
        assert!(sm.warnings.is_empty(), "{:?}", sm.warnings);
        let [one, two] = sm.coverage_per_output.map(Option::unwrap);
        assert_eq!((one.rms_t, one.parts, two.errors), (1.0, 40, 40));
        assert!((two.rms_t - 0.1).abs() < 1e-12 && two.within_2_sigma == 1.0);
        assert_eq!(
            sm.notes,
            [
                "note: output 2's sigmas are wider than its errors: RMS error/sigma 0.10 over 40 \
              errors of 40 parts (0.70 to 1.32 if each sigma were its error's spread), 100.0% \
              within 2 sigma; the largest term of its sigma: staircase at 40"
            ]
        );
    }

    /// An identified parameter beyond 3 of its sigmas is named, by part,
    /// step and parameter; one whose sigmas are far wider than its errors
    /// is noted; the rest, a sigma off, have no line.
    #[test]
    fn identified_parameters_beyond_three_sigma_are_named() {
        let mut parts: Vec<DeviceResult> = (0..40u32)
            .map(|i| {
                let (off, t) = if i.is_multiple_of(2) {
                    (0.1, 1.0)
                } else {
                    (-0.1, -1.0)
                };
                // Q2's sigma is ten times its error.
                part_identified(i, [t, t], &[], [off, off, off, 0.1 * off, off])
            })
            .collect();
        parts[7] = part_identified(7, [-1.0, -1.0], &[], [-0.1, -0.34, -0.1, -0.01, -0.1]);
        let sm = Summary::of(&parts, 1e-3);
        assert_eq!(sm.parameters_beyond_3_sigma, 1);
        assert_eq!(
            sm.warnings,
            [
                "warning: 1 of 200 identified parameters lie beyond 3 of their reported sigmas, \
                 which do not cover them: device 7 at 5 deg C f2 (-3.400 sigma)"
            ]
        );
        let names: Vec<String> = sm
            .coverage_per_parameter
            .iter()
            .map(|c| c.figure.to_string())
            .collect();
        assert_eq!(
            names,
            ["f1", "f2", "Q1", "Q2", "quadrature"],
            "no damping coupling to score"
        );
        let q2 = sm.coverage_per_parameter[3];
        assert_eq!((q2.errors, q2.parts), (40, 40));
        assert!((q2.rms_t - 0.1).abs() < 1e-9, "{q2:?}");
        assert_eq!(sm.notes.len(), 1, "{:?}", sm.notes);
        assert!(
            sm.notes[0]
                .starts_with("note: Q2's sigmas are wider than its errors: RMS error/sigma 0.10")
                && sm.notes[0].ends_with("100.0% within 2 sigma"),
            "{}",
            sm.notes[0]
        );
        // In JSON each coverage names its figure in one key.
        let json = serde_json::to_value(&sm).unwrap();
        assert_eq!(json["coverage_per_parameter"][1]["parameter"], "f2");
        assert_eq!(json["coverage_per_output"][1]["output"], 1);
        let back: Summary = serde_json::from_value(json).unwrap();
        assert_eq!(back, sm);
    }

    /// The truth's own sigma is named where it is the largest.
    #[test]
    fn the_largest_term_may_be_the_truths() {
        let b = SfUncertainty {
            cycle_rate: [3e-4, 0.0],
            staircase: [1e-4, 0.0],
            ..Default::default()
        }
        .with_total();
        assert_eq!(largest_term(&b, b.total[0], 0), "cycle_rate");
        assert_eq!(largest_term(&b, 5e-4, 0), "truth");
    }

    #[test]
    fn errors_beyond_three_sigma_are_named_and_those_within_are_not() {
        let at = |device, t| Scored {
            device: Some(device),
            temperature_c: 5.0,
            figure: Figure::Output(0),
            t,
        };
        let uncovered =
            |scored: &[Scored]| uncovered_errors(&beyond_three_sigma(scored), scored.len());
        assert_eq!(uncovered(&[at(0, 3.0), at(1, -2.9), at(2, 0.1)]), None);
        assert_eq!(
            uncovered(&[at(0, -3.07), at(1, 2.0), at(4, 3.5)]).as_deref(),
            Some(
                "warning: 2 of 3 errors lie beyond 3 of their reported sigmas, which do not cover them: \
                 device 0 at 5 deg C output 1 (-3.070 sigma), device 4 at 5 deg C output 1 (+3.500 sigma)"
            )
        );
    }
}
