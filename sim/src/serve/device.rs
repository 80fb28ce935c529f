//! The device of a `gyrocal run` or `gyrocal field` file on a simulated
//! board, as `gyrocal serve` and `gyrocal calibrate` use it.
//!
//! - Without `[drift]` the device is `[gyro]` as given, with the converter
//!   gains of `[frontend]` and `[drive]` and no front-end phase.
//! - With `[drift]` it is `Drift::at` a temperature (deg C): the first step
//!   T0 unless another is asked for.
//! - The host's knowledge ([`DeviceFile::knowns`]) is the file's
//!   `[datasheet]` applied to `[gyro]` (the device itself when the section
//!   says nothing), `[drive]` and `[experiment]` its settings: the same
//!   function as the field scenario's (`scenario::knowns`).

use crate::config::{self, Experiment};
use crate::drift::{DeviceAt, Drift, TEMPERATURE_RANGE_C};
use crate::engine::Engine;
use crate::error::{ConfigError, DeviceError};
use crate::field::board::SimBoard;
use crate::field::scenario;
use crate::frontend::FrontEnd;
use gyrocal_host::Knowns;

/// A checked device file.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceFile {
    /// The experiment: device at T0, drive, front end, filter, points.
    pub exp: Experiment,
    /// Its `[drift]`, when it has one.
    pub drift: Option<Drift>,
}

/// Parse a file: with a `[drift]` section as `gyrocal field` reads it
/// (`scenario::parse`), else as `gyrocal run` does (`config::parse`).
/// Errors are one line; `name` (the path) labels them.
pub fn parse(name: &str, text: &str) -> Result<DeviceFile, DeviceError> {
    let has_drift = text
        .parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("drift"));
    if has_drift {
        let sc = scenario::parse(name, text)?;
        Ok(DeviceFile {
            exp: sc.exp,
            drift: Some(sc.drift),
        })
    } else {
        Ok(DeviceFile {
            exp: config::parse(name, text)?,
            drift: None,
        })
    }
}

impl DeviceFile {
    /// What a host programmed for this file knows (`scenario::knowns`).
    pub fn knowns(&self) -> Result<Knowns, ConfigError> {
        scenario::knowns(&self.exp)
    }

    /// The converters as built for the nominal device (`experiment::plan`).
    pub fn front_end(&self) -> Result<FrontEnd, DeviceError> {
        Ok(scenario::build(&self.exp)?.0)
    }

    /// The device at `temperature_c` (deg C); `None`: T0, or without
    /// `[drift]` the file's `[gyro]`, whose `temperature_c` is then NaN (the
    /// file names no temperature). A temperature without `[drift]`, or one
    /// where the drift drives a gain or Q to zero, is refused.
    pub fn at(&self, temperature_c: Option<f64>) -> Result<DeviceAt, DeviceError> {
        match (&self.drift, temperature_c) {
            (None, None) => Ok(DeviceAt {
                temperature_c: f64::NAN,
                delta_k: 0.0,
                gyro: self.exp.gyro.clone(),
                adc_gain: [1.0; 2],
                drive_gain: [1.0; 2],
                front_end_phase_deg: 0.0,
            }),
            (None, Some(t)) => Err(DeviceError::TemperatureWithoutDrift(t)),
            (Some(d), None) => Ok(d.at(&self.exp.gyro, d.reference_c())),
            (Some(d), Some(t)) => {
                let (lo, hi) = TEMPERATURE_RANGE_C;
                if !(t.is_finite() && (lo..=hi).contains(&t)) {
                    return Err(DeviceError::Temperature {
                        temperature_c: t,
                        range: TEMPERATURE_RANGE_C,
                    });
                }
                let mut with = d.clone();
                with.temperatures_c.push(t);
                with.validate().map_err(|error| DeviceError::Drift {
                    temperature_c: t,
                    error,
                })?;
                Ok(d.at(&self.exp.gyro, t))
            }
        }
    }

    /// A powered-up board on engine `E` holding the device at `at`
    /// (`scenario::board_on`: the drives have started).
    pub fn board<E: Engine>(&self, at: &DeviceAt) -> Result<SimBoard<E>, DeviceError> {
        Ok(scenario::board_on(&self.exp, &self.front_end()?, at)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RUN: &str = "
        [gyro]
        f1_hz = 33.3e3
        f2_hz = 34.1e3
        q1 = 600
        q2 = 900
        angular_gain = 0.75
        [drive]
        carrier_hz = 33.3e3
        clock_hz = 1.3579e6
        [experiment]
        readout_rates_dps = [50, 250]
        cal_freqs_hz = [3, 5]
    ";

    fn with_drift() -> String {
        format!(
            "{RUN}\n[drift]\ntemperatures_c = [25, 35]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -31\n"
        )
    }

    #[test]
    fn without_drift_the_device_is_the_gyro_section() {
        let f = parse("run.toml", RUN).unwrap();
        assert!(f.drift.is_none());
        let at = f.at(None).unwrap();
        assert_eq!(at.gyro, f.exp.gyro);
        assert!(at.temperature_c.is_nan());
        let e = f.at(Some(30.0)).unwrap_err();
        assert_eq!(e, DeviceError::TemperatureWithoutDrift(30.0));
        assert!(e.to_string().contains("no [drift]"), "{e}");
    }

    #[test]
    fn with_drift_the_device_is_at_the_temperature() {
        let f = parse("field.toml", &with_drift()).unwrap();
        assert_eq!(f.at(None).unwrap().gyro, f.exp.gyro);
        let at = f.at(Some(35.0)).unwrap();
        let expected = 33.3e3 * (1.0 - 30e-6 * 10.0);
        assert!((at.gyro.f1_hz - expected).abs() < 1e-9, "{}", at.gyro.f1_hz);
        let e = f.at(Some(1e4)).unwrap_err().to_string();
        assert!(e.starts_with("temperature 10000 deg C: allowed"), "{e}");
        assert!(!e.contains('\n'));
    }

    #[test]
    fn errors_name_the_file_and_line() {
        let e = parse("bad.toml", "[gyro]\nf1_hz = 'x'\n").unwrap_err();
        assert!(e.to_string().starts_with("bad.toml line 2"), "{e}");
    }
}
