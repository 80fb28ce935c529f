//! gyrocal-sim: gyroscope model, theory, co-simulation engines and experiments.
