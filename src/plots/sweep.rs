//! A sweep's figure, three panels side by side, one colour per output:
//! - the cumulative distribution of each device's worst |self-cal error|
//!   (log axis) with the tolerance as a vertical line: where a curve
//!   crosses it is the yield;
//! - that error against the device's split f2 - f1 (Hz);
//! - that error against its Q1 (a log axis when Q1 spans a decade).
//!
//! The tolerance is dashed in every panel. Devices that failed have no
//! error and are not drawn; the subtitle counts them. The panels' data
//! ([`SweepFigure::new`]) is computed apart from the drawing.

use super::error::PlotError;
use super::style::{GREY, OUT_COLOR, header, text_style};
use super::{Plot, err};
use gyrocal_sim::sweep::SweepReport;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Figure size (pixels).
pub(super) const SIZE: (u32, u32) = (1800, 640);
/// Smallest |error| drawn (relative): exact zeros sit on the floor.
const FLOOR: f64 = 1e-7;

/// Per output: (split Hz, Q1, worst |error| in percent) of each finished device.
pub(super) struct SweepFigure {
    points: [Vec<(f64, f64, f64)>; 2],
    tolerance_percent: f64,
    title: String,
    subtitle: String,
}

impl SweepFigure {
    pub(super) fn new(report: &SweepReport, title: &str) -> Result<Self, PlotError> {
        let points: [Vec<(f64, f64, f64)>; 2] = std::array::from_fn(|k| {
            report
                .devices
                .iter()
                .filter(|d| d.failed.is_empty() && !d.steps.is_empty())
                .map(|d| {
                    (
                        d.device.f2_hz - d.device.f1_hz,
                        d.device.q1,
                        100.0 * d.worst_error(k).max(FLOOR),
                    )
                })
                .collect()
        });
        if points[0].is_empty() {
            return Err(PlotError::Data("sweep figure: no device finished".into()));
        }
        if points
            .iter()
            .flatten()
            .any(|p| !(p.0.is_finite() && p.1 > 0.0 && p.2.is_finite()))
        {
            return Err(PlotError::Data(
                "sweep figure: an error, split or Q is not finite".into(),
            ));
        }
        let s = &report.summary;
        Ok(Self {
            points,
            tolerance_percent: 100.0 * s.tolerance,
            title: title.to_string(),
            subtitle: format!(
                "{} devices, {} failed (not drawn); yield at {:.3}%: {:.1}% / {:.1}% (outputs 1 / 2)",
                s.devices,
                s.failed,
                100.0 * s.tolerance,
                100.0 * s.yield_per_output[0],
                100.0 * s.yield_per_output[1]
            ),
        })
    }

    /// The error axis: every error and the tolerance, with room.
    fn error_range(&self) -> (f64, f64) {
        let (lo, hi) = self.points.iter().flatten().fold(
            (self.tolerance_percent, self.tolerance_percent),
            |(a, b), p| (a.min(p.2), b.max(p.2)),
        );
        (lo / 2.0, hi * 2.0)
    }

    /// A panel's x range over `x` of every point, padded (log: by factors).
    fn x_range(&self, x: fn(&(f64, f64, f64)) -> f64, log: bool) -> (f64, f64) {
        let (lo, hi) = self
            .points
            .iter()
            .flatten()
            .map(x)
            .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        if log {
            (lo / 1.2, hi * 1.2)
        } else {
            let pad = ((hi - lo) * 0.05).max(1e-3 * hi.abs().max(1.0));
            (lo - pad, hi + pad)
        }
    }

    fn draw_cdf<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let (e0, e1) = self.error_range();
        let mut chart = ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d((e0..e1).log_scale(), 0.0..1.0)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("worst |self-cal error| (%)")
            .y_desc("fraction of devices at or below")
            .x_labels(6)
            .light_line_style(WHITE)
            .label_style(text_style(15))
            .axis_desc_style(text_style(17))
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(err)?;
        for (k, &c) in OUT_COLOR.iter().enumerate() {
            let mut e: Vec<f64> = self.points[k].iter().map(|p| p.2).collect();
            e.sort_by(f64::total_cmp);
            let n = e.len() as f64;
            let steps: Vec<(f64, f64)> = e
                .iter()
                .enumerate()
                .flat_map(|(i, &v)| [(v, i as f64 / n), (v, (i + 1) as f64 / n)])
                .collect();
            chart
                .draw_series(LineSeries::new(steps, c.stroke_width(2)))
                .map_err(err)?
                .label(format!("output {}", k + 1))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
        }
        let t = self.tolerance_percent;
        chart
            .draw_series(DashedLineSeries::new(
                vec![(t, 0.0), (t, 1.0)],
                8,
                5,
                GREY.stroke_width(2),
            ))
            .map_err(err)?
            .label("tolerance")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], GREY.stroke_width(2)));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(GREY)
            .label_font(text_style(15))
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(err)
    }

    fn draw_scatter<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        x: fn(&(f64, f64, f64)) -> f64,
        x_desc: &str,
        log_x: bool,
    ) -> Result<(), PlotError> {
        let (e0, e1) = self.error_range();
        let (x0, x1) = self.x_range(x, log_x);
        let t = self.tolerance_percent;
        macro_rules! panel {
            ($xr:expr) => {{
                let mut chart = ChartBuilder::on(area)
                    .margin(15)
                    .x_label_area_size(50)
                    .y_label_area_size(70)
                    .build_cartesian_2d($xr, (e0..e1).log_scale())
                    .map_err(err)?;
                chart
                    .configure_mesh()
                    .x_desc(x_desc)
                    .y_desc("worst |self-cal error| (%)")
                    .x_labels(6)
                    .y_labels(6)
                    .light_line_style(WHITE)
                    .label_style(text_style(15))
                    .axis_desc_style(text_style(17))
                    .y_label_formatter(&|v| format!("{v:.0e}"))
                    .draw()
                    .map_err(err)?;
                for (k, &c) in OUT_COLOR.iter().enumerate() {
                    chart
                        .draw_series(
                            self.points[k]
                                .iter()
                                .map(|p| Circle::new((x(p), p.2), 4, c.filled())),
                        )
                        .map_err(err)?;
                }
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(x0, t), (x1, t)],
                        8,
                        5,
                        GREY.stroke_width(2),
                    ))
                    .map_err(err)?;
            }};
        }
        if log_x {
            panel!((x0..x1).log_scale());
        } else {
            panel!(x0..x1);
        }
        Ok(())
    }
}

impl Plot for SweepFigure {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        let body = header(root, &self.title, &self.subtitle)?;
        let panels = body.split_evenly((1, 3));
        self.draw_cdf(&panels[0])?;
        self.draw_scatter(&panels[1], |p| p.0, "split f2 - f1 (Hz)", false)?;
        // Q on a log axis when it spans a decade or more.
        let (q0, q1) = self.x_range(|p| p.1, false);
        self.draw_scatter(
            &panels[2],
            |p| p.1,
            "Q1",
            q1 > 10.0 * q0.max(f64::MIN_POSITIVE),
        )
    }
}
