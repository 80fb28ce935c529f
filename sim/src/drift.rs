//! Temperature drift of the device and its front end, in quasi-static steps:
//! the `[drift]` section of a field scenario and the parameters it gives at
//! a temperature.
//!
//! Every coefficient is linear in the temperature step `dT = T - T0` from
//! the factory-calibration temperature `T0` (the first of
//! `temperatures_c`), around the nominal values, which hold at `T0`:
//!
//! ```text
//! fk(T)   = fk (1 + tcfk dT 1e-6)                 mode frequencies
//! Qk(T)   = Qk (1 + q_ppm_per_k dT 1e-6)          both modes alike
//! gain(T) = 1 + ppm_per_k dT 1e-6                 ADC k, DAC k: multipliers
//! phase(T) = front_end_phase_deg + front_end_phase_deg_per_k dT
//! Omq(T)  = quadrature_dps + quadrature_dps_per_k dT   quadrature coupling
//! ```
//!
//! The two frequency coefficients are also read as a common drift (their
//! mean, which moves the modes off the carrier) and a differential one
//! (`tcf2 - tcf1`, which moves the split and with it the readout over
//! calibration ratio): [`Drift::common_tcf_ppm_per_k`],
//! [`Drift::differential_tcf_ppm_per_k`], [`Drift::split_drift_hz_per_k`].
//!
//! ```toml
//! [drift]
//! temperatures_c = [25, 35, 15]     # required; the first is T0
//! tcf1_ppm_per_k = -30.0            # required
//! tcf2_ppm_per_k = -30.1            # required
//! q_ppm_per_k = 0                   # the rest default to 0
//! front_end_phase_deg = 0
//! front_end_phase_deg_per_k = 0
//! adc_gain_ppm_per_k = [0, 0]
//! drive_gain_ppm_per_k = [0, 0]
//! quadrature_dps_per_k = 0          # deg/s per K
//! ```

use crate::error::ConfigError;
use crate::gyro::{GyroParams, MAX_COUPLING_DPS};
use serde::{Deserialize, Serialize};

/// Lowest and highest temperature of a step (deg C): beyond any MEMS
/// qualification range, near enough to catch kelvins typed as Celsius.
pub const TEMPERATURE_RANGE_C: (f64, f64) = (-100.0, 250.0);

/// Most steps a scenario may list.
pub const MAX_STEPS: usize = 1000;

/// Largest magnitude of a ppm/K coefficient: 1e5 ppm/K is 10 %/K, far above
/// any device, enough for deliberate stress tests.
pub const MAX_PPM_PER_K: f64 = 1.0e5;

/// Largest magnitude of a front-end phase (deg) at any step.
pub const MAX_PHASE_DEG: f64 = 180.0;

/// The `[drift]` section.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Drift {
    /// Quasi-static temperature steps (deg C); the first is the
    /// factory-calibration temperature T0, where the nominal values hold.
    pub temperatures_c: Vec<f64>,
    /// Temperature coefficient of mode 1's frequency (ppm/K).
    pub tcf1_ppm_per_k: f64,
    /// Temperature coefficient of mode 2's frequency (ppm/K).
    pub tcf2_ppm_per_k: f64,
    /// Temperature coefficient of both Q (ppm/K).
    #[serde(default)]
    pub q_ppm_per_k: f64,
    /// Front-end phase at T0, unknown to the gateware's settings (deg).
    #[serde(default)]
    pub front_end_phase_deg: f64,
    /// Front-end phase drift (deg/K).
    #[serde(default)]
    pub front_end_phase_deg_per_k: f64,
    /// Gain drift of ADC 1 and ADC 2 (ppm/K).
    #[serde(default, deserialize_with = "exactly_two")]
    pub adc_gain_ppm_per_k: [f64; 2],
    /// Gain drift of drive (DAC) 1 and drive 2 (ppm/K).
    #[serde(default, deserialize_with = "exactly_two")]
    pub drive_gain_ppm_per_k: [f64; 2],
    /// Drift of the quadrature coupling `quadrature_dps` (deg/s per K),
    /// at most `MAX_COUPLING_DPS` in magnitude.
    #[serde(default)]
    pub quadrature_dps_per_k: f64,
}

/// A two-element list, refusing any other length (serde's `[f64; 2]`
/// silently drops a third element).
fn exactly_two<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let v = Vec::<f64>::deserialize(d)?;
    <[f64; 2]>::try_from(v.as_slice())
        .map_err(|_| serde::de::Error::invalid_length(v.len(), &"an array of length 2"))
}

/// The device and front end at one temperature step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DeviceAt {
    /// Temperature of the step (deg C).
    pub temperature_c: f64,
    /// Step from T0 (K).
    pub delta_k: f64,
    /// The gyroscope at this temperature.
    pub gyro: GyroParams,
    /// ADC gain multipliers, 1 at T0.
    pub adc_gain: [f64; 2],
    /// Drive (DAC force) gain multipliers, 1 at T0.
    pub drive_gain: [f64; 2],
    /// Front-end phase (deg).
    pub front_end_phase_deg: f64,
}

/// Kelvin of a Celsius temperature.
pub fn kelvin(temperature_c: f64) -> f64 {
    temperature_c + 273.15
}

fn field_error(key: &str, value: impl std::fmt::Display, allowed: &str) -> ConfigError {
    ConfigError::key("drift", key, value, allowed)
}

fn check_ppm(key: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v.abs() <= MAX_PPM_PER_K {
        Ok(())
    } else {
        Err(field_error(
            key,
            v,
            &format!("allowed -{MAX_PPM_PER_K}..={MAX_PPM_PER_K} ppm/K"),
        ))
    }
}

impl Drift {
    /// Checks every key against its limits, and that every step keeps the
    /// gains and Q positive and the phase within +-MAX_PHASE_DEG. Errors are
    /// one line naming the key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let t = &self.temperatures_c;
        if t.is_empty() || t.len() > MAX_STEPS {
            return Err(ConfigError::rule(
                "drift",
                format!("temperatures_c has {} steps", t.len()),
                format!("allowed 1..={MAX_STEPS}"),
            ));
        }
        let (lo, hi) = TEMPERATURE_RANGE_C;
        if let Some(bad) = t
            .iter()
            .find(|v| !(v.is_finite() && (lo..=hi).contains(*v)))
        {
            return Err(ConfigError::rule(
                "drift",
                format!("temperatures_c contains {bad}"),
                format!("allowed {lo}..={hi} deg C"),
            ));
        }
        check_ppm("tcf1_ppm_per_k", self.tcf1_ppm_per_k)?;
        check_ppm("tcf2_ppm_per_k", self.tcf2_ppm_per_k)?;
        check_ppm("q_ppm_per_k", self.q_ppm_per_k)?;
        for k in 0..2 {
            check_ppm("adc_gain_ppm_per_k", self.adc_gain_ppm_per_k[k])?;
            check_ppm("drive_gain_ppm_per_k", self.drive_gain_ppm_per_k[k])?;
        }
        for (key, v) in [
            ("front_end_phase_deg", self.front_end_phase_deg),
            ("front_end_phase_deg_per_k", self.front_end_phase_deg_per_k),
        ] {
            if !v.is_finite() {
                return Err(field_error(key, v, "must be finite"));
            }
        }
        let q = self.quadrature_dps_per_k;
        if !(q.is_finite() && q.abs() <= MAX_COUPLING_DPS) {
            return Err(field_error(
                "quadrature_dps_per_k",
                q,
                &format!("allowed -{MAX_COUPLING_DPS}..={MAX_COUPLING_DPS} deg/s per K"),
            ));
        }
        self.check_steps()
    }

    /// Every step's multipliers stay positive and its phase in range.
    fn check_steps(&self) -> Result<(), ConfigError> {
        let coefficients = [
            ("tcf1_ppm_per_k", self.tcf1_ppm_per_k),
            ("tcf2_ppm_per_k", self.tcf2_ppm_per_k),
            ("q_ppm_per_k", self.q_ppm_per_k),
            ("adc_gain_ppm_per_k", self.adc_gain_ppm_per_k[0]),
            ("adc_gain_ppm_per_k", self.adc_gain_ppm_per_k[1]),
            ("drive_gain_ppm_per_k", self.drive_gain_ppm_per_k[0]),
            ("drive_gain_ppm_per_k", self.drive_gain_ppm_per_k[1]),
        ];
        for &t in &self.temperatures_c {
            let dt = t - self.reference_c();
            for (key, ppm) in coefficients {
                if scale(ppm, dt) <= 0.0 {
                    return Err(field_error(
                        key,
                        ppm,
                        &format!("drives its quantity to zero or below at {t} deg C"),
                    ));
                }
            }
            let phase = self.phase_deg(dt);
            if phase.abs() > MAX_PHASE_DEG {
                return Err(field_error(
                    "front_end_phase_deg_per_k",
                    self.front_end_phase_deg_per_k,
                    &format!(
                        "the phase reaches {phase} deg at {t} deg C (allowed +-{MAX_PHASE_DEG})"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Checks that the device `nominal` keeps its couplings in range at
    /// every step ([`GyroParams::check_couplings`], with the drifted
    /// quadrature, frequencies and Q). Errors are one line naming the step
    /// and the coupling, its value there and what is allowed. Call after
    /// [`Drift::validate`] and the `[gyro]` checks.
    pub fn validate_device(&self, nominal: &GyroParams) -> Result<(), ConfigError> {
        for &t in &self.temperatures_c {
            let gyro = self.at(nominal, t).gyro;
            gyro.check_couplings()
                .map_err(|coupling| ConfigError::DriftCoupling {
                    temperature_c: t,
                    coupling,
                })?;
        }
        Ok(())
    }

    /// No drift: the one step at `temperature_c`, where the nominal values
    /// hold (`gyrocal sweep` without `[drift]`: the factory calibration
    /// alone).
    pub fn constant(temperature_c: f64) -> Self {
        Self {
            temperatures_c: vec![temperature_c],
            tcf1_ppm_per_k: 0.0,
            tcf2_ppm_per_k: 0.0,
            q_ppm_per_k: 0.0,
            front_end_phase_deg: 0.0,
            front_end_phase_deg_per_k: 0.0,
            adc_gain_ppm_per_k: [0.0; 2],
            drive_gain_ppm_per_k: [0.0; 2],
            quadrature_dps_per_k: 0.0,
        }
    }

    /// The factory-calibration temperature T0 (deg C): the first step.
    ///
    /// # Panics
    /// If `temperatures_c` is empty (refused by [`Drift::validate`]).
    pub fn reference_c(&self) -> f64 {
        self.temperatures_c[0]
    }

    /// Mean of the two frequency coefficients (ppm/K).
    pub fn common_tcf_ppm_per_k(&self) -> f64 {
        0.5 * (self.tcf1_ppm_per_k + self.tcf2_ppm_per_k)
    }

    /// `tcf2 - tcf1` (ppm/K).
    pub fn differential_tcf_ppm_per_k(&self) -> f64 {
        self.tcf2_ppm_per_k - self.tcf1_ppm_per_k
    }

    /// How fast the split f2 - f1 of `nominal` moves (Hz/K).
    pub fn split_drift_hz_per_k(&self, nominal: &GyroParams) -> f64 {
        1e-6 * (nominal.f2_hz * self.tcf2_ppm_per_k - nominal.f1_hz * self.tcf1_ppm_per_k)
    }

    fn phase_deg(&self, delta_k: f64) -> f64 {
        self.front_end_phase_deg + self.front_end_phase_deg_per_k * delta_k
    }

    /// The device `nominal` (at T0) and its front end at `temperature_c`.
    pub fn at(&self, nominal: &GyroParams, temperature_c: f64) -> DeviceAt {
        let dt = temperature_c - self.reference_c();
        let q = scale(self.q_ppm_per_k, dt);
        DeviceAt {
            temperature_c,
            delta_k: dt,
            gyro: GyroParams {
                f1_hz: nominal.f1_hz * scale(self.tcf1_ppm_per_k, dt),
                f2_hz: nominal.f2_hz * scale(self.tcf2_ppm_per_k, dt),
                q1: nominal.q1 * q,
                q2: nominal.q2 * q,
                angular_gain: nominal.angular_gain,
                quadrature_dps: nominal.quadrature_dps + self.quadrature_dps_per_k * dt,
                damping_coupling_dps: nominal.damping_coupling_dps,
            },
            adc_gain: self.adc_gain_ppm_per_k.map(|ppm| scale(ppm, dt)),
            drive_gain: self.drive_gain_ppm_per_k.map(|ppm| scale(ppm, dt)),
            front_end_phase_deg: self.phase_deg(dt),
        }
    }

    /// [`Drift::at`] for every step, in order.
    pub fn steps(&self, nominal: &GyroParams) -> Vec<DeviceAt> {
        self.temperatures_c
            .iter()
            .map(|&t| self.at(nominal, t))
            .collect()
    }
}

/// The multiplier `1 + ppm dT 1e-6`.
fn scale(ppm_per_k: f64, delta_k: f64) -> f64 {
    1.0 + ppm_per_k * 1e-6 * delta_k
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> GyroParams {
        GyroParams {
            f1_hz: 9.64e6,
            f2_hz: 9.64025e6,
            q1: 55_000.0,
            q2: 55_000.0,
            angular_gain: 0.6,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
        }
    }

    fn parse(text: &str) -> Result<Drift, ConfigError> {
        let d: Drift =
            toml::from_str(text).map_err(|e| ConfigError::Syntax(e.message().to_string()))?;
        d.validate()?;
        Ok(d)
    }

    const MINIMAL: &str = "temperatures_c = [25, 35, 15]\n\
                           tcf1_ppm_per_k = -30\n\
                           tcf2_ppm_per_k = -30.1\n";

    #[test]
    fn minimal_section_takes_zero_defaults() {
        let d = parse(MINIMAL).unwrap();
        assert_eq!(d.reference_c(), 25.0);
        assert_eq!(d.q_ppm_per_k, 0.0);
        assert_eq!(d.adc_gain_ppm_per_k, [0.0; 2]);
        assert_eq!(d.drive_gain_ppm_per_k, [0.0; 2]);
        assert_eq!(d.front_end_phase_deg, 0.0);
        assert_eq!(d.quadrature_dps_per_k, 0.0);
        let at0 = d.at(&paper(), 25.0);
        assert_eq!(at0.gyro, paper());
        assert_eq!(at0.adc_gain, [1.0; 2]);
        assert_eq!(at0.delta_k, 0.0);
    }

    #[test]
    fn parameters_move_by_their_coefficients() {
        let d = parse(
            "temperatures_c = [20, 30]\n tcf1_ppm_per_k = -30\n tcf2_ppm_per_k = -31\n\
             q_ppm_per_k = 500\n front_end_phase_deg = 1.5\n front_end_phase_deg_per_k = -0.1\n\
             adc_gain_ppm_per_k = [100, -200]\n drive_gain_ppm_per_k = [1000, 0]\n\
             quadrature_dps_per_k = -2.5\n",
        )
        .unwrap();
        let p = GyroParams {
            quadrature_dps: 300.0,
            damping_coupling_dps: 4.0,
            ..paper()
        };
        let at = d.at(&p, 30.0);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        // -30 ppm/K x 10 K at 9.64 MHz: -2892 Hz (the issue's 290 Hz per K).
        assert!(close(at.gyro.f1_hz - p.f1_hz, -2892.0), "{}", at.gyro.f1_hz);
        assert!(close(at.gyro.f2_hz, p.f2_hz * (1.0 - 310e-6)));
        assert!(close(at.gyro.q1, 55_000.0 * 1.005) && close(at.gyro.q2, at.gyro.q1));
        assert!(close(at.adc_gain[0], 1.001) && close(at.adc_gain[1], 0.998));
        assert!(close(at.drive_gain[0], 1.01) && at.drive_gain[1] == 1.0);
        assert!(close(at.front_end_phase_deg, 0.5));
        assert_eq!(at.gyro.angular_gain, p.angular_gain);
        assert_eq!(at.gyro.quadrature_dps, 275.0);
        assert_eq!(at.gyro.damping_coupling_dps, 4.0);
        // The split moves by f2 tcf2 - f1 tcf1: -1 ppm/K of 9.64 MHz is
        // -9.64 Hz/K, and the split over the step agrees.
        let split_rate = d.split_drift_hz_per_k(&p);
        assert!((split_rate - (-9.64025 * 31.0 + 9.64 * 30.0)).abs() < 1e-9);
        let split_move = (at.gyro.f2_hz - at.gyro.f1_hz) - (p.f2_hz - p.f1_hz);
        assert!(
            (split_move - 10.0 * split_rate).abs() < 1e-6,
            "{split_move}"
        );
        assert_eq!(d.common_tcf_ppm_per_k(), -30.5);
        assert_eq!(d.differential_tcf_ppm_per_k(), -1.0);
        assert_eq!(d.steps(&p).len(), 2);
        assert!((kelvin(25.0) - 298.15).abs() < 1e-12);
    }

    #[test]
    fn a_quadrature_drifting_out_of_range_is_refused_at_its_step() {
        // 9.5e4 deg/s + 1e3 deg/s/K reaches 1.05e5 at 35 deg C, beyond 1e5.
        let d = parse(&format!("{MINIMAL}quadrature_dps_per_k = 1e3\n")).unwrap();
        let p = GyroParams {
            quadrature_dps: 9.5e4,
            ..paper()
        };
        let err = d.validate_device(&p).unwrap_err();
        assert!(
            matches!(
                err,
                ConfigError::DriftCoupling {
                    temperature_c: 35.0,
                    ..
                }
            ),
            "{err:?}"
        );
        let err = err.to_string();
        assert!(
            err.starts_with("[drift] at 35 deg C (temperatures_c) quadrature_dps = 105000:"),
            "{err}"
        );
        assert!(!err.contains('\n'), "{err}");
        let p = GyroParams {
            quadrature_dps: 8e4,
            ..paper()
        };
        assert!(d.validate_device(&p).is_ok());
    }

    #[test]
    fn bad_sections_are_refused_in_one_line_naming_the_key() {
        let cases = [
            ("tcf1_ppm_per_k = 1\ntcf2_ppm_per_k = 1\n", "temperatures_c"),
            (
                "temperatures_c = [25]\ntcf2_ppm_per_k = 1\n",
                "tcf1_ppm_per_k",
            ),
            (&format!("{MINIMAL}tcf3_ppm_per_k = 1\n"), "tcf3_ppm_per_k"),
            (&format!("{MINIMAL}adc_gain_ppm_per_k = [1]\n"), "length 2"),
            (
                &format!("{MINIMAL}drive_gain_ppm_per_k = [1, 2, 3]\n"),
                "length 2",
            ),
            (
                "temperatures_c = []\ntcf1_ppm_per_k = 1\ntcf2_ppm_per_k = 1\n",
                "temperatures_c",
            ),
            (
                "temperatures_c = [25, 400]\ntcf1_ppm_per_k = 1\ntcf2_ppm_per_k = 1\n",
                "temperatures_c",
            ),
            (
                "temperatures_c = [25]\ntcf1_ppm_per_k = 1e6\ntcf2_ppm_per_k = 1\n",
                "tcf1_ppm_per_k",
            ),
            (
                "temperatures_c = [25, 5]\ntcf1_ppm_per_k = 1\ntcf2_ppm_per_k = 1\n\
                 drive_gain_ppm_per_k = [0, 1e5]\n",
                "drive_gain_ppm_per_k",
            ),
            (
                &format!("{MINIMAL}front_end_phase_deg = 170\nfront_end_phase_deg_per_k = 2\n"),
                "front_end_phase_deg_per_k",
            ),
            (
                &format!("{MINIMAL}quadrature_dps_per_k = -2e5\n"),
                "quadrature_dps_per_k",
            ),
        ];
        for (text, key) in cases {
            let err = parse(text).expect_err(key).to_string();
            assert!(err.contains(key), "{key}: {err}");
            assert!(!err.trim_end().contains('\n'), "{err}");
        }
    }
}
