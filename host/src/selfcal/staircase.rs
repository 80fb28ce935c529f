//! The calibration staircase: SELECT = 1 at each calibration frequency,
//! whole ripple periods averaged, the slope against the virtual rate and
//! its uncertainty from the spread of the period means.

use super::{FIRST_SETTLE_TAUS, MIN_RIPPLE_PERIODS, Operating};
use crate::board::Board;
use crate::clip;
use crate::error::Error;
use crate::identify;
use crate::knowns::Knowns;
use crate::sampling::{Signal, mean_of_parts, part_means};
use crate::stats::{coverage_factor, linear_fit};

/// A measured staircase.
#[derive(Clone, Debug, PartialEq)]
pub struct Staircase {
    /// Realized calibration frequencies (Hz).
    pub cal_hz: Vec<f64>,
    /// Window means (z LSB).
    pub z: Vec<[f64; 2]>,
    /// Least-squares slopes against 360 f_cal (z LSB per deg/s).
    pub sf_per_dps: [f64; 2],
    /// Their 1-sigma uncertainties (z LSB per deg/s): `staircase`.
    pub sf_uncertainty: [f64; 2],
    /// Clocks it took.
    pub clocks: u64,
}

/// The calibration staircase at `op`: each f_cal settles, then is averaged
/// over a whole number (at least `MIN_RIPPLE_PERIODS`) of ripple periods
/// 1 / (2 f_cal) spanning at least the first window. `peaks` are the ADC
/// peaks the identified response predicts at `op` (fraction of full
/// scale, [`super::adc_peaks`]), which a window that clipped quotes
/// ([`clip::cycle_detail`]).
///
/// Uncertainty: each period's mean cancels the ripple's shape, so the
/// spread of a window's period means is its noise; pooled over the windows
/// (one variance per output, sum of (M_i - 1) degrees of freedom) it gives
/// each window mean's variance s^2 / M_i, propagated through the
/// least-squares slope, sum of c_i^2 s^2 / M_i with c_i = (x_i - mean x) /
/// Sxx, times the coverage factor of those degrees of freedom
/// (`stats::coverage_factor`), as the simulator's rate table has it.
/// Windows at `MIN_RIPPLE_PERIODS` leave few: three windows of two
/// periods, 3 degrees of freedom and a factor of 3.0. Without it, a
/// device of that kind (unseen, 118 kHz on a 1.37 MHz clock) read its
/// output-2 staircase sigma anywhere from 0.7e-4 to 9.0e-4 over 16 noise
/// seeds, and one of its 48 figures lay 4.3 sigma out.
pub fn staircase(
    board: &mut dyn Board,
    knowns: &Knowns,
    op: &Operating,
    peaks: [f64; 2],
) -> Result<Staircase, Error> {
    let clock = knowns.clock_hz;
    let r = knowns.filter.decimation;
    let mut cal_hz = vec![];
    let mut parts = vec![];
    let mut clocks = 0;
    for (i, &f) in knowns.cal_freqs_hz.iter().enumerate() {
        let (regs, real) =
            knowns.registers(op.carrier_hz, Some(f), op.amplitude, op.ref_lag_deg)?;
        board.program(&regs)?;
        let taus = if i == 0 {
            FIRST_SETTLE_TAUS
        } else {
            identify::SETTLE_TAUS
        };
        let settle = knowns.settle_clocks(taus);
        board.wait_clocks(settle)?;
        clip::restart(board)?;
        let period = clock / (2.0 * real.cal_hz);
        let periods = (knowns.filter.min_window_s * 2.0 * real.cal_hz)
            .ceil()
            .max(MIN_RIPPLE_PERIODS as f64);
        let length = periods * period;
        parts.push(part_means(
            board,
            r,
            f64::from(r),
            length,
            periods as usize,
            Signal::Periodic,
        )?);
        clip::check_with(board, "calibration staircase", |adc, n| {
            clip::cycle_detail(adc, n, length, peaks[adc - 1])
        })?;
        clocks += settle + length as u64 + 2 * u64::from(r);
        cal_hz.push(real.cal_hz);
    }
    let means: Vec<[f64; 2]> = parts.iter().map(|p| mean_of_parts(p)).collect();
    let x: Vec<f64> = cal_hz.iter().map(|f| 360.0 * f).collect();
    let sf = std::array::from_fn(|k| {
        let y: Vec<f64> = means.iter().map(|m| m[k]).collect();
        linear_fit(&x, &y).0
    });
    Ok(Staircase {
        cal_hz,
        sf_per_dps: sf,
        sf_uncertainty: std::array::from_fn(|k| pooled_slope_uncertainty(&x, &parts, &means, k)),
        z: means,
        clocks,
    })
}

/// The least-squares slope's 1-sigma uncertainty on output `k` from the
/// windows' period means `parts` (`staircase`).
fn pooled_slope_uncertainty(
    x: &[f64],
    parts: &[Vec<[f64; 2]>],
    means: &[[f64; 2]],
    k: usize,
) -> f64 {
    let (mut ss, mut dof) = (0.0, 0usize);
    for (p, m) in parts.iter().zip(means) {
        ss += p.iter().map(|v| (v[k] - m[k]).powi(2)).sum::<f64>();
        dof += p.len() - 1;
    }
    let s2 = ss / dof as f64;
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let var: f64 = x
        .iter()
        .zip(parts)
        .map(|(xi, p)| ((xi - mx) / sxx).powi(2) * s2 / p.len() as f64)
        .sum();
    var.sqrt() * coverage_factor(dof as u32)
}

#[cfg(test)]
mod tests {
    use super::pooled_slope_uncertainty;
    use crate::sampling::mean_of_parts;
    use crate::stats::linear_fit;
    use rand_distr::{Distribution, StandardNormal};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use rand_xoshiro::rand_core::SeedableRng;

    /// Three windows of two ripple periods each (`MIN_RIPPLE_PERIODS`, as
    /// on a slow clock), period means with independent normal noise: the
    /// slope's error over its sigma is then a Student t of 3 degrees of
    /// freedom times 1 / coverage_factor(3). With the factor, 99.1% of
    /// trials lie within 2 sigma and 0.29% beyond 3 (scipy's t.sf at 6.0
    /// and 9.0); without it 86% and 5.8%. Over 8000 slopes (4000 trials,
    /// two outputs) the binomial 1-sigma of those fractions is 0.11% and
    /// 0.06%: the bounds below lie 4 to 6 of them out.
    #[test]
    fn the_slope_sigma_covers_its_error_with_two_periods_a_window() {
        let x = [4.0, 6.0, 9.0].map(|f: f64| 360.0 * f);
        let sf = [-1265.7, -46.5];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let mut draw = || -> f64 { StandardNormal.sample(&mut rng) };
        let trials = 4000;
        let (mut within_2, mut beyond_3) = (0usize, 0usize);
        for _ in 0..trials {
            let parts: Vec<Vec<[f64; 2]>> = x
                .iter()
                .map(|xi| {
                    (0..2)
                        .map(|_| [sf[0] * xi + 30.0 * draw(), sf[1] * xi + 300.0 * draw()])
                        .collect()
                })
                .collect();
            let means: Vec<[f64; 2]> = parts.iter().map(|p| mean_of_parts(p)).collect();
            for k in 0..2 {
                let y: Vec<f64> = means.iter().map(|m| m[k]).collect();
                let error = linear_fit(&x, &y).0 - sf[k];
                let t = error / pooled_slope_uncertainty(&x, &parts, &means, k);
                within_2 += usize::from(t.abs() < 2.0);
                beyond_3 += usize::from(t.abs() > 3.0);
            }
        }
        let n = (2 * trials) as f64;
        let (inside, outside) = (within_2 as f64 / n, beyond_3 as f64 / n);
        assert!(
            (0.985..=0.997).contains(&inside),
            "{:.2}% within 2 sigma (Student t: 99.1%)",
            100.0 * inside
        );
        assert!(
            outside <= 0.0063,
            "{:.2}% beyond 3 sigma (Student t: 0.29%)",
            100.0 * outside
        );
    }
}
