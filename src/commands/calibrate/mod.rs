//! `gyrocal calibrate [--board URL] --config FILE [--json] [--temperature C]`:
//! the host's self-calibration cycle (`gyrocal_host::selfcal`) against any
//! board.
//!
//! - `--board URL`: a board reached through its registers alone
//!   (`gyrocal_host::transport`: `etherbone://HOST:PORT[?base=0xADDR]`,
//!   `uio:///dev/uioN`, `mem:///dev/mem?base=0xADDR`), time measured by
//!   SAMPLE_COUNT. Without it: the file's device on the in-process
//!   simulated board (model engine, powered up), at `--temperature` when
//!   the file has `[drift]`, turning at `--rate` deg/s during the cycle
//!   (default 0: at rest; the cycle reads a steady rate and predicts at
//!   it); the truth is then given too: the device, the
//!   rate table's scale factor at the cycle's settings with its own
//!   uncertainty, and the self-calibration's error against it with the
//!   two sigmas in quadrature (`selfcal_error_uncertainty`, as in
//!   `gyrocal field`).
//! - The file's `[gyro]` is the datasheet the host starts from, `[drive]`
//!   and `[experiment]` its settings (`serve::device::DeviceFile::knowns`).
//! - Output: a table, or with `--json` one object on stdout: `identified`
//!   (f1_hz, f2_hz, q1, q2, loop_phase_deg, group_delay_s, and
//!   cycle_rate_dps, the rate the device turned at during the cycle, each
//!   with an `_uncertainty` twin, 1 sigma), `sf_cal_per_dps`, `ratio`,
//!   `sf_selfcal_per_dps` and `sf_selfcal_uncertainty` (relative 1 sigma,
//!   as in `gyrocal field`), one per output, `clocks`, `wall_s`, `samples`
//!   (read and missed over the run), `warnings` (what the sigma leaves
//!   out, one line each, also on stderr: a drive-gain ratio nothing
//!   measured nor bounds, a carrier on a slow fold, a datasheet f, split
//!   or Q beyond a part's spread, a device that turned during the cycle
//!   (`SelfCal::warnings`); over the wire, a config that gives no
//!   `[drive] clock_tolerance_ppm` for the board's oscillator; in process,
//!   self-cal errors beyond 3 of their sigmas against the truth), `failed` (null)
//!   and `truth` (null over the wire). Progress goes to stderr.
//! - A cycle that stops after identification (a board that stops
//!   answering mid-staircase, a stage that fails) keeps what it
//!   identified: that is printed (JSON: `board`, `identified`, `clocks`,
//!   `wall_s`, `samples`, `warnings` and `failed`, the stage and its
//!   error), then the error on stderr, with exit status 1. One that stops
//!   before prints only the error.

pub mod output;
pub mod watch;

use super::experiment::read_config;
use crate::Failure;
use gyrocal_host::identify::{self, Identified};
use gyrocal_host::selfcal::{self, SelfCal};
use gyrocal_host::{Board, Knowns, transport};
use gyrocal_sim::drift::DeviceAt;
use gyrocal_sim::field::board::SimBoard;
use gyrocal_sim::field::scenario::{self, RateTable};
use gyrocal_sim::gyro::MAX_COUPLING_DPS;
use gyrocal_sim::serve::device::{self, DeviceFile};
use std::path::PathBuf;
use std::time::Instant;
use watch::{SampleCounts, Watched};

/// Options of `gyrocal calibrate`.
#[derive(clap::Args)]
pub struct Args {
    /// The board: etherbone://HOST:PORT[?base=0xADDR], uio:///dev/uioN[?base=0xOFFSET]
    /// or mem:///dev/mem?base=0xADDR; without it, the file's device simulated in process.
    #[arg(long)]
    pub board: Option<String>,
    /// `[gyro]` (the datasheet), `[drive]` and `[experiment]` (the host's
    /// settings): a `gyrocal run` or `gyrocal field` file.
    #[arg(long)]
    pub config: PathBuf,
    /// Print one JSON object to stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// In process, with `[drift]`: the device at this temperature (deg C;
    /// default the first step).
    #[arg(long, allow_negative_numbers = true)]
    pub temperature: Option<f64>,
    /// In process: the board turns at this rate (deg/s) during the cycle,
    /// as a device not held still would (default 0, at rest).
    #[arg(long, allow_negative_numbers = true)]
    pub rate: Option<f64>,
}

/// What no board tells: the simulated device and its rate table.
pub struct Truth {
    /// The device and front end on the board.
    pub device: DeviceAt,
    /// The rate table at the cycle's carrier and phase: its slopes (z LSB
    /// per deg/s), their own relative 1-sigma and the windows it ran.
    pub table: RateTable,
    /// Clocks the rate table simulated.
    pub clocks: u64,
}

/// One run's result.
pub struct Outcome {
    /// The board's URL, or "in-process".
    pub board: String,
    /// The cycle's result.
    pub cal: SelfCal,
    /// What the cycle's sigma leaves out, one line each
    /// (`SelfCal::warnings`), and in process the errors it does not cover
    /// (`output::uncovered`).
    pub warnings: Vec<String>,
    /// z samples read and missed.
    pub samples: SampleCounts,
    /// Wall time of the cycle (s).
    pub wall_s: f64,
    /// The truth, in process.
    pub truth: Option<Truth>,
}

/// A cycle that stopped: its error, and what identification found when
/// it finished before the stop.
pub struct Halted {
    /// The board's URL, or "in-process".
    pub board: String,
    /// The identified device, when the cycle stopped after identification.
    pub identified: Option<Box<Identified>>,
    /// Why it stopped, one line.
    pub error: String,
    /// z samples read and missed.
    pub samples: SampleCounts,
    /// Wall time until the stop (s).
    pub wall_s: f64,
    /// What the host found before the cycle (the board's profile).
    pub warnings: Vec<String>,
}

/// Calibrate and print.
pub fn run(args: &Args) -> Result<(), Failure> {
    let (name, text) = read_config(&args.config)?;
    let file = device::parse(&name, &text).map_err(Failure::input)?;
    let knowns = file.knowns().map_err(Failure::input)?;
    let outcome = match &args.board {
        Some(url) => over_the_wire(url, &knowns, args)?,
        None => in_process(&file, &knowns, args)?,
    };
    let outcome = match outcome {
        Ok(outcome) => outcome,
        Err(halted) => return stopped(args, &knowns, halted),
    };
    eprintln!(
        "cycle done in {:.1} s wall, {:.3e} clocks; {} z samples read, {} went by unread",
        outcome.wall_s, outcome.cal.clocks as f64, outcome.samples.read, outcome.samples.missed
    );
    // Printed as progress too, as `gyrocal field` prints its own.
    for w in &outcome.warnings {
        eprintln!("{w}");
    }
    if args.json {
        println!("{}", output::json(&outcome));
    } else {
        print!("{}", output::table(&outcome));
    }
    Ok(())
}

/// A cycle that stopped: what identification found, when it finished,
/// printed as the run's result (JSON or table), then its error (exit
/// status 1). Before identification finished there is nothing to print
/// but the error.
fn stopped(args: &Args, knowns: &Knowns, halted: Halted) -> Result<(), Failure> {
    if halted.identified.is_none() {
        for w in &halted.warnings {
            eprintln!("{w}");
        }
    }
    if let Some(id) = halted.identified.as_deref() {
        eprintln!(
            "the cycle stopped after identification ({:.1} s wall); what it identified follows",
            halted.wall_s
        );
        let mut warnings = halted.warnings.clone();
        warnings.extend(id.datasheet_departures(&knowns.nominal));
        for w in &warnings {
            eprintln!("{w}");
        }
        if args.json {
            println!("{}", output::halted_json(&halted, id, &warnings));
        } else {
            print!("{}", output::halted_table(&halted, id, &warnings));
        }
    }
    Err(Failure::Run(halted.error))
}

/// The cycle on a watched board (identification, then the rest from what
/// it found, so a stop after it keeps it); its wall time.
fn cycle(
    board: &mut dyn Board,
    board_name: &str,
    knowns: &Knowns,
) -> Result<(SelfCal, SampleCounts, f64), Halted> {
    let sample_s = f64::from(knowns.filter.decimation) / knowns.clock_hz;
    let start = Instant::now();
    let mut watched = Watched::new(board, sample_s);
    let cal = match identify::identify(&mut watched, knowns, &knowns.nominal) {
        Ok(id) => selfcal::self_calibrate_from(&mut watched, knowns, id.clone())
            .map_err(|e| (Some(Box::new(id)), e)),
        Err(e) => Err((None, e)),
    };
    let samples = watched.finish();
    let wall_s = start.elapsed().as_secs_f64();
    cal.map(|cal| (cal, samples, wall_s))
        .map_err(|(identified, e)| Halted {
            board: board_name.into(),
            identified,
            error: e.to_string(),
            samples,
            wall_s,
            warnings: vec![],
        })
}

fn over_the_wire(
    url: &str,
    knowns: &Knowns,
    args: &Args,
) -> Result<Result<Outcome, Halted>, Failure> {
    if args.temperature.is_some() {
        return Err(Failure::Input(
            "--temperature: applies to the in-process board only (a served board's device is set by gyrocal serve --temperature)"
                .into(),
        ));
    }
    if args.rate.is_some() {
        return Err(Failure::Input(
            "--rate: applies to the in-process board only (a real board turns as it is turned)"
                .into(),
        ));
    }
    transport::parse(url).map_err(|e| Failure::Input(format!("--board: {e}")))?;
    let mut board =
        transport::open(url).map_err(|e| Failure::Run(format!("--board {url}: {e}")))?;
    let mut knowns = knowns.clone();
    let profile = knowns
        .take_board_profile(board.as_mut())
        .map_err(|e| Failure::Run(format!("--board {url}: {e}")))?;
    let knowns = &knowns;
    eprintln!("calibrating the board at {url}");
    let (cal, samples, wall_s) = match cycle(board.as_mut(), url, knowns) {
        Ok(done) => done,
        Err(mut halted) => {
            halted.warnings.extend(profile);
            return Ok(Err(halted));
        }
    };
    let mut warnings = cal.warnings(knowns);
    warnings.extend(profile);
    warnings.extend(knowns.clock_tolerance_missing());
    Ok(Ok(Outcome {
        board: url.into(),
        warnings,
        cal,
        samples,
        wall_s,
        truth: None,
    }))
}

fn in_process(
    file: &DeviceFile,
    knowns: &Knowns,
    args: &Args,
) -> Result<Result<Outcome, Halted>, Failure> {
    let at = file
        .at(args.temperature)
        .map_err(|e| Failure::Input(format!("--{e}")))?;
    let mut board: SimBoard = file.board(&at).map_err(Failure::run)?;
    let rate = args.rate.unwrap_or(0.0);
    if !rate.is_finite() || rate.abs() > MAX_COUPLING_DPS {
        return Err(Failure::Input(format!(
            "--rate {rate}: allowed -{MAX_COUPLING_DPS}..={MAX_COUPLING_DPS} deg/s"
        )));
    }
    board.set_rate(rate.to_radians());
    eprintln!("calibrating the in-process simulated board");
    let (cal, samples, wall_s) = match cycle(&mut board, IN_PROCESS, knowns) {
        Ok(done) => done,
        Err(halted) => return Ok(Err(halted)),
    };
    eprintln!("rate table at the calibrated carrier and phase (the truth)");
    let fe = file.front_end().map_err(Failure::run)?;
    let judged = Some(cal.sf_selfcal_uncertainty.total);
    let (table, clocks) = scenario::rate_table(&file.exp, &fe, &at, knowns, &cal.operating, judged)
        .map_err(Failure::run)?;
    let truth = Truth {
        device: at,
        table,
        clocks,
    };
    let mut warnings = cal.warnings(knowns);
    warnings.extend(output::uncovered(&cal, &truth));
    Ok(Ok(Outcome {
        board: IN_PROCESS.into(),
        warnings,
        cal,
        samples,
        wall_s,
        truth: Some(truth),
    }))
}

/// The board name of the in-process simulated board.
const IN_PROCESS: &str = "in-process";
