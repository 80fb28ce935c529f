//! The corners of the supported ranges (docs/your-device.md, "Supported ranges") plan
//! with the required keys alone: no error, and every derived value inside
//! the limits of the block it sets.
//!
//! Corners: clock 100 kHz and 500 MHz; carrier (at mode 1) 1 kHz and
//! 0.4 x clock; Q 10 and 1e6; split 0 and +-20 mode bandwidths; f_cal from
//! a tenth of a bandwidth to 3 bandwidths, capped by the clock's limits. A
//! split that would put mode 2 outside 1 kHz .. 0.4 x clock is not a device
//! of the box (Q 10 with 20 bandwidths of split is twice the carrier) and
//! is skipped; the count of planned corners is checked.

use gyrocal_hdl::cic_decimator::MAX_DECIMATION;
use gyrocal_hdl::filter_design::{MAX_CUTOFF_RATIO, MIN_CUTOFF_RATIO, MIN_DECIMATION};
use gyrocal_hdl::settings::MAX_CAL_RATIO;
use gyrocal_sim::config::{Experiment, SAMPLES_PER_RIPPLE};
use gyrocal_sim::experiment::plan;
use gyrocal_sim::gyro::GyroParams;

#[test]
fn every_corner_plans_with_derived_values_in_range() {
    let mut planned = 0;
    for clock in [100e3f64, 500e6] {
        // Non-round carriers, as design.md asks of test devices.
        for carrier in [1.0123e3, 0.4 * clock * 0.99991] {
            for q in [10.0, 1e6] {
                let bandwidth = carrier / q;
                for split in [0.0, 20.0 * bandwidth, -20.0 * bandwidth] {
                    let f2 = carrier + split;
                    if !(1e3..=0.4 * clock).contains(&f2) {
                        continue;
                    }
                    let cal_max = (3.0 * bandwidth)
                        .min(clock * MAX_CAL_RATIO)
                        .min(clock / (2.0 * SAMPLES_PER_RIPPLE * f64::from(MIN_DECIMATION)))
                        // The planner floors clock / (2 x 20 x f_cal); at exactly
                        // this limit (R = 166, not a power of two) the quotient can
                        // round to 165.999..., so stay 1e-12 inside it.
                        * (1.0 - 1e-12);
                    let cals = vec![cal_max / 30.0, cal_max];
                    let gyro = GyroParams {
                        f1_hz: carrier,
                        f2_hz: f2,
                        q1: q,
                        q2: q,
                        angular_gain: 0.7,
                        quadrature_dps: 0.0,
                        damping_coupling_dps: 0.0,
                    };
                    let e = Experiment::with_required(gyro, carrier, clock, vec![10.0, 20.0], cals);
                    let what = format!("clock {clock} carrier {carrier} Q {q} split {split}");
                    let p = plan(&e).unwrap_or_else(|err| panic!("{what}: {err}"));
                    let d = &p.derived;
                    let fz = clock / f64::from(d.decimation);
                    assert!(
                        (MIN_DECIMATION..=MAX_DECIMATION).contains(&d.decimation),
                        "{what}: {d:?}"
                    );
                    for f in [d.butterworth_hz, d.rc_hz] {
                        assert!(
                            f >= fz * MIN_CUTOFF_RATIO && f <= fz * MAX_CUTOFF_RATIO,
                            "{what}: {d:?}"
                        );
                    }
                    assert!(d.min_window_s > 0.0 && d.min_window_s.is_finite(), "{what}");
                    assert!(p.points.iter().all(|pt| pt.settle_cycles > 0), "{what}");
                    planned += 1;
                }
            }
        }
    }
    // 2 clocks x 2 carriers x 2 Q x 3 splits = 24, less those that leave
    // the carrier range. Q 1e6: all 12 (20 bandwidths are 2e-5 of the
    // carrier). Q 10: 20 bandwidths are twice the carrier, so -20 never
    // fits, +20 fits only at the 1 kHz carrier: 4 + 2.
    assert_eq!(planned, 12 + 6, "corners planned");
}
