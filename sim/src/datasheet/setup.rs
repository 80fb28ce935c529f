//! The file `gyrocal datasheet` reads: the sections of `gyrocal run`, the
//! whole `[noise]` section ([`NoiseModel`]: Brownian and rate noises) and,
//! optionally, `[drift]` (temperature steps). A field scenario's
//! `[profile]` and `[drive_probe]` are accepted and not used, so the same
//! file serves `gyrocal field`.

use super::Error;
use crate::config::{self, Drive, Experiment, Filter, Frontend, NoiseModel, Points};
use crate::drift::Drift;
use crate::error::ConfigError;
use crate::gyro::GyroParams;
use crate::rate_drift::RateNoise;
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SetupFile {
    gyro: GyroParams,
    drive: Drive,
    #[serde(default)]
    frontend: Frontend,
    #[serde(default)]
    filter: Filter,
    experiment: Points,
    #[serde(default)]
    noise: NoiseModel,
    #[serde(default)]
    drift: Option<Drift>,
    #[serde(default)]
    #[allow(dead_code)] // reason: accepted, not used (module header)
    profile: Option<toml::Value>,
    #[serde(default)]
    #[allow(dead_code)] // reason: accepted, not used (module header)
    drive_probe: Option<toml::Value>,
}

/// A checked datasheet setup.
#[derive(Clone, Debug, PartialEq)]
pub struct Setup {
    /// The experiment; its `noise` is the Brownian part of `[noise]`.
    pub exp: Experiment,
    /// The rate noises of `[noise]`.
    pub rate_noise: RateNoise,
    /// The temperature steps, if the file has `[drift]`.
    pub drift: Option<Drift>,
}

/// Parse and check a setup file's text (`name` labels the errors): one
/// line naming the section and key.
pub fn parse(name: &str, text: &str) -> Result<Setup, Error> {
    let file: SetupFile =
        toml::from_str(text).map_err(|e| Error::Input(config::parse_error(name, text, e)))?;
    let input = |e: ConfigError| Error::Input(format!("{name}: {e}"));
    file.noise.validate().map_err(input)?;
    let exp = Experiment {
        gyro: file.gyro,
        drive: file.drive,
        frontend: file.frontend,
        filter: file.filter,
        points: file.experiment,
        noise: file.noise.thermal(),
        // The datasheet command measures the device; no host datasheet.
        datasheet: Default::default(),
    };
    exp.validate().map_err(input)?;
    exp.derived().map_err(input)?;
    if let Some(d) = &file.drift {
        d.validate().map_err(input)?;
    }
    Ok(Setup {
        exp,
        rate_noise: file.noise.rate(),
        drift: file.drift,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = "[gyro]\nf1_hz = 3.0123e3\nf2_hz = 3.1123e3\nq1 = 50\nq2 = 50\nangular_gain = 0.6\n[drive]\ncarrier_hz = 3.0123e3\nclock_hz = 15.123e3\n[experiment]\nreadout_rates_dps = [100, 200]\ncal_freqs_hz = [0.5, 1]\n";

    #[test]
    fn rate_noise_keys_and_drift_are_read() {
        let text = format!(
            "{BASE}[noise]\nseed = 3\nbias_instability_deg_per_h = 10\n[drift]\ntemperatures_c = [25, 35]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n"
        );
        let s = parse("d.toml", &text).unwrap();
        assert_eq!(s.rate_noise.bias_instability_deg_per_h, 10.0);
        assert_eq!(s.exp.noise.seed, 3);
        assert_eq!(s.drift.unwrap().temperatures_c, vec![25.0, 35.0]);
        let plain = parse("d.toml", BASE).unwrap();
        assert!(!plain.rate_noise.is_on() && plain.drift.is_none());
    }

    #[test]
    fn bad_keys_are_one_line_naming_them() {
        for (extra, start) in [
            (
                "[noise]\nrrw_deg_per_h_per_sqrt_h = -2\n",
                "d.toml: [noise] rrw_deg_per_h_per_sqrt_h = -2",
            ),
            (
                "[noise]\nbogus = 1\n",
                "d.toml line 14 in [noise]: unknown field `bogus`",
            ),
            (
                "[noise]\ntemperature_k = -1\n",
                "d.toml: [noise] temperature_k = -1",
            ),
        ] {
            let err = parse("d.toml", &format!("{BASE}{extra}"))
                .unwrap_err()
                .to_string();
            assert!(err.starts_with(start), "{err}");
            assert!(!err.contains('\n'));
        }
    }
}
