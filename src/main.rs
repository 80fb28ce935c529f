//! `gyrocal`: the command line of the gyrocal interface.
//!
//! Every error is one line on stderr naming what is wrong and what is
//! allowed; bad input exits with status 2, a failed run with status 1.

mod commands;
mod plots;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Reconfigurable phase readout and self-calibration of MEMS gyroscopes:
/// gateware export and co-simulation.
#[derive(Parser)]
#[command(name = "gyrocal", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write the exported Verilog and its port description to verilog-out/.
    Export(commands::export::Args),
    /// Co-simulate a device described in a TOML file: readout sweep and
    /// calibration staircase, scale factors against the exact theory.
    Run(commands::run::Args),
    /// Reproduce the paper's measurement on its device at full scale.
    Reproduce(commands::reproduce::Args),
    /// Measure the engines' speed side by side, and the reproduce run.
    Bench(commands::bench::Args),
    /// Self-calibrate a drifting device over temperature steps (TOML with `[drift]`).
    Field(commands::field::Args),
    /// Synthesize the export with Yosys and write verilog-out/RESOURCES.md.
    Synth(commands::synth::Args),
    /// Print the register words that program a board for a device (table,
    /// C header or JSON), from the plan `run` co-simulates.
    Registers(commands::registers::Args),
    /// Predict and measure the rate output's noise floor: Allan deviation, angle random walk, bias instability.
    Allan(commands::allan::Args),
    /// Put a simulated board (the file's gyroscope and the core) behind
    /// Etherbone over TCP, as LiteX's litex_server serves a real one.
    Serve(commands::serve::Args),
    /// Identify and self-calibrate a board (etherbone://, uio://, mem://),
    /// or without --board the file's device simulated in process.
    Calibrate(commands::calibrate::Args),
    /// Self-calibrate a production spread of devices (TOML with `[spread]`),
    /// whole or one shard (`--shard I/N`); `sweep merge` joins the shards,
    /// `sweep part` prints one part as a `field` file.
    Sweep(commands::sweep::Args),
    /// Measure an IEEE 952/1431-style datasheet: ARW, bias instability,
    /// rate random walk, Allan deviation with confidence intervals, scale
    /// factor, nonlinearity, temperature coefficients, bandwidth, turn-on.
    Datasheet(commands::datasheet::Args),
}

/// A failure, with the exit status it deserves.
#[derive(Debug)]
pub enum Failure {
    /// Bad input (a file, a key, a value): exit status 2.
    Input(String),
    /// The run itself failed: exit status 1.
    Run(String),
}

impl Failure {
    /// Bad input, from any error's message.
    pub fn input(e: impl ToString) -> Self {
        Failure::Input(e.to_string())
    }

    /// A failed run, from any error's message.
    pub fn run(e: impl ToString) -> Self {
        Failure::Run(e.to_string())
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    // A bad GYROCAL_ISA stops here, before any run would quietly pass it
    // over for the widest instruction set.
    let result = match gyrocal_hdl::model::isa::Isa::from_env() {
        Err(e) => Err(Failure::Input(e.to_string())),
        Ok(_) => run(cli.command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(msg)) => {
            eprintln!("error: {msg}");
            ExitCode::from(2)
        }
        Err(Failure::Run(msg)) => {
            eprintln!("error: {msg}");
            ExitCode::from(1)
        }
    }
}

/// The subcommand's work.
fn run(command: Command) -> Result<(), Failure> {
    match command {
        Command::Export(args) => commands::export::run(&args),
        Command::Run(args) => commands::run::run(&args),
        Command::Reproduce(args) => commands::reproduce::run(&args),
        Command::Bench(args) => commands::bench::run(&args),
        Command::Synth(args) => commands::synth::run(&args),
        Command::Registers(args) => commands::registers::run(&args),
        Command::Allan(args) => commands::allan::run(&args),
        Command::Datasheet(args) => commands::datasheet::run(&args),
        Command::Field(args) => commands::field::run(&args),
        Command::Sweep(args) => commands::sweep::run(&args),
        Command::Serve(args) => commands::serve::run(&args),
        Command::Calibrate(args) => commands::calibrate::run(&args),
    }
}
