//! The `[drive_probe]` section of a field scenario.

use crate::config::MAX_RATE_DPS;
use crate::error::ConfigError;
use serde::{Deserialize, Serialize};

/// The `[drive_probe]` section of a field scenario: after each step's
/// cycle the simulation's rate table turns the device at `rate_dps` while
/// the host measures the drive-gain ratio (the host is not told the rate).
///
/// ```toml
/// [drive_probe]
/// rate_dps = 200      # required: any non-zero rate within the rate limit
/// ```
///
/// A rate near the device's damping coupling, or below it, leaves the
/// ratio unsettled or on the identity's second root, and the step fails
/// in one line (`drive_ratio::measure`): probe several times faster than
/// the coupling.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveProbe {
    /// The steady rate during the measurement (deg/s).
    pub rate_dps: f64,
}

impl DriveProbe {
    /// Checks the rate; the error is one line naming the key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let r = self.rate_dps;
        if r.is_finite() && r != 0.0 && r.abs() <= MAX_RATE_DPS {
            Ok(())
        } else {
            Err(ConfigError::key(
                "drive_probe",
                "rate_dps",
                r,
                format!(
                    "allowed non-zero, -{MAX_RATE_DPS}..={MAX_RATE_DPS} deg/s \
                     (at rest the cross responses vanish)"
                ),
            ))
        }
    }
}
