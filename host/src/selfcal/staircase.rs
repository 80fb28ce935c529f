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
use crate::stats::linear_fit;

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
/// 1 / (2 f_cal) spanning at least the first window.
///
/// Uncertainty: each period's mean cancels the ripple's shape, so the
/// spread of a window's period means is its noise; pooled over the windows
/// (one variance per output, sum of (M_i - 1) degrees of freedom) it gives
/// each window mean's variance s^2 / M_i, propagated through the
/// least-squares slope, sum of c_i^2 s^2 / M_i with c_i = (x_i - mean x) /
/// Sxx.
pub fn staircase(
    board: &mut dyn Board,
    knowns: &Knowns,
    op: &Operating,
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
        clip::check(board, "calibration staircase")?;
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
    var.sqrt()
}
