//! What identification found against what the datasheet said: a resonance
//! or a Q beyond a part's spread (`datasheet::F_SPREAD`, `Q_SPREAD`) is
//! said in one line. The figures rest on the identified values and do not
//! move; the line is for the person who wrote the datasheet or owns the
//! part. A datasheet Q sets the search's carrier steps and waits, so a
//! wrong one costs retries and time, and a Q far below its datasheet's is
//! what a package that lost its vacuum shows.

use super::{Estimate, Identified, search::shown_q};
use crate::datasheet::{F_SPREAD, Q_SPREAD, q_beyond_spread};
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
/// let datasheet = GyroParams { f1_hz: 25.5e3, f2_hz: 25.7e3, q1: 3000.0, q2: 9000.0,
///     angular_gain: 0.8, quadrature_dps: 0.0, damping_coupling_dps: 0.0 };
/// let (f, q) = ([e(25e3), e(25.7e3)], [e(3000.0), e(3000.0)]);
/// let line = datasheet_departures(&datasheet, f, q).unwrap();
/// assert!(line.contains("q2 = 9000 is 3.0 times the identified 3000.00 +- 0.50"));
/// assert!(!line.contains("f1_hz")); // 2% off: a part's spread
/// ```
pub fn datasheet_departures(
    nominal: &GyroParams,
    f_hz: [Estimate; 2],
    q: [Estimate; 2],
) -> Option<String> {
    let mut parts = vec![];
    for k in 0..2 {
        let f_said = [nominal.f1_hz, nominal.f2_hz][k];
        let relative = f_said / f_hz[k].value - 1.0;
        if relative.abs() > F_SPREAD {
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
    (!parts.is_empty()).then(|| {
        format!(
            "warning: [datasheet] {}, beyond a part's spread ({}% in f, a factor of {Q_SPREAD} in Q): the figures rest on the identified values; correct the datasheet (its f sets where the search starts, its Q the search's steps and waits), or check the part (a Q far below its datasheet's is what a lost vacuum shows)",
            parts.join("; "),
            100.0 * F_SPREAD
        )
    })
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
        let inside = datasheet([33e3 * 1.049, 33.9e3 * 0.951], [9990.0, 3260.0]);
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
    }
}
