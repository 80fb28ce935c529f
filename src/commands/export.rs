//! `gyrocal export`: write verilog-out/ from the rust-hdl design.

use crate::Failure;
use gyrocal_hdl::export;
use std::path::PathBuf;

/// Options of `gyrocal export`.
#[derive(clap::Args)]
pub struct Args {
    /// Folder to write into.
    #[arg(long, default_value = "verilog-out")]
    pub out: PathBuf,
    /// Only compare: exit with status 1 if the folder is not up to date.
    #[arg(long)]
    pub check: bool,
}

/// Write (or check) the exported files.
pub fn run(args: &Args) -> Result<(), Failure> {
    if !args.out.is_dir() {
        return Err(Failure::Input(format!(
            "--out {}: not a folder (create it first)",
            args.out.display()
        )));
    }
    let mut stale = Vec::new();
    for (name, text) in export::files() {
        let path = args.out.join(name);
        let current = std::fs::read_to_string(&path).unwrap_or_default();
        if current == text {
            continue;
        }
        if args.check {
            stale.push(path.display().to_string());
        } else {
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(|e| {
                    Failure::Run(format!("cannot create {}: {e}", parent.display()))
                })?;
            }
            gyrocal_verify::write_atomically(&path, &text)
                .map_err(|e| Failure::Run(format!("cannot write {}: {e}", path.display())))?;
            println!("wrote {}", path.display());
        }
    }
    if !stale.is_empty() {
        return Err(Failure::Run(format!(
            "out of date: {} (run `gyrocal export`)",
            stale.join(", ")
        )));
    }
    Ok(())
}
