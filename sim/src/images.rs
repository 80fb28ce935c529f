//! The DAC's images in the simulated loop: the part of the simulation
//! that the exact theory leaves out (the truth's own error). The sums
//! themselves are the host's (`gyrocal_host::images`), which predicts with
//! them; this module adds them at a point of a plan.

pub use gyrocal_host::images::{ImageFront, calibration_images, readout_images, sampled_peak};

use crate::experiment::{Experiment, Mode, Plan, PointPlan, envelope_lead_rad, hold_gain};
#[cfg(test)]
use crate::theory::{self, Device};

impl Plan {
    /// z the images add at a point (m^2/s^2), hold included, per output:
    /// the sampled loop's steady state is `theory_z + image_z`.
    pub fn image_z(&self, exp: &Experiment, p: &PointPlan) -> [f64; 2] {
        let dev = self.theory_device_in(exp, p.mode);
        let clock = exp.drive.clock_hz;
        let z = match p.mode {
            Mode::Readout => readout_images(&dev, clock, p.omz_rad_s, ImageFront::default()),
            Mode::Calibration => {
                let gain = [-1.0, 1.0]
                    .map(|s| hold_gain(self.carrier_hz + s * p.cal_hz, clock) / self.hold_gain);
                let lead = envelope_lead_rad(p.cal_hz, clock);
                calibration_images(
                    &dev,
                    clock,
                    p.cal_hz,
                    lead,
                    gain,
                    ImageFront::default(),
                    0.0,
                )
            }
        };
        z.map(|z| z * self.hold_gain)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gyro::GyroModel;
    use std::f64::consts::{PI, TAU};

    /// A broad device read at 0.37 of the clock, where the images are
    /// large: mode 2 detuned by 3 bandwidths, Q 60.
    fn device() -> Device {
        Device {
            f1_hz: 100e3,
            f2_hz: 105e3,
            q1: 60.0,
            q2: 60.0,
            angular_gain: 0.7,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
            carrier_hz: 100e3,
            f1_force: 0.8,
            f2_force: 0.6,
        }
    }

    const CLOCK: f64 = 271.3e3;

    /// The float model of the resonator (exact zero-order-hold
    /// discretization), driven by held words and mixed with references
    /// lined up with the hold's half clock, averaged over `n` clocks after
    /// 4000 of settling: z per output. `drive(n)` gives the forces of clock
    /// n, `reference(t)` the references at time t (clocks).
    fn simulated(
        omz: f64,
        drive: impl Fn(f64) -> [f64; 2],
        reference: impl Fn(f64) -> [f64; 2],
    ) -> [f64; 2] {
        let mut g = GyroModel::new(&device().gyro_params(), CLOCK).unwrap();
        g.set_rate(omz);
        let n = 4_000_000u32;
        let mut z = [0.0; 2];
        for i in 0..4000 + n {
            let t = f64::from(i);
            if i >= 4000 {
                let r = reference(t - 0.5);
                z = [z[0] + g.x1() * r[0], z[1] + g.x2() * r[1]];
            }
            let [f1, f2] = drive(t);
            g.step(f1, f2);
        }
        z.map(|v| v / f64::from(n))
    }

    fn hold(f: f64) -> f64 {
        let x = PI * f / CLOCK;
        x.sin() / x
    }

    /// The simulated z within 2e-3 of the images from theory + images,
    /// and the images at least 1e-4 of z (the theory alone would miss).
    fn assert_closed(sim: [f64; 2], exact: [f64; 2], images: [f64; 2]) {
        for k in 0..2 {
            let miss = sim[k] - exact[k] - images[k];
            assert!(
                miss.abs() <= 2e-3 * images[k].abs(),
                "{k}: {sim:?} {exact:?} {images:?}"
            );
            assert!(
                images[k].abs() >= 1e-4 * exact[k].abs(),
                "{k}: {images:?} {exact:?}"
            );
        }
    }

    #[test]
    fn the_images_close_the_gap_between_theory_and_the_sampled_readout() {
        // The sampled loop against theory + images: within 2e-3 of the
        // images (the average over 4e6 clocks leaves 1e-6 of the
        // ripple; 64 images leave 1.2e-4 of the first), while the theory
        // alone misses by the images themselves, at least 1e-4 of z (the
        // resonant output's calibration) and up to 0.6% (the detuned one).
        let dev = device();
        let th = TAU * dev.carrier_hz / CLOCK;
        let (f1, f2) = (dev.f1_force, dev.f2_force);
        let omz = 40.0;
        let sim = simulated(
            omz,
            |t| [f1 * (th * t).cos(), f2 * (th * t).sin()],
            |t| [f1 * (th * t).cos(), f2 * (th * t).sin()],
        );
        let exact = theory::readout_z(&dev, omz).map(|z| z * hold(dev.carrier_hz));
        let images = readout_images(&dev, CLOCK, omz, ImageFront::default())
            .map(|z| z * hold(dev.carrier_hz));
        assert_closed(sim, exact, images);
    }

    #[test]
    fn the_images_close_the_gap_in_calibration() {
        // Drives F1 cos(wb t) cos(Om t), F2 sin(wb t) sin(Om t), each
        // output mixed with the other drive, envelopes lined up with the
        // hold too (no lead); the sidebands carry their own hold gains.
        // f_cal = CLOCK / 400: the 4e6 clocks are whole ripple periods.
        let dev = device();
        let cal = CLOCK / 400.0;
        let (th, om) = (TAU * dev.carrier_hz / CLOCK, TAU * cal / CLOCK);
        let (f1, f2) = (dev.f1_force, dev.f2_force);
        let drives = |t: f64| {
            [
                f1 * (th * t).cos() * (om * t).cos(),
                f2 * (th * t).sin() * (om * t).sin(),
            ]
        };
        let sim = simulated(0.0, drives, |t| {
            let d = drives(t);
            [d[1], d[0]]
        });
        let h = hold(dev.carrier_hz);
        let gain = [-1.0, 1.0].map(|s| hold(dev.carrier_hz + s * cal) / h);
        let exact = theory::calibration_z_of_datapath(&dev, cal, 0.0, gain).map(|z| z * h);
        let images = calibration_images(&dev, CLOCK, cal, 0.0, gain, ImageFront::default(), 0.0)
            .map(|z| z * h);
        assert_closed(sim, exact, images);
    }
}
