//! Fig. 4: readout scale factor. Window means of both outputs against the
//! rotation rate, their least-squares lines and the exact theory at the
//! same rates, one panel per output (`line_panel`).

use super::error::PlotError;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::data::Data;
use super::line_panel::{LinePanel, draw_line_panel};
use super::style::header;

pub(super) fn draw_readout<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), PlotError> {
    let r = data.report;
    let body = header(
        root,
        "Fig. 4 — readout: output vs rotation rate",
        &format!(
            "window means of z over {} rates, {} engine; each output on its own axis; where an offset b would flatten the line, z − b is shown",
            data.readout.len(),
            r.timing.engine
        ),
    )?;
    let panels = body.split_evenly((1, 2));
    for (k, area) in panels.iter().enumerate() {
        let panel = LinePanel {
            caption: data.output_name(k),
            x_label: "rotation rate Ω (°/s)".into(),
            top_axis: None,
            k,
            sim: data.readout.iter().map(|p| (p.rate_dps, p.z[k])).collect(),
            theory: data
                .readout
                .iter()
                .map(|p| (p.rate_dps, p.z_theory[k]))
                .collect(),
            fit: (
                r.scale_factors.sf_read_per_dps[k],
                r.scale_factors.intercept_read[k],
            ),
            theory_slope: r.theory.sf_read_per_dps[k],
        };
        draw_line_panel(area, &panel)?;
    }
    Ok(())
}
