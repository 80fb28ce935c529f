//! Whether reported sigmas cover their errors, in one line: the errors
//! beyond 3 of their sigmas, each named by its step and figure (an output,
//! or an identified parameter; and its part, in a sweep). `gyrocal field`
//! says it for one device
//! (`crate::field::scenario::uncovered_error_warning`), `gyrocal sweep`
//! over the spread (`crate::sweep::summary`), which also says, per figure,
//! whether the sigmas are the size of their errors ([`Coverage`]).

use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// At most this many parts, or errors, are named in a warning's line; the
/// JSON's `devices` name them all.
pub const NAMED: usize = 8;

/// The first `NAMED` items, comma-separated, and ", ..." when there are
/// more.
pub fn named<T: std::fmt::Display>(items: &[T]) -> String {
    let mut s = items
        .iter()
        .take(NAMED)
        .map(T::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    if items.len() > NAMED {
        s.push_str(", ...");
    }
    s
}

/// An identified parameter that has a truth to score it against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// Mode 1's frequency.
    F1,
    /// Mode 2's frequency.
    F2,
    /// Mode 1's Q.
    Q1,
    /// Mode 2's Q.
    Q2,
    /// The quadrature (stiffness) coupling, measured at rest.
    Quadrature,
    /// The damping coupling.
    Damping,
}

impl Parameter {
    /// Every parameter, in the order the summary lists them.
    pub const ALL: [Parameter; 6] = [
        Parameter::F1,
        Parameter::F2,
        Parameter::Q1,
        Parameter::Q2,
        Parameter::Quadrature,
        Parameter::Damping,
    ];
}

impl std::fmt::Display for Parameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Parameter::F1 => "f1",
            Parameter::F2 => "f2",
            Parameter::Q1 => "Q1",
            Parameter::Q2 => "Q2",
            Parameter::Quadrature => "quadrature",
            Parameter::Damping => "damping coupling",
        })
    }
}

/// What an error is of: an output's self-calibrated scale factor, or an
/// identified parameter. In JSON one key, `"output": 0` or `"parameter":
/// "f2"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Figure {
    /// Output 0 or 1's scale factor.
    Output(usize),
    /// An identified parameter.
    Parameter(Parameter),
}

impl std::fmt::Display for Figure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Figure::Output(k) => write!(f, "output {}", k + 1),
            Figure::Parameter(p) => write!(f, "{p}"),
        }
    }
}

/// An error and its sigma: which part (in a sweep), step and figure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scored {
    /// The part's index (`None`: the one device of a field run).
    pub device: Option<u32>,
    /// The step's temperature (deg C; NaN for a device without one,
    /// `gyrocal calibrate` of a file without `[drift]`: not named).
    pub temperature_c: f64,
    /// What the error is of.
    pub figure: Figure,
    /// Error over its reported sigma.
    pub t: f64,
}

impl Scored {
    /// Both outputs of one step: each error over its reported sigma.
    pub fn outputs(
        device: Option<u32>,
        temperature_c: f64,
        error: [f64; 2],
        sigma: [f64; 2],
    ) -> [Scored; 2] {
        std::array::from_fn(|output| Scored {
            device,
            temperature_c,
            figure: Figure::Output(output),
            t: error[output] / sigma[output],
        })
    }
}

impl std::fmt::Display for Scored {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(device) = self.device {
            write!(f, "device {device} ")?;
        }
        if self.temperature_c.is_finite() {
            write!(f, "at {} deg C ", self.temperature_c)?;
        }
        write!(f, "{} ({:+.3} sigma)", self.figure, self.t)
    }
}

/// The errors beyond 3 of their reported sigmas.
pub fn beyond_three_sigma(scored: &[Scored]) -> Vec<Scored> {
    scored.iter().filter(|s| s.t.abs() > 3.0).copied().collect()
}

/// One line naming `beyond` ([`beyond_three_sigma`] of `total` errors),
/// or None when there are none.
pub fn uncovered_errors(beyond: &[Scored], total: usize) -> Option<String> {
    uncovered(beyond, total, "errors")
}

/// [`uncovered_errors`] of identified parameters against the truth: the
/// line names each parameter, and where a coupling is among them, the
/// input outside the budget that most often puts it there: the couplings
/// are read in deg/s through lambda, which is the datasheet's.
pub fn uncovered_parameters(beyond: &[Scored], total: usize) -> Option<String> {
    let coupling = beyond.iter().any(|s| {
        matches!(
            s.figure,
            Figure::Parameter(Parameter::Quadrature | Parameter::Damping)
        )
    });
    uncovered(beyond, total, "identified parameters").map(|line| {
        if coupling {
            format!(
                "{line}; the couplings are read in deg/s through [datasheet] angular_gain, \
                 within its angular_gain_uncertainty"
            )
        } else {
            line
        }
    })
}

fn uncovered(beyond: &[Scored], total: usize, what: &str) -> Option<String> {
    (!beyond.is_empty()).then(|| {
        format!(
            "warning: {} of {total} {what} lie beyond 3 of their reported sigmas, which do not cover them: {}",
            beyond.len(),
            named(beyond)
        )
    })
}

/// `uncovered_errors` of self-calibration errors (against a simulated
/// truth), with the input outside the budget that most often puts one
/// there: lambda, which self-calibration takes from the datasheet.
pub fn uncovered_selfcal_errors(scored: &[Scored]) -> Option<String> {
    uncovered_errors(&beyond_three_sigma(scored), scored.len()).map(|line| {
        format!(
            "{line}; an input outside the budget is off: self-calibration takes lambda from \
             [datasheet] angular_gain, within its angular_gain_uncertainty, and the board's \
             clock as [drive] clock_hz, within clock_tolerance_ppm"
        )
    })
}

/// How one figure's errors (an output's, or an identified parameter's)
/// sit within their reported sigmas over many steps: the promise is 90 to
/// 99.5% within 2 sigma and none beyond 3, and a sigma much wider than its
/// errors breaks it too.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Coverage {
    /// What the errors are of (JSON: `output` or `parameter`).
    #[serde(flatten)]
    pub figure: Figure,
    /// How many errors (steps).
    pub errors: u32,
    /// How many parts they come from: the degrees of freedom of
    /// [`Coverage::rms_band`], since one part's steps share its
    /// identification and need not be independent.
    pub parts: u32,
    /// Fraction of the errors within 2 of their sigmas.
    pub within_2_sigma: f64,
    /// RMS of error / sigma: 1 where each sigma is its error's spread.
    pub rms_t: f64,
}

/// Probability of each side of [`Coverage::rms_band`]: a standard
/// normal's within 3, so that for one part the upper side is |t| <= 3,
/// the promise itself; the band narrows as the parts grow.
pub const RMS_BAND_PROBABILITY: f64 = 0.997_300_203_936_74;

/// Where a figure's sigmas lie against its errors' spread.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SigmaFit {
    /// Within [`Coverage::rms_band`]: the sigma is the errors' size.
    Fits,
    /// The RMS of error / sigma below the band: the sigma is wider than
    /// the errors (it covers them, and promises less than the device does).
    Wider,
    /// Above it: the sigma is narrower than the errors.
    Narrower,
}

impl Coverage {
    /// `figure`'s coverage over `scored` (None without an error of it).
    pub fn of(scored: &[Scored], figure: Figure) -> Option<Self> {
        let t: Vec<&Scored> = scored.iter().filter(|s| s.figure == figure).collect();
        if t.is_empty() {
            return None;
        }
        let n = t.len() as f64;
        let mut parts: Vec<Option<u32>> = t.iter().map(|s| s.device).collect();
        parts.sort_unstable();
        parts.dedup();
        Some(Self {
            figure,
            errors: t.len() as u32,
            parts: parts.len() as u32,
            within_2_sigma: t.iter().filter(|s| s.t.abs() <= 2.0).count() as f64 / n,
            rms_t: (t.iter().map(|s| s.t * s.t).sum::<f64>() / n).sqrt(),
        })
    }

    /// The band that the RMS of error / sigma over `parts` independent
    /// errors, each a standard normal t (every sigma the spread of its
    /// error), lies below, and above, each with probability P =
    /// [`RMS_BAND_PROBABILITY`]: sqrt(chi2(p) / n) for p = 1 - P and P,
    /// n = `parts` (an honest set falls outside it 0.54% of the time). Taking the
    /// parts, not the steps, as the degrees of freedom widens it where a
    /// part's steps move together.
    ///
    /// ```
    /// use gyrocal_sim::coverage::{Coverage, Figure};
    /// let c = Coverage { figure: Figure::Output(1), errors: 100, parts: 100, within_2_sigma: 1.0, rms_t: 0.24 };
    /// let (low, high) = c.rms_band();
    /// assert!((low - 0.807).abs() < 1e-3 && (high - 1.199).abs() < 1e-3, "{low} {high}");
    /// let one = Coverage { parts: 1, ..c };
    /// assert!((one.rms_band().1 - 3.0).abs() < 1e-9, "{:?}", one.rms_band());
    /// ```
    pub fn rms_band(&self) -> (f64, f64) {
        let n = f64::from(self.parts.max(1));
        let chi2 = ChiSquared::new(n).expect("n >= 1");
        let tail = 1.0 - RMS_BAND_PROBABILITY;
        let at = |p: f64| (chi2.inverse_cdf(p) / n).sqrt();
        (at(tail), at(1.0 - tail))
    }

    /// Whether the sigmas fit the errors' spread ([`Coverage::rms_band`]).
    pub fn fit(&self) -> SigmaFit {
        let (low, high) = self.rms_band();
        if self.rms_t < low {
            SigmaFit::Wider
        } else if self.rms_t > high {
            SigmaFit::Narrower
        } else {
            SigmaFit::Fits
        }
    }

    /// One line when the sigmas do not fit ([`Coverage::fit`]): a
    /// warning where they are narrower than the errors, a note where wider,
    /// with `largest` (where not empty), the budget terms that were each
    /// step's largest and at how many steps, most first.
    pub fn line(&self, largest: &[(&str, u32)]) -> Option<String> {
        let (kind, size) = match self.fit() {
            SigmaFit::Fits => return None,
            SigmaFit::Wider => ("note", "wider"),
            SigmaFit::Narrower => ("warning", "narrower"),
        };
        let (low, high) = self.rms_band();
        let terms = largest
            .iter()
            .map(|(name, steps)| format!("{name} at {steps}"))
            .collect::<Vec<_>>()
            .join(", ");
        let terms = if terms.is_empty() {
            terms
        } else {
            format!("; the largest term of its sigma: {terms}")
        };
        Some(format!(
            "{kind}: {}'s sigmas are {size} than its errors: RMS error/sigma {:.2} over {} errors \
             of {} parts ({low:.2} to {high:.2} if each sigma were its error's spread), {:.1}% within 2 sigma\
             {terms}",
            self.figure,
            self.rms_t,
            self.errors,
            self.parts,
            100.0 * self.within_2_sigma,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scored(device: u32, output: usize, t: f64) -> Scored {
        Scored {
            device: Some(device),
            temperature_c: 25.0,
            figure: Figure::Output(output),
            t,
        }
    }

    /// The band holds honest errors, and says wider or narrower sigmas:
    /// 100 t drawn standard normal fit; the same t over sigmas 4 times too
    /// wide, or 2 times too narrow, do not.
    #[test]
    fn the_rms_band_tells_sigmas_wider_or_narrower_than_their_errors() {
        use rand_distr::{Distribution, StandardNormal};
        use rand_xoshiro::rand_core::SeedableRng;
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        let t: Vec<f64> = (0..100).map(|_| StandardNormal.sample(&mut rng)).collect();
        let at = |scale: f64| {
            let s: Vec<Scored> = t
                .iter()
                .enumerate()
                .map(|(i, &t)| scored(i as u32, 1, scale * t))
                .collect();
            Coverage::of(&s, Figure::Output(1)).unwrap()
        };
        assert_eq!(at(1.0).fit(), SigmaFit::Fits, "{:?}", at(1.0));
        assert_eq!(at(1.0).line(&[]), None);
        assert_eq!(at(0.25).fit(), SigmaFit::Wider);
        assert_eq!(at(2.0).fit(), SigmaFit::Narrower);
        let wider = at(0.25)
            .line(&[("cycle_rate", 61), ("identified", 39)])
            .unwrap();
        assert!(
            wider.starts_with("note: output 2's sigmas are wider than its errors"),
            "{wider}"
        );
        assert!(
            wider.ends_with("cycle_rate at 61, identified at 39"),
            "{wider}"
        );
        assert!(
            at(2.0)
                .line(&[])
                .unwrap()
                .starts_with("warning: output 2's sigmas are narrower")
        );
        assert_eq!(Coverage::of(&[scored(0, 0, 1.0)], Figure::Output(1)), None);
    }

    /// The degrees of freedom are the parts: ten steps of one part whose
    /// t are all 0.3 are one part's error, which may sit anywhere.
    #[test]
    fn one_parts_steps_are_one_degree_of_freedom() {
        let s: Vec<Scored> = (0..10).map(|_| scored(7, 0, 0.3)).collect();
        let c = Coverage::of(&s, Figure::Output(0)).unwrap();
        assert_eq!((c.errors, c.parts), (10, 1));
        assert_eq!(c.fit(), SigmaFit::Fits);
        let apart: Vec<Scored> = (0..10).map(|i| scored(i, 0, 0.3)).collect();
        assert_eq!(
            Coverage::of(&apart, Figure::Output(0)).unwrap().fit(),
            SigmaFit::Wider
        );
    }

    /// A step is named by its temperature where it has one, never as "at
    /// NaN deg C".
    #[test]
    fn a_step_without_temperature_is_named_by_its_output() {
        let [one, two] = Scored::outputs(None, f64::NAN, [4e-3, 1e-4], [1e-3, 1e-3]);
        assert_eq!(one.to_string(), "output 1 (+4.000 sigma)");
        let line = uncovered_errors(&beyond_three_sigma(&[one, two]), 2).unwrap();
        assert!(!line.contains("NaN"), "{line}");
        let [at, _] = Scored::outputs(Some(3), 35.0, [4e-3, 1e-4], [1e-3, 1e-3]);
        assert_eq!(
            at.to_string(),
            "device 3 at 35 deg C output 1 (+4.000 sigma)"
        );
    }
}
