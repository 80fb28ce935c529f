//! Generator of `uncoupled_bits.json` (not compiled here): copied into
//! `sim/tests/` of a checkout of commit 4afc731 (the theory and model before
//! the mode couplings) and run there with
//! `cargo test --release -p gyrocal-sim --test uncoupled_bits_generator`;
//! it writes the exact bits of every theory function and of a model
//! trajectory to the path in `$UNCOUPLED_BITS`.

use gyrocal_sim::gyro::GyroModel;
use gyrocal_sim::theory::*;
use serde_json::{Value, json};

fn bits(v: &[f64]) -> Value {
    json!(v.iter().map(|x| format!("{:016x}", x.to_bits())).collect::<Vec<_>>())
}

fn devices() -> Vec<Device> {
    let d = |f1: f64, f2: f64, q1: f64, q2: f64, lam: f64, fb: f64, ff: [f64; 2]| Device {
        f1_hz: f1,
        f2_hz: f2,
        q1,
        q2,
        angular_gain: lam,
        carrier_hz: fb,
        f1_force: ff[0],
        f2_force: ff[1],
    };
    vec![
        d(9.64e6, 9.64025e6, 55e3, 55e3, 0.6, 9.64e6, [1.0, 1.0]),
        d(9.64e6, 9.64025e6, 55e3, 55e3, 0.6, 9.640125e6, [0.7, 1.3]),
        d(1.2345e6, 1.2345e6, 6e3, 6e3, 0.8, 1.2345e6, [1.0, 1.0]),
        d(3.0071e6, 3.00702e6, 3e4, 2.5e4, 0.6, 3.0071e6, [1.0, 2.0]),
        d(25.1e3, 25.8e3, 3e3, 3e3, 0.8, 25.1e3, [0.8, 0.6]),
        d(100.3e3, 101.3e3, 200.0, 200.0, 0.7, 100.312e3, [0.8, 0.6]),
        d(2.0e6, 2.000004e6, 1e5, 9e4, 0.7, 2.0e6, [0.3, 0.4]),
    ]
}

#[test]
fn generate() {
    let mut checks = vec![];
    for (i, dev) in devices().iter().enumerate() {
        for rate in [-500.0f64, 1.0, 20.0, 300.0] {
            let omz = rate.to_radians();
            for lag in [0.0, 0.01] {
                let z = readout_z_lagged(dev, omz, lag);
                checks.push(json!({"device": i, "what": "readout_z_lagged", "args": [omz, lag], "bits": bits(&z)}));
            }
            let x = readout_peak_displacement(dev, omz);
            checks.push(json!({"device": i, "what": "readout_peak_displacement", "args": [omz], "bits": bits(&x)}));
        }
        for f in [0.5, 10.0, 300.0] {
            let z = calibration_z(dev, f);
            checks.push(json!({"device": i, "what": "calibration_z", "args": [f], "bits": bits(&z)}));
            let x = calibration_peak_displacement(dev, f);
            checks.push(json!({"device": i, "what": "calibration_peak_displacement", "args": [f], "bits": bits(&x)}));
            for (lead, g, lag) in [(0.0, [1.0, 1.0], 0.0), (1e-5, [0.999, 1.001], -0.02)] {
                let z = calibration_z_lagged(dev, f, lead, g, lag);
                checks.push(json!({"device": i, "what": "calibration_z_lagged", "args": [f, lead, g[0], g[1], lag], "bits": bits(&z)}));
            }
        }
        checks.push(json!({"device": i, "what": "sf_read_per_rad_s", "args": [], "bits": bits(&sf_read_per_rad_s(dev))}));
        checks.push(json!({"device": i, "what": "sf_cal_per_rad_s", "args": [], "bits": bits(&sf_cal_per_rad_s(dev))}));
        // The model: 3000 clocks at 4 clocks per carrier period and more
        // (forces from a fixed pattern), rotating, then 1000 at rest.
        let clock = 4.1 * dev.f1_hz.max(dev.f2_hz);
        let mut g = GyroModel::new(&dev.gyro_params(), clock).unwrap();
        g.set_rate(3.0);
        for n in 0..3000 {
            let p = n as f64 * 1.3;
            g.step(p.cos(), (0.7 * p).sin());
        }
        g.set_rate(0.0);
        for n in 0..1000 {
            g.step((n as f64).sin(), 0.5);
        }
        checks.push(json!({"device": i, "what": "model_state", "args": [clock], "bits": bits(&g.state())}));
    }
    let devices: Vec<Value> = devices()
        .iter()
        .map(|d| json!({"f1_hz": d.f1_hz, "f2_hz": d.f2_hz, "q1": d.q1, "q2": d.q2, "angular_gain": d.angular_gain, "carrier_hz": d.carrier_hz, "f1_force": d.f1_force, "f2_force": d.f2_force}))
        .collect();
    let out = json!({"commit": "4afc731", "devices": devices, "checks": checks});
    let path = std::env::var("UNCOUPLED_BITS").unwrap();
    std::fs::write(path, serde_json::to_string_pretty(&out).unwrap() + "\n").unwrap();
}
