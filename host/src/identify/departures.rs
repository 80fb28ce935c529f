//! What identification found against what the datasheet said: a resonance,
//! the modes' split or a Q beyond a part's spread (`datasheet::F_SPREAD`,
//! `SPLIT_SPREAD`, `Q_SPREAD`) is said in one line. The figures rest on
//! the identified values and do not move; the line is for the person who
//! wrote the datasheet or owns the part. A datasheet Q sets the search's carrier steps and waits, so a
//! wrong one costs retries and time, and a Q far below its datasheet's is
//! what a package that lost its vacuum shows.

use super::{Estimate, Identified, search::shown_q};
use crate::datasheet::{F_SPREAD, Q_SPREAD, SPLIT_SPREAD, q_beyond_spread};
use crate::device::GyroParams;

impl Identified {
    /// [`datasheet_departures`] of these modes.
    pub fn datasheet_departures(&self, nominal: &GyroParams) -> Option<String> {
        let [m1, m2] = &self.modes;
        datasheet_departures(nominal, [m1.f_hz, m2.f_hz], [m1.q, m2.q])
    }
}

/// The datasheet's resonances and Qs (`nominal`) that lie beyond a part's
/// spread from the identified ones (`f_hz`, `q`, per mode), in one line,
/// or None.
///
/// ```
/// use gyrocal_host::GyroParams;
/// use gyrocal_host::identify::{Estimate, datasheet_departures};
/// let e = |value| Estimate { value, uncertainty: 0.5 };
/// let datasheet = GyroParams { f1_hz: 25.5e3, f2_hz: 26.2e3, q1: 3000.0, q2: 9000.0,
///     angular_gain: 0.8, quadrature_dps: 0.0, damping_coupling_dps: 0.0 };
/// let (f, q) = ([e(25e3), e(25.7e3)], [e(3000.0), e(3000.0)]);
/// let line = datasheet_departures(&datasheet, f, q).unwrap();
/// assert!(line.contains("q2 = 9000 is 3.0 times the identified 3000.00 +- 0.50"));
/// assert!(!line.contains("f1_hz")); // both 2% off: a part's spread
/// let swapped = GyroParams { f2_hz: 25.2e3, q2: 3000.0, ..datasheet };
/// let line = datasheet_departures(&swapped, f, q).unwrap();
/// assert!(line.contains("f2_hz - f1_hz = -300 Hz has the other sign"));
/// ```
pub fn datasheet_departures(
    nominal: &GyroParams,
    f_hz: [Estimate; 2],
    q: [Estimate; 2],
) -> Option<String> {
    let mut parts = vec![];
    let mut f_departs = false;
    for k in 0..2 {
        let f_said = [nominal.f1_hz, nominal.f2_hz][k];
        let relative = f_said / f_hz[k].value - 1.0;
        if relative.abs() > F_SPREAD {
            f_departs = true;
            parts.push(format!(
                "f{}_hz = {f_said} is {:.1}% {} the identified {}",
                k + 1,
                100.0 * relative.abs(),
                if relative > 0.0 { "above" } else { "below" },
                shown(f_hz[k], "Hz")
            ));
        }
        let q_said = nominal.q(k);
        let factor = q_said / q[k].value;
        if q_beyond_spread(factor) {
            parts.push(format!(
                "q{} = {} is {} times the identified {}",
                k + 1,
                shown_q(q_said),
                significant(factor),
                shown(q[k], "")
            ));
        }
    }
    // A resonance already named says the split too.
    if !f_departs {
        parts.extend(split_departure(nominal, f_hz, q));
    }
    (!parts.is_empty()).then(|| {
        format!(
            "warning: [datasheet] {}, beyond a part's spread ({}% in f, a factor of {SPLIT_SPREAD} in the split, a factor of {Q_SPREAD} in Q): the figures rest on the identified values; correct the datasheet (its f sets where the search starts, its Q the search's steps and waits), or check the part (a Q far below its datasheet's is what a lost vacuum shows)",
            parts.join("; "),
            100.0 * F_SPREAD
        )
    })
}

/// The datasheet's split f2 - f1 where it lies beyond a part's spread of
/// the identified one ([`SPLIT_SPREAD`]: a factor either way, or the other
/// sign, and more than the modes' mean bandwidth apart), as one part of
/// [`datasheet_departures`]'s line, or None.
fn split_departure(nominal: &GyroParams, f_hz: [Estimate; 2], q: [Estimate; 2]) -> Option<String> {
    // To 0.1 mHz: the difference of two written values, without the
    // binary fractions their subtraction leaves.
    let said = ((nominal.f2_hz - nominal.f1_hz) * 1e4).round() / 1e4;
    let found = Estimate {
        value: f_hz[1].value - f_hz[0].value,
        uncertainty: f_hz[0].uncertainty.hypot(f_hz[1].uncertainty),
    };
    let bandwidth = (f_hz[0].value / q[0].value + f_hz[1].value / q[1].value) / 2.0;
    let factor = said / found.value;
    let beyond = !(1.0 / SPLIT_SPREAD..=SPLIT_SPREAD).contains(&factor);
    if !beyond || (said - found.value).abs() <= bandwidth {
        return None;
    }
    let found_shown = shown(found, "Hz");
    let how = if factor > 0.0 {
        format!(
            "is {} times the identified split {found_shown}",
            significant(factor)
        )
    } else {
        format!(
            "has the other sign than the identified split {found_shown} (the modes in the other order)"
        )
    };
    Some(format!(
        "f2_hz - f1_hz = {said} Hz {how}, {} Hz apart, more than the modes' mean bandwidth {} Hz",
        significant((said - found.value).abs()),
        significant(bandwidth)
    ))
}

/// An estimate as `value +- sigma unit`, each to two significant digits
/// of the sigma.
fn shown(e: Estimate, unit: &str) -> String {
    let decimals = if e.uncertainty > 0.0 {
        (1.0 - e.uncertainty.log10().floor()).clamp(0.0, 9.0) as usize
    } else {
        0
    };
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    format!(
        "{:.decimals$} +- {:.decimals$}{unit}",
        e.value, e.uncertainty
    )
}

/// A ratio to two significant digits, more decimals below 1.
fn significant(x: f64) -> String {
    let decimals = (1.0 - x.log10().floor()).clamp(1.0, 9.0) as usize;
    format!("{x:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(value: f64, uncertainty: f64) -> Estimate {
        Estimate { value, uncertainty }
    }

    fn datasheet(f: [f64; 2], q: [f64; 2]) -> GyroParams {
        GyroParams {
            f1_hz: f[0],
            f2_hz: f[1],
            q1: q[0],
            q2: q[1],
            angular_gain: 0.8,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        }
    }

    /// Within a part's spread nothing is said, just beyond it each key is
    /// named with its factor or percent, all in one line.
    #[test]
    fn a_datasheet_beyond_a_parts_spread_is_named_key_by_key() {
        let f = [estimate(33e3, 1e-3), estimate(33.9e3, 1e-3)];
        let q = [estimate(5000.0, 2.0), estimate(6500.0, 2.0)];
        let inside = datasheet([33e3 * 1.049, 33.9e3 * 1.049], [9990.0, 3260.0]);
        assert_eq!(datasheet_departures(&inside, f, q), None);
        let beyond = datasheet([33e3 * 1.051, 33.9e3 * 0.949], [10010.0, 3240.0]);
        let line = datasheet_departures(&beyond, f, q).unwrap();
        for part in [
            "f1_hz = 34683 is 5.1% above the identified 33000.0000 +- 0.0010 Hz",
            "f2_hz = 32171.1 is 5.1% below the identified 33900.0000 +- 0.0010 Hz",
            "q1 = 10010 is 2.0 times the identified 5000.0 +- 2.0",
            "q2 = 3240 is 0.50 times the identified 6500.0 +- 2.0",
        ] {
            assert!(line.contains(part), "{part} not in {line}");
        }
        assert!(line.starts_with("warning: [datasheet] ") && !line.contains('\n'));
        // Its split (-2512 Hz for 900) is not said again.
        assert!(!line.contains("f2_hz - f1_hz"), "{line}");
    }

    /// Each f within a part's spread, the split beyond it: by a factor
    /// (just beyond 2 either way), of the other sign (the same size), and
    /// not where the split differs by a factor but by less than the modes'
    /// mean bandwidth (Q 5000 and 6500 at 33 kHz: 5.9 Hz), nor just within the
    /// factor.
    #[test]
    fn a_datasheet_split_beyond_a_parts_spread_is_named() {
        let f = [estimate(33e3, 1e-3), estimate(33.9e3, 1e-3)];
        let q = [estimate(5000.0, 2.0), estimate(6500.0, 2.0)];
        let said = |split: f64, f1: f64| {
            let ds = datasheet([f1, f1 + split], [5000.0, 6500.0]);
            datasheet_departures(&ds, f, q)
        };
        for (split, part) in [
            (
                1801.0,
                "f2_hz - f1_hz = 1801 Hz is 2.0 times the identified split 900.0000 +- 0.0014 Hz, 901.0 Hz apart, more than the modes' mean bandwidth 5.9 Hz",
            ),
            (
                449.0,
                "f2_hz - f1_hz = 449 Hz is 0.50 times the identified split 900.0000 +- 0.0014 Hz, 451.0 Hz apart",
            ),
            (
                -900.0,
                "f2_hz - f1_hz = -900 Hz has the other sign than the identified split 900.0000 +- 0.0014 Hz (the modes in the other order), 1800.0 Hz apart",
            ),
        ] {
            // The modes swapped about their mean (each 1.3% from its own).
            let f1 = if split < 0.0 {
                33.45e3 - split / 2.0
            } else {
                33e3
            };
            let line = said(split, f1).unwrap_or_else(|| panic!("{split}: nothing said"));
            assert!(line.contains(part), "{part} not in {line}");
            assert!(line.contains("a factor of 2 in the split"), "{line}");
            assert!(
                line.starts_with("warning: [datasheet] f2_hz - f1_hz = "),
                "{line}"
            );
        }
        // Within the factor, also with both modes moved 4% together.
        for (split, f1) in [(1799.0, 33e3), (451.0, 33e3), (900.0 * 1.04, 33e3 * 1.04)] {
            assert_eq!(said(split, f1), None, "{split}");
        }
        // Beyond the factor, within a bandwidth: matched modes.
        let matched = [estimate(33e3, 1e-3), estimate(33e3 + 2.0, 1e-3)];
        let ds = datasheet([33e3, 33e3 + 5.0], [5000.0, 6500.0]);
        assert_eq!(datasheet_departures(&ds, matched, q), None);
    }
}
