//! A linear-fit panel (Figs. 4 and 5b): simulated points, the least-squares
//! line and the exact theory points of one output against the (virtual)
//! rate. [`LinePanel::view`] computes what is shown (offsets, power of ten,
//! ranges, legend corner); [`draw_line_panel`] only draws it.

use super::error::PlotError;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::err;
use super::format::{eng_exponent, fmt_num, fmt_sci, padded_range, scaled_unit, sub};
use super::style::{
    OUT_COLOR, SF_UNIT, draw_legend, draw_panel_mesh, free_corner, panel_builder, text_style,
};
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// A linear fit panel: simulated points, the least-squares line, exact
/// theory points.
pub(super) struct LinePanel {
    pub(super) caption: String,
    pub(super) x_label: String,
    /// A second x axis on top: (unit of its ticks, factor from the bottom
    /// axis).
    pub(super) top_axis: Option<(&'static str, f64)>,
    /// Output index (colour, names).
    pub(super) k: usize,
    /// Rate (x) and z of the simulated points.
    pub(super) sim: Vec<(f64, f64)>,
    /// The same for the exact theory.
    pub(super) theory: Vec<(f64, f64)>,
    /// Fitted slope and intercept of the simulated points.
    pub(super) fit: (f64, f64),
    /// Fitted slope of the theory points.
    pub(super) theory_slope: f64,
}

/// What a [`LinePanel`] shows, in plot units (z less `offset`, times
/// `scale = 10^-exp`).
struct LineView {
    x: (f64, f64),
    y: (f64, f64),
    /// Fitted intercept taken off the simulated z (0: none).
    offset: f64,
    /// The theory's own intercept taken off its points.
    theory_offset: f64,
    sim: Vec<(f64, f64)>,
    theory: Vec<(f64, f64)>,
    /// The fitted line at the ends of the x range.
    line: [(f64, f64); 2],
    corner: SeriesLabelPosition,
    y_label: String,
}

impl LinePanel {
    /// The fitted line at `x`.
    fn line(&self, x: f64) -> f64 {
        self.fit.0 * x + self.fit.1
    }

    /// Least-squares intercept of the theory points for the theory's slope.
    fn theory_intercept(&self) -> f64 {
        let n = self.theory.len() as f64;
        let mx = self.theory.iter().map(|q| q.0).sum::<f64>() / n;
        let my = self.theory.iter().map(|q| q.1).sum::<f64>() / n;
        my - self.theory_slope * mx
    }

    fn view(&self) -> LineView {
        let (x0, x1) = padded_range(self.sim.iter().map(|q| q.0), 0.06, 0.06);
        // Where the intercept dwarfs the change of the line over the plot,
        // the line would look flat: show each series less its own fitted
        // intercept (the slope is what the figure is about; the residual
        // figure shows the offsets).
        let line_span = (self.line(x1) - self.line(x0)).abs();
        let (offset, theory_offset) = if self.fit.1.abs() > 0.5 * line_span {
            (self.fit.1, self.theory_intercept())
        } else {
            (0.0, 0.0)
        };
        let ys: Vec<f64> = self
            .sim
            .iter()
            .map(|q| q.1 - offset)
            .chain(self.theory.iter().map(|q| q.1 - theory_offset))
            .chain([self.line(x0) - offset, self.line(x1) - offset])
            .collect();
        let exp = eng_exponent(ys.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        let scale = 10f64.powi(-exp);
        let shift = |pts: &[(f64, f64)], by: f64| -> Vec<(f64, f64)> {
            pts.iter().map(|q| (q.0, (q.1 - by) * scale)).collect()
        };
        let sim = shift(&self.sim, offset);
        let theory = shift(&self.theory, theory_offset);
        let (mut y0, mut y1) = padded_range(ys.iter().map(|v| v * scale), 0.08, 0.08);
        if y1 <= y0 {
            (y0, y1) = (y0 - 1.0, y1 + 1.0);
        }
        // A corner free of data for the legend (and the intercept note),
        // else room on top.
        let mut samples: Vec<(f64, f64)> = (0..=40)
            .map(|i| {
                let x = x0 + (x1 - x0) * i as f64 / 40.0;
                (x, (self.line(x) - offset) * scale)
            })
            .collect();
        samples.extend(sim.iter().chain(&theory));
        let (lw, lh) = (0.64, if offset != 0.0 { 0.36 } else { 0.27 });
        let normalized: Vec<(f64, f64)> = samples
            .iter()
            .map(|&(x, y)| ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0)))
            .collect();
        let corner = match free_corner(&normalized, lw, lh) {
            Some(c) => c,
            None => {
                y1 += (y1 - y0) * lh / (1.0 - lh);
                SeriesLabelPosition::UpperLeft
            }
        };
        let k = self.k;
        let quantity = if offset == 0.0 {
            format!("z{}", sub(k + 1))
        } else {
            format!("z{} − b{}", sub(k + 1), sub(k + 1))
        };
        LineView {
            x: (x0, x1),
            y: (y0, y1),
            offset,
            theory_offset,
            sim,
            theory,
            line: [x0, x1].map(|x| (x, (self.line(x) - offset) * scale)),
            corner,
            y_label: format!("{quantity}  ({})", scaled_unit(exp, "m²/s²")),
        }
    }
}

pub(super) fn draw_line_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &LinePanel,
) -> Result<(), PlotError> {
    let k = p.k;
    let color = OUT_COLOR[k];
    let v = p.view();
    let ((x0, x1), (y0, y1)) = (v.x, v.y);
    let top_factor = p.top_axis.map_or(1.0, |a| a.1);
    let mut builder = panel_builder(area, &p.caption, 56);
    if p.top_axis.is_some() {
        builder.top_x_label_area_size(34);
    }
    let mut chart = builder
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?
        .set_secondary_coord(x0 * top_factor..x1 * top_factor, y0..y1);
    let desc = (p.x_label.as_str(), v.y_label.as_str());
    draw_panel_mesh(&mut chart, desc, (8, 8), (16, 14))?;
    if let Some((unit, _)) = p.top_axis {
        chart
            .configure_secondary_axes()
            .label_style(text_style(14))
            .x_labels(8)
            .x_label_formatter(&|v: &f64| format!("{} {unit}", fmt_num(*v, 4)))
            .draw()
            .map_err(err)?;
    }
    let sf_note = |slope: f64| format!("SF = {} {SF_UNIT}", fmt_sci(slope, 4));
    chart
        .draw_series(LineSeries::new(v.line, color.stroke_width(2)))
        .map_err(err)?
        .label(format!("least-squares fit: {}", sf_note(p.fit.0)))
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2)));
    chart
        .draw_series(v.sim.iter().map(|&q| Circle::new(q, 4, color.filled())))
        .map_err(err)?
        .label("simulated (window means)")
        .legend(move |(x, y)| Circle::new((x + 12, y), 4, color.filled()));
    chart
        .draw_series(
            v.theory
                .iter()
                .map(|&q| Circle::new(q, 8, BLACK.stroke_width(1))),
        )
        .map_err(err)?
        .label(format!("exact theory: {}", sf_note(p.theory_slope)))
        .legend(|(x, y)| Circle::new((x + 12, y), 8, BLACK.stroke_width(1)));
    draw_legend(&mut chart, v.corner.clone(), (10, 14))?;
    if v.offset != 0.0 {
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        intercept_notes(area, k, &v, (xs, ys))?;
    }
    Ok(())
}

/// The intercept notes under (or over) the legend, in the same corner of
/// the plotting area whose pixel ranges are `xs`, `ys`.
fn intercept_notes<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    k: usize,
    v: &LineView,
    (xs, ys): (std::ops::Range<i32>, std::ops::Range<i32>),
) -> Result<(), PlotError> {
    let lower = matches!(
        v.corner,
        SeriesLabelPosition::LowerRight | SeriesLabelPosition::LowerLeft
    );
    let right = matches!(
        v.corner,
        SeriesLabelPosition::LowerRight | SeriesLabelPosition::UpperRight
    );
    let notes = [
        format!(
            "b{} = {} m²/s² (fitted intercept)",
            sub(k + 1),
            fmt_sci(v.offset, 6)
        ),
        format!(
            "theory less its own intercept, b{} {} {} m²/s²",
            sub(k + 1),
            if v.theory_offset >= v.offset {
                "+"
            } else {
                "−"
            },
            fmt_sci((v.theory_offset - v.offset).abs(), 2)
        ),
    ];
    let (bx, by) = area.get_base_pixel();
    let anchor = Pos::new(if right { HPos::Right } else { HPos::Left }, VPos::Top);
    let x = if right { xs.end - 12 } else { xs.start + 12 };
    // The legend box is about 3 x 22 px + margins high.
    let y = if lower {
        ys.end - 122 - 44
    } else {
        ys.start + 92
    };
    for (i, note) in notes.iter().enumerate() {
        area.draw(&Text::new(
            note.clone(),
            (x - bx, y + 22 * i as i32 - by),
            text_style(14).color(&super::style::GREY).pos(anchor),
        ))
        .map_err(err)?;
    }
    Ok(())
}
