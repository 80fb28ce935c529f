//! Whether reported sigmas cover their errors, in one line: the errors
//! beyond 3 of their sigmas, each named by its step and output (and its
//! part, in a sweep). `gyrocal field` says it for one device
//! (`crate::field::scenario::uncovered_error_warning`), `gyrocal sweep`
//! over the spread (`crate::sweep::summary`).

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

/// An error and its sigma: which part (in a sweep), step and output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scored {
    /// The part's index (`None`: the one device of a field run).
    pub device: Option<u32>,
    /// The step's temperature (deg C; NaN for a device without one,
    /// `gyrocal calibrate` of a file without `[drift]`: not named).
    pub temperature_c: f64,
    /// The output, 0 or 1.
    pub output: usize,
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
            output,
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
        write!(f, "output {} ({:+.3} sigma)", self.output + 1, self.t)
    }
}

/// The errors beyond 3 of their reported sigmas.
pub fn beyond_three_sigma(scored: &[Scored]) -> Vec<Scored> {
    scored.iter().filter(|s| s.t.abs() > 3.0).copied().collect()
}

/// One line naming `beyond` ([`beyond_three_sigma`] of `total` errors),
/// or None when there are none.
pub fn uncovered_errors(beyond: &[Scored], total: usize) -> Option<String> {
    (!beyond.is_empty()).then(|| {
        format!(
            "warning: {} of {total} errors lie beyond 3 of their reported sigmas, which do not cover them: {}",
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

#[cfg(test)]
mod tests {
    use super::*;

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
