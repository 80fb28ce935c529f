//! One module per subcommand.

pub mod allan;
pub mod bench;
pub mod calibrate;
pub mod datasheet;
pub mod experiment;
pub mod export;
pub mod field;
pub mod registers;
pub mod reproduce;
pub mod run;
pub mod serve;
pub mod sweep;
pub mod synth;
