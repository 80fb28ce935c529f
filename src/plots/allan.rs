//! Allan deviation figure: the overlapping Allan deviation of a rate
//! series (`gyrocal_sim::allan`) on log-log axes, in deg/h against tau in
//! s, with the angle random walk's tau^-1/2 line drawn through its reading
//! at 1 s and the bias instability's floor (min sigma) marked and
//! annotated. [`AllanFigure::new`] computes the series, the line, the
//! floor and the ranges, [`AllanFigure::with_prediction`] adds a predicted
//! curve (the noise model's); drawing only draws them.

use super::error::PlotError;
use gyrocal_sim::allan::{AllanAnalysis, BIAS_INSTABILITY_FACTOR};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::format::{fmt_num, padded_range};
use super::style::{GREY, LIGHT, OUT_COLOR, draw_legend, header, text_style};
use super::{Plot, err};

/// Pixel size of the figure.
pub(super) const SIZE: (u32, u32) = (1000, 720);

/// Colour of a predicted curve (green, apart from both outputs' colours).
const PREDICTION_COLOR: RGBColor = RGBColor(44, 160, 44);

/// deg/s to deg/h.
const PER_HOUR: f64 = 3600.0;

/// The tau^-1/2 line of the angle random walk, clipped to the plot.
struct ArwLine {
    /// End points (tau s, sigma deg/h).
    ends: [(f64, f64); 2],
    /// The reading at tau = 1 s (deg/h), where the line is marked.
    at_1s: (f64, f64),
    label: String,
}

/// Everything the Allan figure shows.
pub(super) struct AllanFigure {
    title: String,
    subtitle: String,
    /// (tau s, sigma deg/h) of every point.
    points: Vec<(f64, f64)>,
    arw: Option<ArwLine>,
    /// The minimum (tau s, sigma deg/h) and its label.
    floor: ((f64, f64), String),
    /// A predicted curve (tau s, sigma deg/h) and its label.
    prediction: Option<(Vec<(f64, f64)>, String)>,
    x: (f64, f64),
    y: (f64, f64),
}

/// A log range around `values`: from half the smallest to twice the
/// largest (`pad` decades each side, as a factor).
fn log_range(values: impl IntoIterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = padded_range(values.into_iter().map(f64::log10), 0.0, 0.0);
    (10f64.powf(lo - pad), 10f64.powf(hi + pad))
}

impl AllanFigure {
    /// Checks `analysis` (at least two points, every tau and deviation
    /// finite and positive) and lays the figure out.
    pub(super) fn new(analysis: &AllanAnalysis, title: &str) -> Result<Self, PlotError> {
        let pts = &analysis.points;
        if pts.len() < 2 {
            return Err(PlotError::Data(format!(
                "Allan figure: {} points, at least 2 are needed",
                pts.len()
            )));
        }
        if let Some(p) = pts
            .iter()
            .find(|p| !(p.tau_s.is_finite() && p.tau_s > 0.0 && p.adev.is_finite() && p.adev > 0.0))
        {
            return Err(PlotError::Data(format!(
                "Allan figure: point at tau = {} s has deviation {}: a log axis needs finite, positive values",
                p.tau_s, p.adev
            )));
        }
        let points: Vec<(f64, f64)> = pts.iter().map(|p| (p.tau_s, p.adev * PER_HOUR)).collect();
        let x = log_range(points.iter().map(|p| p.0), 0.15);
        let y = log_range(points.iter().map(|p| p.1), 0.3);
        let bi = &analysis.bias_instability;
        let floor_sigma = bi.deg_per_h * BIAS_INSTABILITY_FACTOR;
        let floor = (
            (bi.tau_s, floor_sigma),
            format!(
                "bias instability B = σ_min / 0.664 = {} °/h (σ_min at τ = {} s)",
                fmt_num(bi.deg_per_h, 3),
                fmt_num(bi.tau_s, 3)
            ),
        );
        let arw = analysis.angle_random_walk.as_ref().map(|a| {
            // sigma (deg/h) = 60 N (deg/sqrt(h)) / sqrt(tau (s)); kept
            // inside the y range by cutting its tau span.
            let line = |tau: f64| 60.0 * a.deg_per_sqrt_h / tau.sqrt();
            let tau_at = |sigma: f64| (60.0 * a.deg_per_sqrt_h / sigma).powi(2);
            let (t0, t1) = (x.0.max(tau_at(y.1)), x.1.min(tau_at(y.0)));
            ArwLine {
                ends: [(t0, line(t0)), (t1, line(t1))],
                at_1s: (1.0, line(1.0)),
                label: format!(
                    "τ^−1/2 (angle random walk): N = {} °/√h at τ = 1 s, fitted slope {}",
                    fmt_num(a.deg_per_sqrt_h, 3),
                    fmt_num(a.fitted_slope, 3)
                ),
            }
        });
        Ok(Self {
            title: title.to_string(),
            subtitle: format!(
                "overlapping Allan deviation (IEEE 952), {} octave-spaced τ, rate sampled at {} Hz",
                points.len(),
                fmt_num(analysis.sample_rate_hz, 4)
            ),
            points,
            arw,
            floor,
            prediction: None,
            x,
            y,
        })
    }

    /// Adds a predicted curve, `(tau s, sigma deg/s)` pairs (each finite
    /// and positive), labelled `label`; the y range widens to hold it.
    pub(super) fn with_prediction(
        mut self,
        curve: &[(f64, f64)],
        label: &str,
    ) -> Result<Self, PlotError> {
        if let Some(p) = curve
            .iter()
            .find(|p| !(p.0.is_finite() && p.0 > 0.0 && p.1.is_finite() && p.1 > 0.0))
        {
            return Err(PlotError::Data(format!(
                "Allan figure: predicted point ({}, {}): a log axis needs finite, positive values",
                p.0, p.1
            )));
        }
        let curve: Vec<(f64, f64)> = curve.iter().map(|&(t, s)| (t, s * PER_HOUR)).collect();
        let ys = self.points.iter().chain(&curve).map(|p| p.1);
        self.y = log_range(ys, 0.3);
        self.prediction = Some((curve, label.to_string()));
        Ok(self)
    }
}

impl Plot for AllanFigure {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        let body = header(root, &self.title, &self.subtitle)?;
        let mut chart = self.chart(&body)?;
        self.draw_measured(&mut chart)?;
        self.draw_prediction_and_arw(&mut chart)?;
        self.draw_floor(&mut chart)?;
        draw_legend(&mut chart, SeriesLabelPosition::LowerLeft, (10, 14))?;
        Ok(())
    }
}

/// The figure's log-log chart.
type LogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

impl AllanFigure {
    /// The log-log axes over the figure's ranges, with their mesh.
    fn chart<'a, DB: DrawingBackend>(
        &self,
        body: &'a DrawingArea<DB, Shift>,
    ) -> Result<LogChart<'a, DB>, PlotError> {
        let (x, y) = (self.x, self.y);
        let mut chart = ChartBuilder::on(body)
            .margin(16)
            .margin_right(32)
            .x_label_area_size(56)
            .y_label_area_size(90)
            .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .bold_line_style(LIGHT)
            .light_line_style(LIGHT.mix(0.4))
            .x_desc("cluster time τ (s)")
            .y_desc("Allan deviation σ(τ)  (°/h)")
            .axis_desc_style(text_style(16))
            .label_style(text_style(14))
            .x_label_formatter(&|v: &f64| fmt_num(*v, 3))
            .y_label_formatter(&|v: &f64| fmt_num(*v, 3))
            .draw()
            .map_err(err)?;
        Ok(chart)
    }

    /// The measured deviations, as a line and circles.
    fn draw_measured<DB: DrawingBackend>(
        &self,
        chart: &mut LogChart<'_, DB>,
    ) -> Result<(), PlotError> {
        let color = OUT_COLOR[0];
        chart
            .draw_series(LineSeries::new(
                self.points.iter().copied(),
                color.stroke_width(2),
            ))
            .map_err(err)?;
        chart
            .draw_series(
                self.points
                    .iter()
                    .map(|&p| Circle::new(p, 4, color.filled())),
            )
            .map_err(err)?
            .label("σ(τ) of the rate output")
            .legend(move |(x, y)| Circle::new((x + 12, y), 4, color.filled()));
        Ok(())
    }

    /// The predicted curve and the angle random walk's line, each when
    /// the figure has it.
    fn draw_prediction_and_arw<DB: DrawingBackend>(
        &self,
        chart: &mut LogChart<'_, DB>,
    ) -> Result<(), PlotError> {
        if let Some((curve, label)) = &self.prediction {
            let color = PREDICTION_COLOR;
            chart
                .draw_series(LineSeries::new(
                    curve.iter().copied(),
                    color.stroke_width(2),
                ))
                .map_err(err)?
                .label(label.clone())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2))
                });
        }
        if let Some(arw) = &self.arw {
            chart
                .draw_series(DashedLineSeries::new(arw.ends, 8, 5, BLACK.stroke_width(2)))
                .map_err(err)?
                .label(arw.label.clone())
                .legend(|(x, y)| PathElement::new([(x, y), (x + 24, y)], BLACK.stroke_width(2)));
            chart
                .draw_series([Cross::new(arw.at_1s, 8, BLACK.stroke_width(2))])
                .map_err(err)?;
        }
        Ok(())
    }

    /// The floor: a dashed line at the least deviation and a ring on it.
    fn draw_floor<DB: DrawingBackend>(
        &self,
        chart: &mut LogChart<'_, DB>,
    ) -> Result<(), PlotError> {
        let ((tau_min, sigma_min), label) = &self.floor;
        let (x, highlight) = (self.x, OUT_COLOR[1]);
        chart
            .draw_series(DashedLineSeries::new(
                [(x.0, *sigma_min), (x.1, *sigma_min)],
                4,
                4,
                GREY.stroke_width(1),
            ))
            .map_err(err)?;
        chart
            .draw_series([Circle::new(
                (*tau_min, *sigma_min),
                8,
                highlight.stroke_width(3),
            )])
            .map_err(err)?
            .label(label.clone())
            .legend(move |(x, y)| Circle::new((x + 12, y), 8, highlight.stroke_width(3)));
        Ok(())
    }
}
