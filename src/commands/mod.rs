//! One module per subcommand.

pub mod experiment;
pub mod export;
pub mod reproduce;
pub mod run;
