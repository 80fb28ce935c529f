//! Fig. 5b: calibration scale factor. Window means against the virtual
//! rate 360 f_cal (f_cal on a top axis), fitted lines, theory, one panel
//! per output (`line_panel`).

use super::error::PlotError;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::data::Data;
use super::format::fmt_num;
use super::line_panel::{LinePanel, draw_line_panel};
use super::style::header;

pub(super) fn draw_calibration<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), PlotError> {
    let r = data.report;
    let freqs: Vec<f64> = data.cal.iter().map(|p| p.cal_hz).collect();
    let body = header(
        root,
        "Fig. 5b — calibration: output vs virtual rate 360·f_cal (top axis: f_cal)",
        &format!(
            "window means of z at f_cal = {}…{} Hz, gyroscope at rest, {} engine; SF_read/SF_cal = {} (output 1), {} (output 2)",
            fmt_num(freqs[0], 4),
            fmt_num(freqs[freqs.len() - 1], 4),
            r.timing.engine,
            fmt_num(r.scale_factors.ratio[0], 4),
            fmt_num(r.scale_factors.ratio[1], 4),
        ),
    )?;
    let panels = body.split_evenly((1, 2));
    for (k, area) in panels.iter().enumerate() {
        let panel = LinePanel {
            caption: data.output_name(k),
            x_label: "virtual rate 360·f_cal (°/s)".into(),
            top_axis: Some(("Hz", 1.0 / 360.0)),
            k,
            sim: data.cal.iter().map(|p| (p.rate_dps, p.z[k])).collect(),
            theory: data
                .cal
                .iter()
                .map(|p| (p.rate_dps, p.z_theory[k]))
                .collect(),
            fit: (
                r.scale_factors.sf_cal_per_dps[k],
                r.scale_factors.intercept_cal[k],
            ),
            theory_slope: r.theory.sf_cal_per_dps[k],
        };
        draw_line_panel(area, &panel)?;
    }
    Ok(())
}
