//! `gyrocal serve --config FILE --listen HOST:PORT [--engine model|verilator]
//! [--temperature C]`: a simulated board (the file's gyroscope and the
//! core) behind Etherbone over TCP, the wire of LiteX's `litex_server`.
//!
//! The board runs freely from power-up, as hardware does; a client (LiteX's
//! `RemoteClient`, `gyrocal calibrate --board etherbone://HOST:PORT`)
//! reaches the core's registers at the byte offsets of REGISTERS.md from
//! address 0, and measures time by SAMPLE_COUNT. One line on stderr says
//! where it listens (with the port the system chose when PORT is 0); then
//! it serves until killed (Ctrl-C).

use super::experiment::read_config;
use crate::Failure;
use gyrocal_host::Board;
use gyrocal_sim::drift::DeviceAt;
use gyrocal_sim::engine::{EngineKind, ModelEngine};
use gyrocal_sim::serve::device::{self, DeviceFile};
use gyrocal_sim::serve::server::{Clocking, Log, Server};
use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::Arc;

/// Options of `gyrocal serve`.
#[derive(clap::Args)]
pub struct Args {
    /// Device: a `gyrocal run` file, or a `gyrocal field` file (with `[drift]`).
    #[arg(long)]
    pub config: PathBuf,
    /// Address to listen on, HOST:PORT (PORT 0: any free port, printed).
    #[arg(long, default_value = "127.0.0.1:1234")]
    pub listen: String,
    /// Datapath simulator: model (bit-true Rust, default) or verilator (the
    /// exported Verilog; needs a build with --features verilator).
    #[arg(long, default_value = "model")]
    pub engine: String,
    /// With `[drift]`: the device at this temperature (deg C; default the
    /// first step, T0).
    #[arg(long, allow_negative_numbers = true)]
    pub temperature: Option<f64>,
    /// Pace the board: at most CLOCKS clocks run after each bus request,
    /// then it waits for the next (a clock a slow wire can follow, the same
    /// on any machine; at most R, a client reading z misses no sample).
    /// Without it the board runs freely, as fast as it simulates.
    #[arg(long, value_name = "CLOCKS")]
    pub pace: Option<u64>,
}

/// Serve until killed.
pub fn run(args: &Args) -> Result<(), Failure> {
    let engine = engine(&args.engine)?;
    if args.pace == Some(0) {
        return Err(Failure::Input(
            "--pace 0: allowed 1 or more clocks per request".into(),
        ));
    }
    let (name, text) = read_config(&args.config)?;
    let file = device::parse(&name, &text).map_err(Failure::input)?;
    let at = file
        .at(args.temperature)
        .map_err(|e| Failure::Input(format!("--{e}")))?;
    let board = board(&file, &at, engine)?;
    let listener = TcpListener::bind(&args.listen)
        .map_err(|e| Failure::Input(format!("--listen {}: cannot listen: {e}", args.listen)))?;
    let log: Log = Arc::new(|line| eprintln!("gyrocal serve: {line}"));
    let clocking = Clocking {
        per_request: args.pace,
        ..Clocking::default()
    };
    let server = Server::start(board, listener, clocking, log);
    let here = server
        .local_addr()
        .map_err(|e| Failure::Run(e.to_string()))?;
    let g = &at.gyro;
    let temperature = if at.temperature_c.is_nan() {
        String::new()
    } else {
        format!(" at {} deg C", at.temperature_c)
    };
    eprintln!(
        "gyrocal serve: listening on etherbone://{here} ({} engine, {}; {name}{temperature}: f1 {} Hz, f2 {} Hz, Q {} / {}); Ctrl-C ends it",
        engine.name(),
        args.pace.map_or("free-running".into(), |n| format!(
            "paced {n} clocks per request"
        )),
        g.f1_hz,
        g.f2_hz,
        g.q1,
        g.q2
    );
    server
        .run()
        .map_err(|e| Failure::Run(format!("etherbone://{here}: {e}")))
}

/// The engine asked for: model, or verilator when built in.
fn engine(name: &str) -> Result<EngineKind, Failure> {
    match EngineKind::parse(name) {
        Ok(EngineKind::Rtl) | Err(_) => Err(Failure::Input(format!(
            "--engine {name:?}: allowed model, verilator"
        ))),
        Ok(EngineKind::Verilator) if !cfg!(feature = "verilator") => Err(Failure::Input(format!(
            "--engine verilator: {}",
            gyrocal_sim::error::EngineError::NotBuilt
        ))),
        Ok(kind) => Ok(kind),
    }
}

/// A powered-up board of the file's device on the engine.
fn board(
    file: &DeviceFile,
    at: &DeviceAt,
    engine: EngineKind,
) -> Result<Box<dyn Board + Send>, Failure> {
    match engine {
        #[cfg(feature = "verilator")]
        EngineKind::Verilator => {
            use gyrocal_sim::verilator::VerilatorEngine;
            Ok(Box::new(
                file.board::<VerilatorEngine>(at).map_err(Failure::run)?,
            ))
        }
        _ => Ok(Box::new(
            file.board::<ModelEngine>(at).map_err(Failure::run)?,
        )),
    }
}
