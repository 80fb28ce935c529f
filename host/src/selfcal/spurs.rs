//! The table core's carrier spurs in the rate's passband: which of the
//! carrier words' harmonics the sampling folds next to the carrier at an
//! operating point (`crate::carrier_lines`), and the rate ripple each can
//! put on an output.
//!
//! Each line ripples the demodulated output at Omega. Against a reference
//! R and an ADC signal H(f_c) D, whose product's full magnitude is M = |H
//! D R| / 2 (in-phase and quadrature: the line turns through both), a
//! reference line rho R ripples z by rho M and a drive line rho D by rho M
//! |H(f_c + Omega) / H(f_c)|, both through the output filter's gain at
//! Omega. Drive and reference read the table a `REF_PHASE` apart, so
//! their lines' phases are unrelated: the sum of the two amplitudes is
//! the bound. M and the readout scale factor come from the exact theory
//! at the identified device, so the ripple is in deg/s.

use super::Operating;
use super::predict::devices;
pub use crate::carrier_lines::{Depth, FULL, SEARCH, SPUR_BAND_CORNERS};
use crate::carrier_lines::{candidates, harmonics, output_gain, record_gain, relative};
use crate::error::Error;
use crate::identify::Identified;
use crate::knowns::Knowns;
use crate::theory::{self, Device};
use gyrocal_regs::datapath::{CarrierProfile, PEAK, q15_product};
use serde::Serialize;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};

/// One line next to the carrier.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpurLine {
    /// Distance from the carrier (Hz, both sides folded together).
    pub offset_hz: f64,
    /// Bound on the ripple's amplitude per output at the filter's output
    /// (deg/s, peak).
    pub amplitude_dps: [f64; 2],
}

/// One line next to the carrier, its amplitude per output a fraction rho
/// of the output's full magnitude M (module header) as a mean over a
/// record leaves it ([`relative_lines_over_records`]): what the coupling's
/// uncertainty takes (`crate::coupling`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RelativeLine {
    /// Distance from the carrier (Hz, both sides folded together).
    pub offset_hz: f64,
    /// rho per output (peak), times the record's |sinc(pi offset
    /// record_s)|.
    pub rho: [f64; 2],
}

/// Points a mode bandwidth f / Q at which the drive lines' response is
/// taken from the exact theory and interpolated between (a field step on
/// a slow clock has some 1e5 lines). A Lorentzian's magnitude at its peak
/// bends as 1 - x^2 / 2, x the detuning in half-bandwidths: points 2 / 32
/// of a half-bandwidth apart interpolate within (2 / 32)^2 / 8 = 4.9e-4
/// (this module's test measures it).
const RESPONSE_GRID: f64 = 32.0;

/// Lines the report names, largest first.
pub const NAMED_LINES: usize = 8;

/// The table core's spur lines in the passband at an operating point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spurs {
    /// The lines, by offset (some thousands; not serialized).
    #[serde(skip)]
    pub lines: Vec<SpurLine>,
    /// The `NAMED_LINES` largest (by the larger output's amplitude).
    pub largest: Vec<SpurLine>,
    /// Bound on the rate's RMS ripple per output from all of them (deg/s).
    pub rms_dps: [f64; 2],
}

impl Spurs {
    /// The RMS of the lines after averaging over records of `record_s`
    /// seconds, each line's amplitude times |sinc(pi offset record_s)|.
    pub fn rms_over_records_dps(&self, record_s: f64) -> [f64; 2] {
        rms_over_records(&self.lines, record_s)
    }
}

impl std::fmt::Display for Spurs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "carrier table spurs in the passband: rate ripple at most {:.4} / {:.4} deg/s RMS",
            self.rms_dps[0], self.rms_dps[1]
        )?;
        if let Some(l) = self.largest.first() {
            write!(f, ", largest line {:.1} Hz from the carrier", l.offset_hz)?;
        }
        Ok(())
    }
}

/// The RMS of `lines` after averaging over records of `record_s` seconds,
/// each line's amplitude times |sinc(pi offset record_s)|.
fn rms_over_records(lines: &[SpurLine], record_s: f64) -> [f64; 2] {
    rms(lines.iter().map(|l| {
        let g = record_gain(l.offset_hz, record_s);
        l.amplitude_dps.map(|a| a * g)
    }))
}

/// Root mean square of lines of these amplitudes at distinct offsets.
fn rms(amplitudes: impl Iterator<Item = [f64; 2]>) -> [f64; 2] {
    let s = amplitudes.fold([0.0; 2], |s, a| [s[0] + a[0] * a[0], s[1] + a[1] * a[1]]);
    s.map(|v| (v / 2.0).sqrt())
}

/// The spur lines at `op` on the table core (`None` on the fine core,
/// whose rounding error is fed back away from the carrier).
pub fn spurs(knowns: &Knowns, id: &Identified, op: &Operating) -> Result<Option<Spurs>, Error> {
    let Some(lines) = spur_lines(knowns, id, op, FULL)? else {
        return Ok(None);
    };
    let rms_dps = rms(lines.iter().map(|l| l.amplitude_dps));
    // The largest by index: the lines themselves stay in offset order.
    let by_peak = |a: &usize, b: &usize| peak(&lines[*b]).total_cmp(&peak(&lines[*a]));
    let mut order: Vec<usize> = (0..lines.len()).collect();
    if order.len() > NAMED_LINES {
        order.select_nth_unstable_by(NAMED_LINES, by_peak);
        order.truncate(NAMED_LINES);
    }
    order.sort_by(by_peak);
    let largest = order.into_iter().map(|i| lines[i]).collect();
    Ok(Some(Spurs {
        lines,
        largest,
        rms_dps,
    }))
}

/// What a line's amplitude is given in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Unit {
    /// The rate ripple at the filter's output (deg/s, peak).
    Dps,
    /// The ripple at the filter's output as a fraction of the output's
    /// full magnitude M (module header).
    Relative,
}

/// The lines of [`spurs`] to `depth`, by offset.
fn spur_lines(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    depth: Depth,
) -> Result<Option<Vec<SpurLine>>, Error> {
    lines_in(
        knowns,
        id,
        op,
        depth,
        Unit::Dps,
        |offset_hz, amplitude_dps| SpurLine {
            offset_hz,
            amplitude_dps,
        },
    )
}

/// The lines at `op`, as a mean over a record of `record_s` seconds
/// leaves them (each amplitude times |sinc(pi offset record_s)|), in
/// fractions of their outputs' full magnitudes. `None` on the fine core.
pub(crate) fn relative_lines_over_records(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    record_s: f64,
) -> Result<Option<Vec<RelativeLine>>, Error> {
    lines_in(knowns, id, op, FULL, Unit::Relative, |offset_hz, rho| {
        RelativeLine {
            offset_hz,
            rho: rho.map(|a| a * record_gain(offset_hz, record_s)),
        }
    })
}

/// The lines of [`spurs`] to `depth`, by offset, each made by `line` from
/// its offset (Hz) and its amplitudes per output in `unit`.
fn lines_in<L>(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    depth: Depth,
    unit: Unit,
    line: impl Fn(f64, [f64; 2]) -> L,
) -> Result<Option<Vec<L>>, Error> {
    if knowns.carrier_profile != CarrierProfile::Table {
        return Ok(None);
    }
    let (regs, _) = knowns.registers(op.carrier_hz, None, op.amplitude, op.ref_lag_deg)?;
    let step = regs.carrier_step;
    let band = SPUR_BAND_CORNERS * knowns.filter.butterworth_hz;
    let per_step = knowns.clock_hz / 2f64.powi(32);
    let envelopes = [regs.amp.0, regs.amp.1].map(|a| i32::from(q15_product(a, PEAK as i16)));
    let spectra = envelopes.map(harmonics);
    let [read, _] = devices(knowns, &id.gyro(&knowns.nominal), op)?;
    let m_full = full(&read);
    let sf_dps = theory::sf_read_per_rad_s(&read).map(|s| (s * PI / 180.0).abs());
    // The drive lines' response |H(f_c + Omega)| in the full magnitude,
    // on a grid of RESPONSE_GRID points a mode bandwidth, interpolated.
    let spacing = (read.f1_hz / read.q1).min(read.f2_hz / read.q2) / RESPONSE_GRID;
    let mut grid: HashMap<i64, [f64; 2]> = HashMap::new();
    let mut at_grid = |i: i64| -> [f64; 2] {
        *grid.entry(i).or_insert_with(|| {
            full(&Device {
                carrier_hz: op.carrier_hz + i as f64 * spacing,
                ..read.clone()
            })
        })
    };
    let mut found: Vec<(u32, [f64; 2])> = candidates(step, (band / per_step) as u32, depth)
        .into_iter()
        .map(|(m, side)| {
            let omega = f64::from(side) * per_step;
            let x = omega / spacing;
            let i = x.floor() as i64;
            let (lo, hi, w) = (at_grid(i), at_grid(i + 1), x - x.floor());
            let m_moved: [f64; 2] = std::array::from_fn(|k| lo[k] + w * (hi[k] - lo[k]));
            let g = output_gain(&knowns.filter, omega.abs());
            let amp = std::array::from_fn(|k| {
                let rho = relative(&spectra[k], m);
                match unit {
                    Unit::Dps => m_full[k] * rho * (1.0 + m_moved[k] / m_full[k]) * g / sf_dps[k],
                    Unit::Relative => rho * (1.0 + m_moved[k] / m_full[k]) * g,
                }
            });
            (side.unsigned_abs(), amp)
        })
        .collect();
    // Lines by |offset| in NCO steps: the two sides of a fold and the
    // drive's and reference's lines at one offset add.
    found.sort_unstable_by_key(|f| f.0);
    let mut lines: Vec<(f64, [f64; 2])> = Vec::new();
    for (s, amp) in found {
        let offset_hz = f64::from(s) * per_step;
        match lines.last_mut() {
            Some((at, sum)) if *at == offset_hz => {
                sum[0] += amp[0];
                sum[1] += amp[1];
            }
            _ => lines.push((offset_hz, amp)),
        }
    }
    Ok(Some(lines.into_iter().map(|(o, a)| line(o, a)).collect()))
}

/// The bound of [`spurs`] alone, its RMS per output (deg/s), over the
/// images `depth` counts.
pub fn spur_rms(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    depth: Depth,
) -> Result<Option<[f64; 2]>, Error> {
    Ok(spur_lines(knowns, id, op, depth)?.map(|lines| rms(lines.iter().map(|l| l.amplitude_dps))))
}

/// A line's larger amplitude of the two outputs.
fn peak(l: &SpurLine) -> f64 {
    l.amplitude_dps[0].max(l.amplitude_dps[1])
}

/// The demodulated outputs' full magnitude at rest (in-phase and
/// quadrature), per output, from the exact theory.
fn full(dev: &Device) -> [f64; 2] {
    let (i, q) = (
        theory::readout_z_lagged(dev, 0.0, 0.0),
        theory::readout_z_lagged(dev, 0.0, FRAC_PI_2),
    );
    [i[0].hypot(q[0]), i[1].hypot(q[1])]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `RESPONSE_GRID`'s premise: between grid points 1 / 32 of a mode
    /// bandwidth apart, the full magnitude interpolates within 5e-4, on
    /// the paper device driven at mode 1 (output 1 on its resonance,
    /// output 2 250 Hz off it), over two bandwidths either side.
    #[test]
    fn the_response_interpolates_within_5e_4_between_grid_points() {
        let dev = Device {
            f1_hz: 9.64e6,
            f2_hz: 9.640_25e6,
            q1: 55000.0,
            q2: 55000.0,
            angular_gain: 0.6,
            quadrature_dps: 0.0,
            damping_coupling_dps: 0.0,
            carrier_hz: 9.64e6,
            f1_force: 1.0,
            f2_force: 1.0,
        };
        let spacing = dev.f1_hz / dev.q1 / RESPONSE_GRID;
        let at = |x: f64| {
            full(&Device {
                carrier_hz: dev.carrier_hz + x * spacing,
                ..dev.clone()
            })
        };
        let mut worst = 0.0f64;
        for i in -64..64 {
            let (lo, hi) = (at(f64::from(i)), at(f64::from(i + 1)));
            for w in [0.25, 0.5, 0.75] {
                let exact = at(f64::from(i) + w);
                for k in 0..2 {
                    let lerp = lo[k] + w * (hi[k] - lo[k]);
                    worst = worst.max((lerp / exact[k] - 1.0).abs());
                }
            }
        }
        eprintln!("worst interpolation error {worst:.2e}");
        assert!(worst < 5e-4, "{worst}");
    }
}
