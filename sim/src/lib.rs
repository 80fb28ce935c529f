//! gyrocal-sim: gyroscope model, theory, co-simulation engines and experiments.

pub mod fit;
pub mod gyro;
pub mod theory;
