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

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// A progress bar of `total` steps on stderr, drawn with `template`;
/// hidden when `quiet` or when stderr is not a terminal (a log file gets
/// no redraws).
pub fn progress_bar(quiet: bool, total: u64, template: &str) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(template)
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar
}
