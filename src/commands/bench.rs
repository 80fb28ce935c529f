//! `gyrocal bench`: clocks per second of every engine, side by side in one
//! process, and the full reproduce run. A benchmark, not a test: the
//! machine is shared, so it reports medians of repetitions and ratios.

use crate::Failure;
use gyrocal_sim::bench;
use gyrocal_sim::engine::EngineKind;

/// Options of `gyrocal bench`.
#[derive(clap::Args)]
pub struct Args {
    /// Engines to measure (comma-separated: model, verilator, rtl).
    #[arg(long, default_value = "model,verilator,rtl")]
    pub engines: String,
    /// Repetitions per engine and setting (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub repetitions: usize,
    /// Scale the clocks per repetition (1 = model 2e7, verilator 1e6, rtl 1e4).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Skip timing the full reproduce experiment.
    #[arg(long)]
    pub no_reproduce: bool,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Run the benchmark.
pub fn run(args: &Args) -> Result<(), Failure> {
    let engines: Vec<EngineKind> = args
        .engines
        .split(',')
        .map(|e| EngineKind::parse(e.trim()).map_err(|m| Failure::Input(format!("--engines: {m}"))))
        .collect::<Result<_, _>>()?;
    if !(1..=100).contains(&args.repetitions) {
        return Err(Failure::Input(format!(
            "--repetitions {}: allowed 1..=100",
            args.repetitions
        )));
    }
    if !(args.scale.is_finite() && args.scale > 0.0 && args.scale <= 100.0) {
        return Err(Failure::Input(format!(
            "--scale {}: allowed 0 < scale <= 100",
            args.scale
        )));
    }
    let report = bench::run(
        &engines,
        args.repetitions,
        args.scale,
        !args.no_reproduce,
        &|m| eprintln!("{m}"),
    )
    .map_err(Failure::run)?;
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&report).map_err(|e| Failure::Run(e.to_string()))?
        );
        return Ok(());
    }
    println!("model engine compiled for {}", report.model_isa);
    println!(
        "{:<10} {:<16} {:>16} {:>24}",
        "engine", "gyro in loop", "median clocks/s", "min .. max"
    );
    for m in &report.measurements {
        let lo = m.samples.iter().cloned().fold(f64::MAX, f64::min);
        let hi = m.samples.iter().cloned().fold(0.0, f64::max);
        println!(
            "{:<10} {:<16} {:>16.4e} {:>11.3e} .. {:.3e}",
            m.engine,
            match (m.with_gyro, m.lanes) {
                (false, _) => "no".into(),
                (true, 1) => "yes".into(),
                (true, n) => format!("yes, {n} lanes"),
            },
            m.median_clocks_per_s,
            lo,
            hi
        );
    }
    if let Some(r) = report.model_over_verilator_with_gyro {
        println!("model / verilator, gyroscope in the loop: {r:.1}x");
    }
    if let Some(r) = &report.reproduce {
        println!(
            "reproduce (paper's device, {} clocks, {} threads): {:.2} s wall, peak memory {}",
            r.clocks,
            r.threads,
            r.wall_s,
            r.peak_memory_mb
                .map_or("unknown".into(), |m| format!("{m:.0} MB"))
        );
    }
    Ok(())
}
