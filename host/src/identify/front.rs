//! What identification knows of the front end's response across a fine
//! sweep (`fit::FrontSlope`): its group delay, measured by the line
//! through the two modes' phases, and a bound on its gain slope, which no
//! measurement at rest separates from the channels' gains.

use super::fit::{self, FrontSlope};
use super::{C64, Error, ModeFit, loop_phase};
use std::f64::consts::TAU;

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
    /// delay of `super::loop_phase` (measured, or a first-order front
    /// end's when the modes are not resolved). A lag phi of a first-order
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
        let both = |front: &FrontEnd| {
            let [m1, m2] = [0, 1]
                .map(|k| super::with_uncertainty(modes[k].clone(), k, clock_hz, pulls[k], front));
            Ok::<_, Error>([m1?, m2?])
        };
        let front = Self::of(modes, carrier_hz);
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

    /// A noise-free fine sweep of mode (fk, q) at clock `fs` seen through
    /// the simulator's pick-off (`frontend::PickoffPhase`: x cos phi -
    /// v sin phi / w_ref, referenced at fk, acting on every image at its
    /// own frequency), fitted with `slope`.
    fn fit_through_pickoff(fk: f64, q: f64, fs: f64, phi: f64, slope: FrontSlope) -> ModeFit {
        let bk = fk / q;
        let c = C64::from_polar(2.0e9, -phi);
        let pickoff = |v: f64| C64::new(phi.cos(), -phi.sin() * v / fk);
        let y = |f: f64| {
            let sum: C64 = (-fit::FIT_IMAGES..=fit::FIT_IMAGES)
                .map(|j| f + f64::from(j) * fs)
                .map(|v| (f / v) * pickoff(v) / C64::new((fk - v) * (fk + v), v * bk))
                .sum();
            c * sum * hold_gain(f, fs) / pickoff(fk)
        };
        let points: Vec<(f64, C64)> = [-1.5, -0.75, 0.0, 0.75, 1.5, 1.5, 0.75, 0.0, -0.75, -1.5]
            .iter()
            .map(|s| fk + s * bk)
            .map(|f| (f, y(f)))
            .collect();
        fit::fit_mode(&points, fk + 0.01 * bk, bk, Some(fs), &fit::no_pull, slope).unwrap()
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
    #[test]
    fn the_front_ends_delay_is_in_the_model_and_what_it_leaves_within_its_terms() {
        let phi = 2f64.to_radians();
        for (fk, q, fs) in [
            (2.6e4, 200.0, 3.5e5),
            (7.7e5, 2600.0, 2.2e6),
            (1e5, 100.0, 6e5),
            (25.1e3, 3000.0, 1.2345e6),
            (9.64e6, 5e4, 5e7),
        ] {
            let alone = fit_through_pickoff(fk, q, fs, phi, FrontSlope::default());
            let bias = (alone.q.value - q) / phi;
            assert!(bias > 0.7, "{fk} Hz: Q alone only {bias} phi high");
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
                    "{fk} Hz: {left:e} left, terms {term:e}"
                );
            }
            assert!(
                (m.q.value - q).abs() < 0.03 * phi,
                "{fk} Hz: Q {}",
                m.q.value
            );
        }
    }
}
