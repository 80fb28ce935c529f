//! Window means when the wire misses samples (issue 21): a board whose
//! host sees only about one z sample in twenty (a free-running wire), the
//! missing ones at random, while z carries a calibration ripple (a mean, a
//! ripple at the window's period and its second harmonic).
//!
//! `sampling::part_means` must give each period's mean from the samples
//! it has (a fit of a constant plus harmonics, `sampling` header): within
//! 1e-6 of the ripple's amplitude for this noise-free signal, where the
//! interpolation that is right with every sample is off by 100 times that. With
//! fewer samples than the fit needs, a one-line error, never a figure.

use gyrocal_host::average::window_mean;
use gyrocal_host::board::{Board, ZSample};
use gyrocal_host::error::Error;
use gyrocal_host::sampling::{Signal, part_means};
use gyrocal_regs::map::{BusError, RegisterAccess};
use std::f64::consts::TAU;

const R: u32 = 100;
/// Ripple period (clocks): 2,000 samples per period when none is missed.
const PERIOD: f64 = 200_000.5;
const MEAN: [f64; 2] = [1234.5, -987.25];
const RIPPLE: f64 = 500.0;
/// What the fit must reach on this noise-free signal: rounding only (the
/// fit is exact for a signal of its form).
const TOLERANCE: f64 = 1e-6 * RIPPLE;

/// Counts advance in samples; the host's next sample skips `skip(n)` of
/// them (a deterministic pseudo-random 0..2*mean_skip).
struct Sparse {
    count: u32,
    state: u64,
    mean_skip: u64,
}

fn z_at(count: u32) -> [f64; 2] {
    let phase = TAU * f64::from(count) * f64::from(R) / PERIOD;
    std::array::from_fn(|k| {
        MEAN[k] + RIPPLE * (phase + k as f64).cos() + 0.3 * RIPPLE * (2.0 * phase + 0.7).sin()
    })
}

impl RegisterAccess for Sparse {
    fn write_register(&mut self, _: u32, _: u32) -> Result<(), BusError> {
        Ok(())
    }
    fn read_register(&mut self, _: u32) -> Result<u32, BusError> {
        Ok(0)
    }
}

impl Board for Sparse {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        self.count += clocks.div_ceil(u64::from(R)) as u32;
        Ok(())
    }
    fn read_z(&mut self) -> Result<ZSample, BusError> {
        Ok(ZSample {
            count: self.count,
            z: z_at(self.count),
        })
    }
    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
        // xorshift: the samples that went by while the host read.
        self.state ^= self.state << 13;
        self.state ^= self.state >> 7;
        self.state ^= self.state << 17;
        let skipped = self.state % (2 * self.mean_skip + 1);
        self.count = self.count.max(after) + 1 + skipped as u32;
        self.read_z()
    }
}

#[test]
fn period_means_are_fitted_across_the_gaps_of_a_slow_wire() {
    let mut board = Sparse {
        count: 5,
        state: 0x9e37_79b9_7f4a_7c15,
        mean_skip: 19,
    };
    let periods = 4;
    let means = part_means(
        &mut board,
        R,
        f64::from(R),
        PERIOD * periods as f64,
        periods,
        Signal::Periodic,
    )
    .unwrap();
    for (p, m) in means.iter().enumerate() {
        for k in 0..2 {
            assert!(
                (m[k] - MEAN[k]).abs() < TOLERANCE,
                "period {p} output {}: {} against {}",
                k + 1,
                m[k],
                MEAN[k]
            );
        }
    }
}

/// The negative control: the same sparse samples interpolated (what
/// `part_means` does when no sample is missing) miss the mean by more than
/// 100 times the fit's tolerance (1.2e-4 of the ripple, at about 100
/// samples per period; fewer samples miss by more), so the test above
/// could fail.
#[test]
fn interpolating_across_the_gaps_would_miss_the_mean() {
    let mut board = Sparse {
        count: 5,
        state: 0x9e37_79b9_7f4a_7c15,
        mean_skip: 19,
    };
    let first = board.next_sample(5).unwrap();
    let (mut t, mut z) = (vec![0.0], vec![first.z[0]]);
    let mut last = first.count;
    while *t.last().unwrap() < 2.0 * PERIOD {
        let s = board.next_sample(last).unwrap();
        last = s.count;
        t.push(f64::from(s.count - first.count) * f64::from(R));
        z.push(s.z[0]);
    }
    let m = window_mean(&t, &z, 0.0, PERIOD);
    assert!((m - MEAN[0]).abs() > 100.0 * TOLERANCE, "{m}");
}

#[test]
fn too_few_samples_is_an_error_not_a_figure() {
    let mut board = Sparse {
        count: 5,
        state: 0x9e37_79b9_7f4a_7c15,
        mean_skip: 400,
    };
    let err = part_means(&mut board, R, f64::from(R), PERIOD, 1, Signal::Periodic).unwrap_err();
    assert!(matches!(err, Error::Measurement { .. }), "{err}");
    let line = err.to_string();
    assert!(line.contains("fewer than the 18 its fit needs"), "{line}");
    assert_eq!(line.lines().count(), 1);
}
