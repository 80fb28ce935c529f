//! The calibrated rate output: the null at rest, record means of z, and
//! the rate a user of the board reads,
//!
//! ```text
//! rate_k = (z_k - null_k) / SF_k        (deg/s; z, null in z LSB, SF in z LSB per deg/s)
//! ```

use crate::board::Board;
use crate::error::Error;
use crate::sampling::{mean, window_z};

/// The readout null: z at rest (mean over `length` clocks after one
/// sample), on a board already programmed and settled in readout. The
/// host measures it right after the cycle, with the device still.
pub fn readout_null(
    board: &mut dyn Board,
    decimation: u32,
    length: f64,
) -> Result<[f64; 2], Error> {
    window_z(board, decimation, f64::from(decimation), length)
}

/// One record of the rate output: the mean z and what the converters did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// Mean of the record's z samples (z LSB, both outputs).
    pub z: [f64; 2],
    /// Clocks on which ADC 1 and ADC 2 clipped from the end of the record
    /// before (from the start, for the first) to this record's last
    /// sample (`crate::clip`): a clipped record's z holds the converter's
    /// rail, not the rate, and so does the output for the filter's
    /// settling after it.
    pub clip_clocks: [u32; 2],
}

/// `records` records of `per_record` successive z samples each, with the
/// ADC clip counts over each (one `ADC_CLIP` read per record).
/// `before(board, i)` runs before sample i is waited for: the simulator's
/// rate table turns its device there; on a real board it does nothing.
pub fn read_records<B: Board + ?Sized>(
    board: &mut B,
    per_record: usize,
    records: usize,
    mut before: impl FnMut(&mut B, usize),
) -> Result<Vec<Record>, Error> {
    let mut last = board.read_z()?.count;
    crate::clip::restart(board)?;
    let mut out = Vec::with_capacity(records);
    let mut sample = 0;
    for _ in 0..records {
        let mut batch = Vec::with_capacity(per_record);
        for _ in 0..per_record {
            before(board, sample);
            let s = board.next_sample(last)?;
            last = s.count;
            batch.push(s);
            sample += 1;
        }
        out.push(Record {
            z: mean(&batch),
            clip_clocks: crate::clip::counts(board)?,
        });
    }
    Ok(out)
}

/// A calibrated rate series: (z - null) / SF per record and output.
pub fn calibrated(z: &[[f64; 2]], null: [f64; 2], sf_per_dps: [f64; 2]) -> Vec<[f64; 2]> {
    z.iter()
        .map(|v| std::array::from_fn(|k| (v[k] - null[k]) / sf_per_dps[k]))
        .collect()
}

/// RMS of `rate - truth` per output over the records marked in `keep`
/// (NaN when none is).
pub fn rms_error(rate: &[[f64; 2]], truth: &[f64], keep: &[bool]) -> [f64; 2] {
    std::array::from_fn(|k| {
        let (ss, n) = rate
            .iter()
            .zip(truth)
            .zip(keep)
            .filter(|(_, keep)| **keep)
            .fold((0.0, 0usize), |(ss, n), ((r, t), _)| {
                (ss + (r[k] - t).powi(2), n + 1)
            });
        (ss / n as f64).sqrt()
    })
}
