//! A board seen through a watcher: every call goes to the board unchanged,
//! and the watcher counts the z samples the host read and those that went
//! by unread between two reads (SAMPLE_COUNT tells), and shows progress on
//! stderr: a spinner with the board time on a terminal, else one line when
//! the cycle leaves identification for the staircase (the first write of
//! SELECT = 1).

use gyrocal_host::board::{Board, ZSample};
use gyrocal_regs::map::{BusError, RegisterAccess, SELECT};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Samples the host read and missed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SampleCounts {
    /// z samples read by `next_sample`.
    pub read: u64,
    /// Samples that went by unread between a sample and the next one read.
    pub missed: u64,
}

/// The watcher around a board.
pub struct Watched<'a> {
    board: &'a mut dyn Board,
    counts: SampleCounts,
    /// Seconds of board time per z sample (R / f_clk).
    sample_s: f64,
    first: Option<u32>,
    bar: Option<ProgressBar>,
    calibrating: bool,
    start: Instant,
}

impl<'a> Watched<'a> {
    /// Watch `board`, whose z samples come every `sample_s` seconds.
    pub fn new(board: &'a mut dyn Board, sample_s: f64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new_spinner();
            bar.set_style(
                ProgressStyle::with_template("{spinner} {elapsed} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.enable_steady_tick(Duration::from_millis(200));
            bar.set_message("identifying");
            bar
        });
        Self {
            board,
            counts: SampleCounts::default(),
            sample_s,
            first: None,
            bar,
            calibrating: false,
            start: Instant::now(),
        }
    }

    /// What was read and missed so far; clears the spinner.
    pub fn finish(self) -> SampleCounts {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        self.counts
    }

    fn board_s(&self, count: u32) -> f64 {
        self.first
            .map_or(0.0, |f| f64::from(count.wrapping_sub(f)) * self.sample_s)
    }
}

impl RegisterAccess for Watched<'_> {
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        if offset == SELECT.offset && word & 1 == 1 && !self.calibrating {
            self.calibrating = true;
            eprintln!(
                "identification done after {:.1} s wall; calibration staircase",
                self.start.elapsed().as_secs_f64()
            );
        }
        self.board.write_register(offset, word)
    }

    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        self.board.read_register(offset)
    }

    fn read_registers(&mut self, offsets: &[u32]) -> Result<Vec<u32>, BusError> {
        self.board.read_registers(offsets)
    }
}

impl Board for Watched<'_> {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        self.board.wait_clocks(clocks)
    }

    fn read_z(&mut self) -> Result<ZSample, BusError> {
        self.board.read_z()
    }

    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
        let s = self.board.next_sample(after)?;
        self.counts.read += 1;
        self.counts.missed += u64::from(s.count.wrapping_sub(after).saturating_sub(1));
        self.first.get_or_insert(s.count);
        if let Some(bar) = &self.bar
            && self.counts.read.is_multiple_of(256)
        {
            let phase = if self.calibrating {
                "staircase"
            } else {
                "identifying"
            };
            bar.set_message(format!(
                "{phase}: board time {:.2} s, {} samples read, {} missed",
                self.board_s(s.count),
                self.counts.read,
                self.counts.missed
            ));
        }
        Ok(s)
    }
}
