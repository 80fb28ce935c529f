//! The report of a run, checked and sorted for drawing.

use super::error::PlotError;
use gyrocal_sim::experiment::{Mode, PointResult};
use gyrocal_sim::report::Report;

use super::format::sub;

/// The report, checked and sorted for drawing.
pub(super) struct Data<'a> {
    pub(super) report: &'a Report,
    pub(super) readout: Vec<&'a PointResult>,
    /// Calibration points by increasing frequency.
    pub(super) cal: Vec<&'a PointResult>,
}

impl<'a> Data<'a> {
    pub(super) fn new(report: &'a Report) -> Result<Self, PlotError> {
        let pick = |mode: Mode| -> Vec<&PointResult> {
            report.points.iter().filter(|p| p.mode == mode).collect()
        };
        let readout = pick(Mode::Readout);
        let mut cal = pick(Mode::Calibration);
        cal.sort_by(|a, b| a.cal_hz.total_cmp(&b.cal_hz));
        for (what, points) in [("readout", &readout), ("calibration", &cal)] {
            if points.len() < 2 {
                return Err(PlotError::Data(format!(
                    "figures: the report has {} {what} points, at least 2 are needed",
                    points.len()
                )));
            }
            for p in points.iter() {
                let values = [p.rate_dps, p.z[0], p.z[1], p.z_theory[0], p.z_theory[1]];
                if values.iter().any(|v| !v.is_finite()) {
                    return Err(PlotError::Data(format!(
                        "figures: {what} point at {} deg/s has a non-finite value (z {:?}, theory {:?})",
                        p.rate_dps, p.z, p.z_theory
                    )));
                }
            }
        }
        for p in &cal {
            if p.trace.len() < 2 || p.trace.iter().flatten().any(|v| !v.is_finite()) {
                return Err(PlotError::Data(format!(
                    "figures: calibration point at {} Hz has no usable trace ({} samples; traces are not serialized, figures need the report of a run)",
                    p.cal_hz,
                    p.trace.len()
                )));
            }
        }
        let scalars = [
            report.scale_factors.sf_read_per_dps,
            report.scale_factors.sf_cal_per_dps,
            report.scale_factors.intercept_read,
            report.scale_factors.intercept_cal,
            report.theory.sf_read_per_dps,
            report.theory.sf_cal_per_dps,
        ];
        if scalars.iter().flatten().any(|v| !v.is_finite()) {
            return Err(PlotError::Data(
                "figures: the report has a non-finite scale factor or intercept".into(),
            ));
        }
        Ok(Self {
            report,
            readout,
            cal,
        })
    }

    /// "output 2 (f₂ − f_c = +250.0 Hz, detuned: the paper's output)".
    pub(super) fn output_name(&self, k: usize) -> String {
        let d = &self.report.device;
        let offset = d.gyro.f_hz(k) - d.carrier_hz;
        let tag = if self.report.detuned_output == Some(k) {
            ", detuned: the paper's output"
        } else {
            ""
        };
        let offset = if offset.abs() < 0.05 {
            "≈ 0 Hz".to_string()
        } else {
            format!("= {:+.1} Hz", offset).replace('-', "−")
        };
        format!("output {} (f{} − f_c {offset}{tag})", k + 1, sub(k + 1))
    }
}
