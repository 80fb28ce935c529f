//! Residual figure: simulated minus exact theory at every point, in ppm of
//! the signal the fit measures at that output (|SF| times the span of the
//! rates), less its mean (an offset error does not move the scale
//! factor), readout and calibration side by side.

use super::error::PlotError;
use gyrocal_sim::experiment::PointResult;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::data::Data;
use super::err;
use super::format::{fmt_num, fmt_sci, padded_range};
use super::style::{GREY, OUT_COLOR, draw_legend, draw_panel_mesh, header, panel_builder};

/// One panel's data: per output, the residuals in ppm less their mean,
/// and the mean; the axis ranges.
struct ResidualPanel {
    series: Vec<(Vec<(f64, f64)>, f64)>,
    x: (f64, f64),
    y: (f64, f64),
}

/// Residuals of `points` against the theory, in ppm of `|sf_theory| x
/// span of the rates`, less their mean, per output.
fn residual_panel(points: &[&PointResult], sf_theory: [f64; 2]) -> ResidualPanel {
    let (xmin, xmax) = padded_range(points.iter().map(|p| p.rate_dps), 0.0, 0.0);
    let span = xmax - xmin;
    let series: Vec<(Vec<(f64, f64)>, f64)> = (0..2)
        .map(|k| {
            let signal = sf_theory[k].abs() * span;
            let v: Vec<(f64, f64)> = points
                .iter()
                .map(|p| {
                    let d = p.z[k] - p.z_theory[k];
                    let v = if signal > 0.0 { d / signal * 1e6 } else { 0.0 };
                    (p.rate_dps, v)
                })
                .collect();
            let mean = v.iter().map(|q| q.1).sum::<f64>() / v.len() as f64;
            (v.iter().map(|&(x, y)| (x, y - mean)).collect(), mean)
        })
        .collect();
    let x = padded_range(points.iter().map(|p| p.rate_dps), 0.06, 0.06);
    let all = series.iter().flat_map(|s| s.0.iter().map(|q| q.1));
    let y = padded_range(all.chain([0.0]), 0.1, 0.6);
    ResidualPanel { series, x, y }
}

pub(super) fn draw_residuals<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), PlotError> {
    let r = data.report;
    let body = header(
        root,
        "Simulated − exact theory, per point",
        "in ppm of the signal the fit measures at that output, |SF_theory|·(span of the rates); each output less its mean (given in the legend), so what is left is what moves the scale factor",
    )?;
    let panels = body.split_evenly((1, 2));
    let sets = [
        (
            "readout",
            "rotation rate Ω (°/s)",
            &data.readout,
            r.scale_factors.sf_read_per_dps,
            r.theory.sf_read_per_dps,
        ),
        (
            "calibration",
            "virtual rate 360·f_cal (°/s)",
            &data.cal,
            r.scale_factors.sf_cal_per_dps,
            r.theory.sf_cal_per_dps,
        ),
    ];
    for (area, set) in panels.iter().zip(sets) {
        draw_panel(area, set, r.detuned_output)?;
    }
    Ok(())
}

/// One panel's set: what, the x axis's label, the points, the simulated
/// and the theory's scale factors.
type PanelSet<'a> = (
    &'a str,
    &'a str,
    &'a Vec<&'a PointResult>,
    [f64; 2],
    [f64; 2],
);

/// One panel: its chart (`residual_chart`), the zero line, each output's
/// residuals as a line and circles, and the legend.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (what, x_label, points, sf, sf_theory): PanelSet,
    detuned: Option<usize>,
) -> Result<(), PlotError> {
    let ResidualPanel {
        series,
        x: (x0, x1),
        y: (y0, y1),
    } = residual_panel(points, sf_theory);
    let rel = |k: usize| fmt_sci(sf[k] / sf_theory[k] - 1.0, 2);
    let caption = format!(
        "{what}: SF_sim / SF_theory − 1 = {} (output 1), {} (output 2)",
        rel(0),
        rel(1)
    );
    let mut chart = residual_chart(area, caption, x_label, (x0, x1), (y0, y1))?;
    chart
        .draw_series(LineSeries::new(
            [(x0, 0.0), (x1, 0.0)],
            GREY.stroke_width(1),
        ))
        .map_err(err)?;
    for (k, (s, mean)) in series.iter().enumerate() {
        let color = OUT_COLOR[k];
        chart
            .draw_series(LineSeries::new(
                s.iter().copied(),
                color.mix(0.5).stroke_width(1),
            ))
            .map_err(err)?;
        let detuned = if detuned == Some(k) { " (detuned)" } else { "" };
        chart
            .draw_series(s.iter().map(|&q| Circle::new(q, 4, color.filled())))
            .map_err(err)?
            .label(format!(
                "output {}{detuned}: mean {} ppm",
                k + 1,
                fmt_num(*mean, 3)
            ))
            .legend(move |(x, y)| Circle::new((x + 12, y), 4, color.filled()));
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, (10, 14))
}

/// A panel's chart over `x` and `y` with its caption and mesh.
fn residual_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: String,
    x_label: &str,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, PlotError> {
    let mut chart = panel_builder(area, &caption, 56)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    let y_desc = "(z − z_theory) / (|SF|·span), less its mean  (ppm)";
    draw_panel_mesh(&mut chart, (x_label, y_desc), (8, 8), (16, 14))?;
    Ok(chart)
}
