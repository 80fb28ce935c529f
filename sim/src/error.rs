//! Typed errors of the simulator, from the leaves up: the models of the
//! analog side (`ModelError`: the gyroscope, its thermal noise, the
//! converters), the engines (`EngineError`), a configuration file's
//! checks (`ConfigError`), planning and running an experiment's points
//! (`RunError`), the Allan deviation (`AllanError`), the field
//! scenario's file (`ScenarioError`) and steps (`FieldError`), and the
//! device file of `gyrocal serve` and `gyrocal calibrate`
//! (`DeviceError`). Each message is one line naming what
//! is wrong and what is allowed.

use gyrocal_host::datasheet::DatasheetError;
use gyrocal_host::device::CouplingOutOfRange;
use gyrocal_regs::PlanError;
use gyrocal_regs::map::BusError;

/// What a leaf model refuses.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A parameter outside its range: `name = value: rule`, where the
    /// rule reads "allowed ..." or "must be ...".
    #[error("{name} = {value}: {rule}")]
    Parameter {
        /// The parameter as the user names it (a key, or what it is).
        name: String,
        /// Its value as given.
        value: String,
        /// What is allowed.
        rule: String,
    },
    /// A mode coupling beyond its range.
    #[error(transparent)]
    Coupling(#[from] CouplingOutOfRange),
    /// The thermal noise's one-clock state covariance has no Cholesky
    /// factor.
    #[error("thermal noise: the state covariance is not positive definite")]
    CovarianceNotPositiveDefinite,
}

impl ModelError {
    /// `name = value: rule`.
    pub fn parameter(
        name: impl Into<String>,
        value: impl ToString,
        rule: impl Into<String>,
    ) -> Self {
        Self::Parameter {
            name: name.into(),
            value: value.to_string(),
            rule: rule.into(),
        }
    }
}

/// What choosing or starting an engine refuses.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EngineError {
    /// A name that is no engine.
    #[error("engine {0:?}: allowed model, verilator, rtl")]
    Unknown(String),
    /// The Verilator engine, in a build without it.
    #[error("this build has no Verilator engine (rebuild with --features verilator)")]
    NotBuilt,
    /// The Verilated model could not be allocated.
    #[error("cannot create the Verilated model")]
    NotCreated,
}

/// What the checks of a configuration file refuse (`crate::config`):
/// one line naming the section and the key.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// The file is no TOML, or a key is unknown or of the wrong type:
    /// the file, the line and section where the parser stopped, and its
    /// message.
    #[error("{0}")]
    Syntax(String),
    /// A key outside its range: `[section] key = value: allowed`.
    #[error("[{section}] {key} = {value}: {allowed}")]
    Key {
        /// The section, without brackets.
        section: &'static str,
        /// The key (or the keys' sum it checks).
        key: String,
        /// Its value as given.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// A rule over several keys or a list's values, `[section] what:
    /// rule`.
    #[error("[{section}] {what}: {rule}")]
    Rule {
        /// The section, without brackets.
        section: &'static str,
        /// What breaks it (the keys, or the list and its value).
        what: String,
        /// The rule.
        rule: String,
    },
    /// A mode coupling of `[gyro]` beyond its range.
    #[error("[gyro] {0}")]
    Coupling(#[from] CouplingOutOfRange),
    /// `[datasheet]` does not fit `[gyro]`.
    #[error(transparent)]
    Datasheet(#[from] DatasheetError),
    /// A key of the Brownian noise in `[noise]`.
    #[error("[noise] {0}")]
    Thermal(#[from] ModelError),
    /// A coupling that a step of `[drift]` carries out of its range.
    #[error("[drift] at {temperature_c} deg C (temperatures_c) {coupling}")]
    DriftCoupling {
        /// The step's temperature (deg C).
        temperature_c: f64,
        /// The coupling there.
        coupling: CouplingOutOfRange,
    },
}

impl ConfigError {
    /// `[section] key = value: allowed`.
    pub fn key(
        section: &'static str,
        key: impl Into<String>,
        value: impl ToString,
        allowed: impl Into<String>,
    ) -> Self {
        Self::Key {
            section,
            key: key.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    /// `[section] what: rule`.
    pub fn rule(section: &'static str, what: impl Into<String>, rule: impl Into<String>) -> Self {
        Self::Rule {
            section,
            what: what.into(),
            rule: rule.into(),
        }
    }
}

/// What planning or running an experiment's points refuses
/// (`crate::experiment`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RunError {
    /// The configuration's checks.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A frequency plan or filter the datapath cannot realize.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// A model of the analog side.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// An engine that does not start.
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// The Verilator engine, asked of a build without it.
    #[error("engine = \"verilator\": {}", EngineError::NotBuilt)]
    NoVerilator,
    /// A drive amplitude that rounds to no DAC word.
    #[error("[drive] amplitude1, amplitude2: both drives need at least one DAC LSB")]
    DrivesBelowOneLsb,
    /// Lanes of no point or board (`gyrocal_hdl::model::lanes`).
    #[error(transparent)]
    NoLane(#[from] gyrocal_hdl::model::lanes::NoLane),
}

/// What the Allan deviation and the noise fit of a rate series refuse
/// (`crate::allan`, `crate::noise_terms`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AllanError {
    /// A sample rate that is not a positive number.
    #[error("sample rate {0} Hz: must be finite and > 0")]
    SampleRate(f64),
    /// Fewer than 2 samples.
    #[error("{0} rate samples: the Allan deviation needs at least 2")]
    TooFewSamples(usize),
    /// A sample that is not finite.
    #[error("rate sample {index} is {value}: must be finite")]
    NotFinite {
        /// Its index.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A cluster of 0 samples or longer than half the series.
    #[error("cluster of {cluster} samples: allowed 1..={} for {samples} samples", samples / 2)]
    Cluster {
        /// Samples per cluster.
        cluster: usize,
        /// Samples in the series.
        samples: usize,
    },
    /// A series shorter than two clusters of the asked tau.
    #[error(
        "{samples} rate samples at {sample_rate_hz} Hz: reading tau = {tau_s} s needs at least {needed}"
    )]
    TooShortForTau {
        /// Samples in the series.
        samples: usize,
        /// Their rate (Hz).
        sample_rate_hz: f64,
        /// The tau asked (s).
        tau_s: f64,
        /// Samples it needs.
        needed: usize,
    },
    /// No Allan point at or above the fit's least tau.
    #[error(
        "no Allan point at tau >= {tau_min_s} s from {samples} samples at {sample_rate_hz} Hz: run longer"
    )]
    NothingToFit {
        /// The fit's least tau (s).
        tau_min_s: f64,
        /// Samples in the series.
        samples: usize,
        /// Their rate (Hz).
        sample_rate_hz: f64,
    },
}

/// What a field scenario's step, or the scenario, fails on
/// (`crate::field::scenario`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FieldError {
    /// The scenario's configuration.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// Planning the experiment, or building a board.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A host step (self-calibration, a measurement).
    #[error(transparent)]
    Host(#[from] gyrocal_host::Error),
    /// The simulated board refused a register access.
    #[error(transparent)]
    Bus(#[from] BusError),
    /// A baseline profile asked of a scenario without `[profile]`.
    #[error("no profile")]
    NoProfile,
}

/// What reading a scenario file refuses (`crate::field::scenario::parse`,
/// the sweep's and the device file's parsers): one line, led by the file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ScenarioError {
    /// The file is no TOML, or a key is unknown or of the wrong type:
    /// the file, the line and the parser's message.
    #[error("{0}")]
    Syntax(String),
    /// A key or a rule of its sections.
    #[error("{file}: {error}")]
    Invalid {
        /// The file.
        file: String,
        /// The key or rule at fault.
        error: ConfigError,
    },
    /// A `[spread]` in a file for `gyrocal field` (the file).
    #[error(
        "{0}: [spread] is read by `gyrocal sweep` (many devices); `gyrocal field` runs the file's one device: remove it"
    )]
    SpreadInField(String),
    /// No `[drift]` in a file for `gyrocal field` (the file).
    #[error(
        "{0}: missing [drift]: `gyrocal field` needs its temperature steps (temperatures_c, tcf1_ppm_per_k, tcf2_ppm_per_k)"
    )]
    NoDrift(String),
    /// A scenario that TOML cannot hold (the serializer's message), as a
    /// seed of 2^63 or more would be.
    #[error("the scenario cannot be written as a field file: {0}")]
    Unwritable(String),
}

/// What the device of a `gyrocal serve` or `gyrocal calibrate` file
/// refuses (`crate::serve::device`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DeviceError {
    /// The file, read as `gyrocal field` reads it (it has `[drift]`).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The file, read as `gyrocal run` reads it.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A temperature asked of a file without `[drift]`.
    #[error(
        "temperature {0} deg C: the file has no [drift] section, its device is [gyro] at one temperature"
    )]
    TemperatureWithoutDrift(f64),
    /// A temperature out of the drift's range (`TEMPERATURE_RANGE_C`).
    #[error("temperature {temperature_c} deg C: allowed {}..={}", range.0, range.1)]
    Temperature {
        /// The temperature asked (deg C).
        temperature_c: f64,
        /// The range allowed (deg C).
        range: (f64, f64),
    },
    /// A temperature where the drift breaks a rule (a gain or Q at zero).
    #[error("temperature {temperature_c} deg C: {error}")]
    Drift {
        /// The temperature asked (deg C).
        temperature_c: f64,
        /// The rule.
        error: ConfigError,
    },
    /// Building the converters or the board.
    #[error(transparent)]
    Run(#[from] RunError),
    /// Powering the board up.
    #[error(transparent)]
    Field(#[from] FieldError),
}
