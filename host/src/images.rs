//! The DAC's images, aliased back by the ADC: the part of the sampled
//! loop that the phasor theory's single tone leaves out.
//!
//! The DAC holds each word for a clock T, so a drive phasor F at w leaves
//! it at every w + j ws (ws = 2 pi / T, j any integer), each with the
//! hold's response (1 - e^(-i v T)) / (i v T) at v = w + j ws. At those
//! frequencies that response is the carrier's times w / (w + j ws)
//! exactly (the phase factors e^(-i j pi) and sin(... + j pi) cancel).
//! The ADC samples x at the clock, where e^(i j ws n T) = 1: every image
//! lands on the carrier's own phasor. So the sampled loop sees, for each
//! mode, the response
//!
//! ```text
//! H_sampled(w) = sum_j H(w + j ws) w / (w + j ws)
//! ```
//!
//! of which the theory keeps j = 0 (its hold gain and delay). The images
//! are off resonance, 1 / (wk^2 - v^2) each, so they matter when the
//! carrier is a large fraction of the clock and the resonance is broad: on
//! a Q 160 device with its carrier at 0.38 of the clock they moved the
//! detuned output's calibration scale factor by +3.9% (measured +3.6%
//! before the ADC gains counted them, +3.9% since), at 0.13 of the clock
//! by 1e-4. They fall as 1 / j^3; `IMAGES` on each side leave
//! 1 / (2 IMAGES^2) of the first.
//!
//! The same sums bound the sampled displacement, which sets the ADC gains
//! (`sampled_peak`): an image adds to the continuous amplitude, and at
//! `adc_headroom` 0.9 a few percent more clip.

use crate::theory::{self, Device};
use nalgebra::Complex;
use std::f64::consts::TAU;

/// The front end's response at the images relative to the carrier's,
/// which the sampled loop carries onto it. A group delay tau turns the
/// image `shift` away by 2 pi tau shift: the model, as the fine fits take
/// it (`identify::FrontEnd`). `linear` is the first-order form
/// 1 + (a - j 2 pi tau) shift instead, with a gain slope a: exact for the
/// simulator's pick-off (a = sin(phi)^2 / f), whose gain grows with the
/// shift, a low-pass's falls (a = -sin(phi)^2 / f). At the first image,
/// some clocks away, a few clocks per carrier make that percents, and the
/// images can be percents of the response: the budget moves the
/// prediction to both ends. [`ImageFront::default`] is a flat front end
/// (the theory's).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImageFront {
    /// Group delay tau (s).
    pub delay_s: f64,
    /// Relative gain slope a (per Hz), in the `linear` form.
    pub gain_per_hz: f64,
    /// The first-order form instead of the turn.
    pub linear: bool,
}

impl ImageFront {
    /// The gain at `shift_hz` from the carrier, relative to the carrier's:
    /// 1 for the delay's turn; in the first-order form, what moves the
    /// calibration's sidebands apart as well as the images
    /// (`selfcal::predict`).
    pub fn gain(self, shift_hz: f64) -> f64 {
        self.at(shift_hz).0
    }

    /// (gain, lag in rad) at an image `shift_hz` from the carrier.
    fn at(self, shift_hz: f64) -> (f64, f64) {
        let turn = TAU * self.delay_s * shift_hz;
        if self.linear {
            let h = Complex::new(1.0 + self.gain_per_hz * shift_hz, -turn);
            (h.norm(), -h.arg())
        } else {
            (1.0, turn)
        }
    }
}

/// Images summed on each side of the carrier.
const IMAGES: i32 = 64;

/// The image indices j != 0 as frequency shifts j f_clk (Hz).
fn shifts(clock_hz: f64) -> impl Iterator<Item = f64> {
    (-IMAGES..=IMAGES)
        .filter(|&j| j != 0)
        .map(move |j| f64::from(j) * clock_hz)
}

/// `dev` with its carrier moved by `shift_hz` (the phasor solves take
/// signed frequencies).
fn moved(dev: &Device, shift_hz: f64) -> Device {
    Device {
        carrier_hz: dev.carrier_hz + shift_hz,
        ..dev.clone()
    }
}

/// What the images add to `theory::readout_z(dev, omz_rad_s)` (before the
/// hold gain, as that z is), through the `front` end.
pub fn readout_images(dev: &Device, clock_hz: f64, omz_rad_s: f64, front: ImageFront) -> [f64; 2] {
    let fc = dev.carrier_hz;
    shifts(clock_hz).fold([0.0; 2], |sum, shift| {
        let (gain, lag) = front.at(shift);
        let z = theory::readout_z_lagged(&moved(dev, shift), omz_rad_s, lag);
        let w = gain * fc / (fc + shift);
        [sum[0] + w * z[0], sum[1] + w * z[1]]
    })
}

/// What the images add to `theory::calibration_z_turning(dev, cal_hz,
/// lead_rad, sideband_gain, 0, omz_rad_s)`, through the `front` end.
pub fn calibration_images(
    dev: &Device,
    clock_hz: f64,
    cal_hz: f64,
    lead_rad: f64,
    sideband_gain: [f64; 2],
    front: ImageFront,
    omz_rad_s: f64,
) -> [f64; 2] {
    let fc = dev.carrier_hz;
    shifts(clock_hz).fold([0.0; 2], |sum, shift| {
        let (front_gain, lag) = front.at(shift);
        let gain: [f64; 2] = std::array::from_fn(|s| {
            let f = fc + [-cal_hz, cal_hz][s];
            front_gain * sideband_gain[s] * f / (f + shift)
        });
        let moved = moved(dev, shift);
        let z = theory::calibration_z_turning(&moved, cal_hz, lead_rad, gain, lag, omz_rad_s);
        [sum[0] + z[0], sum[1] + z[1]]
    })
}

/// Upper bound on the sampled displacement amplitudes `[|x1|, |x2|]` (m):
/// `peak` (a theory peak function of a device, carrier included) summed
/// over the carrier and its images, each weighted by |w / (w + j ws)|.
/// `dev` carries the forces as applied (hold gain included).
pub fn sampled_peak(dev: &Device, clock_hz: f64, peak: impl Fn(&Device) -> [f64; 2]) -> [f64; 2] {
    let fc = dev.carrier_hz;
    shifts(clock_hz).fold(peak(dev), |sum, shift| {
        let x = peak(&moved(dev, shift));
        let w = (fc / (fc + shift)).abs();
        [sum[0] + w * x[0], sum[1] + w * x[1]]
    })
}
