//! What identification knows of the front end's response across a fine
//! sweep (`fit::FrontSlope`): its group delay, measured by the line
//! through the two modes' phases, and a bound on its gain slope, which no
//! measurement at rest separates from the channels' gains.

use super::fit::{self, FrontSlope};
use super::probe::Prober;
use super::{C64, Error, Estimate, ModeFit, loop_phase};
use crate::board::Board;
use crate::knowns::{Knowns, TAU_MARGIN};
use std::f64::consts::{PI, TAU};

/// Bandwidths each side of a mode where identification measures once
/// more when the two modes are not resolved (`probe`): the delay turns
/// the phase between the two by 2 pi tau 16 bk, and the response there is
/// 1/16 of the peak, so the delay comes out about as well as from modes
/// 0.6 bandwidths apart (its sigma about sqrt 2 times the peak's relative
/// noise over 2 pi bk).
pub const PROBE_SPAN: f64 = 8.0;

/// Measures `mode` (mode k, fitted alone) at `PROBE_SPAN` bandwidths each
/// side, at the drive that puts its peak at the target (as its sweep did)
/// and its own settling, into `mode.probe`, and the delay they give into
/// `mode.probed_delay_s`; returns the clocks spent.
pub(super) fn probe(
    board: &mut dyn Board,
    knowns: &Knowns,
    k: usize,
    mode: &mut ModeFit,
) -> Result<u64, Error> {
    let (fk, q) = (mode.f_hz.value, mode.q.value);
    let bk = fk / q;
    let max = [knowns.amplitude.0, knowns.amplitude.1][k].abs();
    let mut prober = Prober::new(board, knowns, k, max / 8.0);
    prober.tau_s = TAU_MARGIN / (PI * bk);
    prober.set_amplitude_for_peak(mode.gain_hz2 / (fk * bk));
    mode.probe = vec![
        prober.measure(fk - PROBE_SPAN * bk)?,
        prober.measure(fk + PROBE_SPAN * bk)?,
    ];
    mode.probed_delay_s = probed_delay(mode, knowns.clock_hz, &fit::no_pull);
    Ok(prober.clocks)
}

/// The front end's delay `mode`'s probe points give (`mode` fitted with
/// `pull`): the delay with which the fitted model turns from one probe
/// point to the other as the measured responses do. The model's turn
/// depends on the delay directly (2 pi tau (f+ - f-)) and through the
/// DAC's images, which the delay turns by 2 pi tau fs and which at a few
/// clocks per carrier are a good part of the response out there: 1.5 times
/// the direct turn at 2.9 clocks per carrier and Q 2600, so that reading
/// the delay off one fit and refitting with it diverges. The turn is linear
/// in the delay but for the far images: Newton, twice. Each point's
/// phase sigma is the residuals' sigma over its response; the images'
/// weighting (the first-order form against the turn) is in the sigma too.
/// None without probe points or when a fit fails.
pub(super) fn probed_delay(
    mode: &ModeFit,
    clock_hz: f64,
    pull: &dyn Fn(f64) -> C64,
) -> Option<Estimate> {
    let [(fa, ya), (fb, yb)] = <[(f64, C64); 2]>::try_from(mode.probe.as_slice()).ok()?;
    let (fk, q) = (mode.f_hz.value, mode.q.value);
    let bk = fk / q;
    let turn = |delay_s: f64, linear: bool| {
        let slope = FrontSlope {
            delay_s,
            linear,
            ..mode.front
        };
        let m = fit::fit_mode(&mode.sweep, fk, bk, Some(clock_hz), pull, slope).ok()?;
        let ra = ya / fit::response(&m, fa, clock_hz);
        let rb = yb / fit::response(&m, fb, clock_hz);
        Some(((rb / ra).arg(), m.residual_sd))
    };
    // Newton on the turn, with a step that turns the farthest image the
    // fit carries by 0.01 rad (linear there to 5e-5); twice, as the
    // images' turns are not linear over the whole move.
    let step = 1e-2 / (TAU * f64::from(fit::FIT_IMAGES) * clock_hz);
    let root = |linear: bool| {
        let mut value = mode.front.delay_s;
        let (mut per_s, mut noise) = (f64::NAN, f64::NAN);
        for _ in 0..2 {
            let ((r0, sd), (r1, _)) = (turn(value, linear)?, turn(value + step, linear)?);
            per_s = (r1 - r0) / step;
            noise = sd;
            value -= r0 / per_s;
        }
        Some((
            value,
            (noise / ya.norm()).hypot(noise / yb.norm()) / per_s.abs(),
        ))
    };
    // The images' weighting, which the fits' own term carries
    // (`FrontEnd::moves`), moves this delay too: 0.2% to 1.3% of it on the
    // pick-off (`the_probe_points_measure_the_delay`).
    let ((value, noise), (other, _)) = (root(false)?, root(true)?);
    let sd = noise.hypot(other - value);
    (value.is_finite() && sd.is_finite()).then_some(Estimate {
        value,
        uncertainty: sd,
    })
}

/// The inverse-variance mean of `delays`; None if there are none.
pub(super) fn combined(delays: impl Iterator<Item = Estimate>) -> Option<Estimate> {
    let (mut sum, mut weight) = (0.0, 0.0);
    for d in delays {
        let w = d.uncertainty.powi(-2);
        sum += w * d.value;
        weight += w;
    }
    (weight > 0.0 && weight.is_finite()).then(|| Estimate {
        value: sum / weight,
        uncertainty: weight.sqrt().recip(),
    })
}

/// Rounds of refitting both modes with the delay their phases give
/// (`FrontEnd::refit_both`): the delay moves the fitted phases only at
/// second order (its background lies in quadrature with the phase,
/// `fit::FrontSlope`). On seeds 2001 to 2003 of `tests/field_coverage.rs`
/// the first refit moved the delay by 3% of its final sigma, the second by
/// under 1e-6 of it.
const ROUNDS: usize = 3;

/// The front end as the fine fits model it, with what is not known of it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FrontEnd {
    /// The slope in the model: the delay's estimate, no gain slope.
    pub slope: FrontSlope,
    /// The delay's 1-sigma uncertainty (s).
    pub delay_sd_s: f64,
    /// The gain slope lies within +- this (per Hz).
    pub gain_bound_per_hz: f64,
}

impl FrontEnd {
    /// The front end the two modes' phases imply at `carrier_hz`: the
    /// delay of `super::loop_phase` (measured: the line through the
    /// modes' phases, or their probe points when the modes are not
    /// resolved). A lag phi of a first-order
    /// front end (the pick-off, an RC) delays by sin(phi) cos(phi) / w
    /// and slopes the gain by +-sin(phi)^2 / f (`fit::FrontSlope`); the
    /// gain slope is bounded by that.
    pub(crate) fn of(modes: &[ModeFit; 2], carrier_hz: f64) -> Self {
        let (lag, delay) = loop_phase(modes, carrier_hz);
        let phi = lag.value.to_radians();
        let f = 0.5 * (modes[0].f_hz.value + modes[1].f_hz.value);
        Self {
            slope: FrontSlope {
                delay_s: delay.value,
                ..FrontSlope::default()
            },
            delay_sd_s: delay.uncertainty,
            gain_bound_per_hz: phi.sin().powi(2) / f,
        }
    }

    /// `apparent`'s modes (each fitted alone) refitted with the front end
    /// their phases imply, to its fixed point (`ROUNDS`).
    pub(crate) fn refit_both(
        apparent: &[ModeFit; 2],
        carrier_hz: f64,
        clock_hz: f64,
    ) -> Result<[ModeFit; 2], Error> {
        let mut modes = apparent.clone();
        for _ in 0..ROUNDS {
            let front = Self::of(&modes, carrier_hz);
            let [m1, m2] =
                [0, 1].map(|k| super::refit(&apparent[k], k, clock_hz, &fit::no_pull, &front));
            modes = [m1?, m2?];
        }
        Ok(modes)
    }

    /// How far the fit of `mode` (mode k, fitted with `pull` and this
    /// front end) moves (fk Hz, Q, phase deg) when the delay moves by its
    /// sigma, and when the gain slope sits at its bound. The fit is
    /// linear in both at these sizes (the background they leave is some
    /// 1e-6 of the peak), so each is a central difference over a small
    /// step (a milliradian, a thousandth of the gain, across a
    /// bandwidth), scaled.
    pub(crate) fn moves(
        &self,
        mode: &ModeFit,
        k: usize,
        clock_hz: f64,
        pull: &dyn Fn(f64) -> C64,
    ) -> Result<[[f64; 3]; 3], Error> {
        let (fk, q) = (mode.f_hz.value, mode.q.value);
        let bk = fk / q;
        let fitted = |slope: FrontSlope| {
            fit::fit_mode(&mode.sweep, fk, bk, Some(clock_hz), pull, slope)
                .map(|m| [m.f_hz.value, m.q.value, m.phase_deg.value])
                .map_err(|reason| Error::Identification {
                    mode: k + 1,
                    reason: format!("with the front end's slope moved: {reason}"),
                })
        };
        let slope = |delay: f64, gain: f64| FrontSlope {
            delay_s: self.slope.delay_s + delay,
            gain_per_hz: self.slope.gain_per_hz + gain,
            ..self.slope
        };
        let per_unit = |step: FrontSlope, back: FrontSlope, size: f64, by: f64| {
            if by == 0.0 {
                // No sigma to carry (`complete`'s first pass): no fits.
                return Ok([0.0; 3]);
            }
            let (up, down) = (fitted(step)?, fitted(back)?);
            Ok::<_, Error>(std::array::from_fn(|i| {
                ((up[i] - down[i]) / (2.0 * size) * by).abs()
            }))
        };
        let (dt, da) = (1e-3 / (TAU * bk), 1e-3 / bk);
        let linear = FrontSlope {
            linear: true,
            ..self.slope
        };
        Ok([
            per_unit(slope(dt, 0.0), slope(-dt, 0.0), dt, self.delay_sd_s)?,
            per_unit(slope(0.0, da), slope(0.0, -da), da, self.gain_bound_per_hz)?,
            per_unit(linear, self.slope, 0.5, 1.0)?,
        ])
    }

    /// Both `modes` (fitted with `pulls` and the front end they imply,
    /// [`FrontEnd::of`]) with their uncertainties completed
    /// (`super::with_uncertainty`); the delay's sigma is that of the line
    /// through the completed phases.
    pub(crate) fn complete(
        modes: &[ModeFit; 2],
        carrier_hz: f64,
        clock_hz: f64,
        pulls: [&dyn Fn(f64) -> C64; 2],
    ) -> Result<[ModeFit; 2], Error> {
        let front = Self::of(modes, carrier_hz);
        // The sweeps' part does not depend on the front end's sigmas: once
        // for both passes.
        let sweep =
            [0, 1].map(|k| super::sweep_uncertainty(&modes[k], clock_hz, pulls[k], front.slope));
        let both = |front: &FrontEnd| {
            let [m1, m2] = [0, 1].map(|k| {
                super::with_uncertainty(modes[k].clone(), sweep[k], k, clock_hz, pulls[k], front)
            });
            Ok::<_, Error>([m1?, m2?])
        };
        let phases_only = both(&FrontEnd {
            delay_sd_s: 0.0,
            gain_bound_per_hz: 0.0,
            ..front
        })?;
        both(&FrontEnd {
            slope: front.slope,
            ..Self::of(&phases_only, carrier_hz)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::theory::hold_gain;

    /// Modes (fk, q, clock) of the pick-off tests: Q 100 to 5e4, 2.9 to
    /// 50 clocks per carrier.
    const PICKOFF_MODES: [(f64, f64, f64); 5] = [
        (2.6e4, 200.0, 3.5e5),
        (7.7e5, 2600.0, 2.2e6),
        (1e5, 100.0, 6e5),
        (25.1e3, 3000.0, 1.2345e6),
        (9.64e6, 5e4, 5e7),
    ];

    /// A noise-free fine sweep of mode (fk, q) at clock `fs` seen through
    /// the simulator's pick-off (`frontend::PickoffPhase`: x cos phi -
    /// v sin phi / w_ref, referenced at fk, acting on every image at its
    /// own frequency), fitted with `slope`.
    fn fit_through_pickoff(fk: f64, q: f64, fs: f64, phi: f64, slope: FrontSlope) -> ModeFit {
        let bk = fk / q;
        let y = pickoff_response(fk, q, fs, phi);
        let points: Vec<(f64, C64)> = [-1.5, -0.75, 0.0, 0.75, 1.5, 1.5, 0.75, 0.0, -0.75, -1.5]
            .iter()
            .map(|s| fk + s * bk)
            .map(|f| (f, y(f)))
            .collect();
        let mut m =
            fit::fit_mode(&points, fk + 0.01 * bk, bk, Some(fs), &fit::no_pull, slope).unwrap();
        m.probe = [-PROBE_SPAN, PROBE_SPAN]
            .map(|s| fk + s * bk)
            .map(|f| (f, y(f)))
            .to_vec();
        m
    }

    /// The response of mode (fk, q) at clock `fs` through the pick-off.
    fn pickoff_response(fk: f64, q: f64, fs: f64, phi: f64) -> impl Fn(f64) -> C64 {
        let bk = fk / q;
        let c = C64::from_polar(2.0e9, -phi);
        let pickoff = move |v: f64| C64::new(phi.cos(), -phi.sin() * v / fk);
        move |f: f64| {
            let sum: C64 = (-fit::FIT_IMAGES..=fit::FIT_IMAGES)
                .map(|j| f + f64::from(j) * fs)
                .map(|v| (f / v) * pickoff(v) / C64::new((fk - v) * (fk + v), v * bk))
                .sum();
            c * sum * hold_gain(f, fs) / pickoff(fk)
        }
    }

    /// The pick-off's delay is what biased Q: fitted alone, a mode seen
    /// through 2 deg of pick-off lag comes out with Q high by 0.75 to 2
    /// phi (absolute; the most at 2.9 clocks per carrier, where the images
    /// are strong), on modes of Q 100 to 5e4 (as `tests/field_coverage.rs`
    /// found it on the simulator). With the delay sin(phi) cos(phi) / w in
    /// the model, what is left in fk and Q is the gain slope's pull and
    /// the images' weighting, and the terms `FrontEnd::moves` gives for
    /// them cover it: the pick-off sits at the end of both (its gain slope
    /// at the bound, its images on the first-order form), so its pull is
    /// their sum, to the 6% (at Q 100) that the two add at second order.
    /// So at 5 and 10 deg too (the lag `examples/sweep/phase_drift_20khz.toml`
    /// reaches), where Q's remainder grows past 0.03 phi (0.15 phi at
    /// 770 kHz and 10 deg) and the terms still cover it (at most 1.03 of
    /// their sum).
    #[test]
    fn the_front_ends_delay_is_in_the_model_and_what_it_leaves_within_its_terms() {
        for lag_deg in [2.0, 5.0, 10.0] {
            delay_in_the_model_leaves_within_its_terms(f64::to_radians(lag_deg));
        }
    }

    fn delay_in_the_model_leaves_within_its_terms(phi: f64) {
        for (fk, q, fs) in PICKOFF_MODES {
            let alone = fit_through_pickoff(fk, q, fs, phi, FrontSlope::default());
            let bias = (alone.q.value - q) / phi;
            assert!(
                bias > 0.7,
                "{fk} Hz, {phi} rad: Q alone only {bias} phi high"
            );
            let front = FrontEnd {
                slope: FrontSlope {
                    delay_s: phi.sin() * phi.cos() / (TAU * fk),
                    ..FrontSlope::default()
                },
                delay_sd_s: 0.0,
                gain_bound_per_hz: phi.sin().powi(2) / fk,
            };
            let m = fit_through_pickoff(fk, q, fs, phi, front.slope);
            let [_, gain, images] = front.moves(&m, 0, fs, &fit::no_pull).unwrap();
            for (i, left) in [m.f_hz.value - fk, m.q.value - q].into_iter().enumerate() {
                let term = gain[i] + images[i];
                assert!(
                    left.abs() <= 1.1 * term,
                    "{fk} Hz, {phi} rad: {left:e} left, terms {term:e}"
                );
            }
            // The delay in the model takes Q's bias to first order, so
            // what it leaves is small at the field's usual 2 deg.
            if phi < 2.5f64.to_radians() {
                assert!(
                    (m.q.value - q).abs() < 0.03 * phi,
                    "{fk} Hz, {phi} rad: Q {}",
                    m.q.value
                );
            }
        }
    }

    /// Modes that are not resolved give no line to read the delay off:
    /// their probe points at +-`PROBE_SPAN` bandwidths do. Through the
    /// pick-off at 2 deg, on the five modes, the delay from a mode fitted
    /// alone and from the fit with that delay in the model lie within
    /// 1.3% of the pick-off's group delay sin(phi) cos(phi) / w (the
    /// delay is solved for, not iterated: read off one fit and refitted
    /// with, it had diverged at 2.9 clocks per carrier), and within the
    /// images' term that the sigma carries.
    #[test]
    fn the_probe_points_measure_the_delay() {
        let phi = 2f64.to_radians();
        for (fk, q, fs) in PICKOFF_MODES {
            let tau = phi.sin() * phi.cos() / (TAU * fk);
            let alone = fit_through_pickoff(fk, q, fs, phi, FrontSlope::default());
            let first = probed_delay(&alone, fs, &fit::no_pull).unwrap().value;
            let slope = FrontSlope {
                delay_s: first,
                ..FrontSlope::default()
            };
            let after = probed_delay(
                &fit_through_pickoff(fk, q, fs, phi, slope),
                fs,
                &fit::no_pull,
            )
            .unwrap();
            let again = after.value;
            assert!(
                (first / tau - 1.0).abs() < 0.02,
                "{fk} Hz: alone {first:e} s, {tau:e}"
            );
            assert!(
                (again / tau - 1.0).abs() < 0.02,
                "{fk} Hz: {again:e} s, {tau:e}"
            );
            // Noise-free, its sigma is the images' term alone, which
            // covers what the turn leaves.
            assert!(
                (after.value - tau).abs() <= 1.01 * after.uncertainty,
                "{fk} Hz: {after:?}, {tau:e}"
            );
        }
    }
}
