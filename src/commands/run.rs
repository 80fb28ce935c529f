//! `gyrocal run --config FILE.toml`: co-simulate a user's device.

use super::experiment::{RunOptions, execute, load_experiment, summary, write_results};
use crate::Failure;
use std::path::PathBuf;

/// Options of `gyrocal run`.
#[derive(clap::Args)]
pub struct Args {
    /// Device and experiment description (TOML; every key has a default).
    #[arg(long)]
    pub config: PathBuf,
    /// Print one JSON object (the full report) to stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Also write results.json, points.csv and the figures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub options: RunOptions,
}

/// Run the configured experiment.
pub fn run(args: &Args) -> Result<(), Failure> {
    let exp = load_experiment(&args.config)?;
    let checked = args.options.check(&exp)?;
    let report = execute(&exp, &args.options, &checked)?;
    if let Some(dir) = &args.out {
        for path in write_results(&report, dir)? {
            eprintln!("wrote {}", path.display());
        }
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&report).map_err(|e| Failure::Run(e.to_string()))?
        );
    } else {
        print!("{}", summary(&report));
    }
    Ok(())
}
