//! The table core's carrier lines in a fine-sweep point: the error they
//! can put on one measured Y, and what that error moves the fit by.
//!
//! A point's Y is the mean of z over a window of `SAMPLES_PER_PHASE`
//! samples, I, then Q a quarter turn later, with mode k's drive word as
//! both drive and reference (`probe`). A harmonic m of the words that the
//! carrier step folds Omega from the carrier (`crate::carrier_lines`) is a
//! line of relative size rho_m in the reference, which ripples z by rho_m
//! of the point's full magnitude |Y|, and in the drive, which the mode
//! passes at H(f + Omega) and so ripples z by rho_m |H(f + Omega) / H(f)|.
//! The output filter passes the ripple at its gain at Omega and the
//! window's mean keeps |sinc(pi Omega T)| of it. Drive and reference read
//! the table a `REF_PHASE` apart, so their lines' phases are unrelated:
//! their amplitudes add, as for the operating point (`selfcal::spurs`).
//! That is the pair's bound; their powers would be its mean square over
//! unrelated phases, but a pair's phases come back from run to run with
//! the sweep's timing, and with powers part 54's f2 read RMS error /
//! sigma 1.06 over 40 noise seeds (largest 2.83) against 0.93 with the
//! bound (`tests/table_lines.rs`; both with the waits' residues taken at
//! their windows' starts, `super::window_mean`).
//! Each line's phase in a window is the line's phase at the window's time,
//! which no sweep controls: a line is a cosine of random phase in each of
//! I and Q, of variance a^2 / 2. A point's error per component has the
//! variance sum(a^2) / 2 over its lines.
//!
//! The words' rounding is some tenths of an LSB whatever the word, so
//! the lines are a larger part of a small drive word: a high-Q mode
//! driven at a few thousandths of full scale to keep its peak below
//! clipping reads lines of some 1e-6 of its response (0.28% of full
//! scale, this module's doctest: 6.5e-7 at 1%, 1.4e-7 at 10%), and which
//! of them the filter and the window pass depends on the folds near each
//! carrier. On the consumer sweep's part 54 (mode 2 beside the clock's
//! 1 / 48, driven at 0.28%) they moved f2 by up to 3.2 of the sigma the
//! residuals and the jackknife gave (docs/sweep.md). The fit's residuals
//! see such errors only as far as they differ from the model's shape, so
//! they are carried apart, and once (`super::fit::noise_and_lines`).
//!
//! On the fine core the rounding is fed back away from the carrier: no
//! term.

use super::{C64, window_s};
use crate::carrier_lines::{
    FULL, SPUR_BAND_CORNERS, candidates, harmonics, output_gain, record_gain, relative,
};
use crate::error::Error;
use crate::knowns::Knowns;
use gyrocal_regs::datapath::{CarrierProfile, PEAK, q15_product};

/// The 1-sigma per real component of the error the table core's lines
/// put on the Y measured at `carrier_hz` through drive k at `amplitude`
/// (fraction of full scale), relative to |Y| (module header); the mode is
/// taken at `fk_hz`, `bk_hz` for the drive lines' response. 0 on the fine
/// core.
///
/// ```
/// # use gyrocal_host::knowns::{Derived, Knowns};
/// # use gyrocal_host::GyroParams;
/// # use gyrocal_regs::datapath::CarrierProfile;
/// # let gyro = GyroParams { f1_hz: 25.1e3, f2_hz: 25.8e3, q1: 3e3, q2: 3e3,
/// #     angular_gain: 0.8, quadrature_dps: 0.0, damping_coupling_dps: 0.0 };
/// # let mut knowns = Knowns {
/// #     filter: Derived { decimation: 643, butterworth_hz: 48.0, rc_hz: 192.0,
/// #         min_window_s: 0.27 },
/// #     rates_dps: vec![50.0], cal_freqs_hz: vec![2.0],
/// #     ..Knowns::exact(gyro, 1.2345e6, 25.1e3)
/// # };
/// use gyrocal_host::identify::point_spur_sd;
/// // Mode 2 half a bandwidth above the clock's 1 / 48 (25718.75 Hz),
/// // measured 0.75 bandwidths below it, driven at 1% and 10% of full
/// // scale: the words' rounding is a larger part of the smaller word.
/// let (fk, bk) = (25722.4, 7.0);
/// let small = point_spur_sd(&knowns, 1, fk - 0.75 * bk, 0.01, fk, bk).unwrap();
/// let large = point_spur_sd(&knowns, 1, fk - 0.75 * bk, 0.1, fk, bk).unwrap();
/// assert!(small > 2.0 * large && small < 1e-5, "{small:e} {large:e}");
/// knowns.carrier_profile = CarrierProfile::Fine;
/// assert_eq!(point_spur_sd(&knowns, 1, fk - 0.75 * bk, 0.01, fk, bk).unwrap(), 0.0);
/// ```
pub fn point_spur_sd(
    knowns: &Knowns,
    k: usize,
    carrier_hz: f64,
    amplitude: f64,
    fk_hz: f64,
    bk_hz: f64,
) -> Result<f64, Error> {
    if knowns.carrier_profile != CarrierProfile::Table {
        return Ok(0.0);
    }
    let amps = if k == 0 {
        (amplitude, 0.0)
    } else {
        (0.0, amplitude)
    };
    let (regs, real) = knowns.registers(carrier_hz, None, amps, 0.0)?;
    let word = [regs.amp.0, regs.amp.1][k];
    let spectrum = harmonics(i32::from(q15_product(word, PEAK as i16)));
    let per_step = knowns.clock_hz / 2f64.powi(32);
    let band = SPUR_BAND_CORNERS * knowns.filter.butterworth_hz;
    let record = window_s(knowns);
    let f = real.carrier_hz;
    let response = |f: f64| 1.0 / C64::new(fk_hz * fk_hz - f * f, f * bk_hz).norm();
    let here = response(f);
    let variance: f64 = candidates(regs.carrier_step, (band / per_step) as u32, FULL)
        .into_iter()
        .map(|(m, side)| {
            let omega = f64::from(side) * per_step;
            let a = relative(&spectrum, m)
                * (1.0 + response(f + omega) / here)
                * output_gain(&knowns.filter, omega.abs())
                * record_gain(omega.abs(), record);
            a * a / 2.0
        })
        .sum();
    Ok(variance.sqrt())
}
