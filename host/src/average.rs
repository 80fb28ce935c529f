//! Time averages of a sampled output over an exact window.
//!
//! The decimated outputs z arrive every R clocks, but a calibration window
//! must span a whole number of periods of the 2 Om ripple, which is rarely
//! a whole number of samples. Rounding the window to whole samples leaves an
//! error of up to A dt / T (ripple amplitude A, about 10x the DC value on the
//! paper's device; dt up to half a sample): 1e-4 already at R = 1000 and a
//! 50 ms window. So the average is the integral of the piecewise-linear
//! interpolant of the samples over the exact window [t0, t1], divided by its
//! length, with fractional end intervals.
//!
//! Error of that estimate for a ripple A cos(2 pi f t) sampled every h
//! seconds, averaged over whole periods T: the trapezoid rule's end
//! correction (Euler-Maclaurin) is h^2/12 [g'(t1) - g'(t0)], at most
//! pi f A h^2 / 3, so the mean is off by at most pi f A h^2 / (3 T); the
//! linear interpolation inside the two partial end intervals adds at most
//! 2 h A (2 pi f h)^2 / 8 / T. At f = 30 Hz, h = 20 us (R = 1000 at 50 MHz)
//! and T = 50 ms the two add to 2.5e-7 A: with A = 10 times the DC value,
//! 2.5e-6 of it, far below the 1e-4 asked of each point.

/// Mean of the piecewise-linear interpolant of `(t, v)` samples over
/// `[t0, t1]`. Samples must be sorted by time, cover the window
/// (`t[0] <= t0 < t1 <= t[last]`) and have distinct times.
pub fn window_mean(t: &[f64], v: &[f64], t0: f64, t1: f64) -> f64 {
    assert!(
        t.len() == v.len() && t.len() >= 2,
        "need at least two samples"
    );
    assert!(
        t0 < t1 && t[0] <= t0 && t1 <= t[t.len() - 1],
        "window not covered by the samples"
    );
    let value_at = |i: usize, x: f64| v[i] + (v[i + 1] - v[i]) * (x - t[i]) / (t[i + 1] - t[i]);
    let mut integral = 0.0;
    for i in 0..t.len() - 1 {
        let (a, b) = (t[i].max(t0), t[i + 1].min(t1));
        if a < b {
            integral += 0.5 * (value_at(i, a) + value_at(i, b)) * (b - a);
        }
    }
    integral / (t1 - t0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_periods_of_a_ripple_average_to_the_dc_value() {
        // DC 1 plus a ripple 10 times larger at 20..30 Hz, sampled at 50 kHz
        // from an arbitrary phase; windows of whole ripple periods that
        // start and end between samples. Bound: the analysis above.
        let h = 20e-6;
        for (f, phase, t0) in [
            (20.0, 0.3, 0.01234567),
            (26.0, 1.9, 0.02),
            (30.0, -2.2, 0.0100001),
        ] {
            let t: Vec<f64> = (0..10_000).map(|k| k as f64 * h).collect();
            let v: Vec<f64> = t
                .iter()
                .map(|&x| 1.0 + 10.0 * (std::f64::consts::TAU * f * x + phase).cos())
                .collect();
            let periods = (0.05 * f).ceil();
            let span = periods / f;
            let mean = window_mean(&t, &v, t0, t0 + span);
            let pi = std::f64::consts::PI;
            let bound = pi * f * 10.0 * h * h / (3.0 * span)
                + 2.0 * h * 10.0 * (2.0 * pi * f * h).powi(2) / 8.0 / span;
            assert!((mean - 1.0).abs() <= bound, "f {f}: {mean}, bound {bound}");
        }
    }

    #[test]
    fn a_line_is_averaged_exactly() {
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.5).collect();
        let v: Vec<f64> = t.iter().map(|x| 3.0 * x - 2.0).collect();
        let m = window_mean(&t, &v, 1.3, 17.9);
        assert!((m - (3.0 * (1.3 + 17.9) / 2.0 - 2.0)).abs() < 1e-12);
    }
}
