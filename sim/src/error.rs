//! Typed errors of the simulator's leaf models: the gyroscope, its
//! thermal noise and the converters, the path a sample takes from the DAC
//! to the ADC. Each message is one line naming what is wrong and what is
//! allowed. The layers above still speak `String`: `From` turns a
//! `ModelError` into its message, so `?` carries it up unchanged.

use gyrocal_host::device::CouplingOutOfRange;

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

impl From<ModelError> for String {
    fn from(e: ModelError) -> Self {
        e.to_string()
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

impl From<EngineError> for String {
    fn from(e: EngineError) -> Self {
        e.to_string()
    }
}
