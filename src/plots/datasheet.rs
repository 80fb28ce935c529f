//! The datasheet's figures (`gyrocal datasheet --out`):
//!
//! - `datasheet_adev`: both outputs' overlapping Allan deviation (deg/h,
//!   log-log) with one-sigma error bars (chi-square, Greenhall's edf), the
//!   fitted three-term model and the bias-instability minimum marked;
//! - `datasheet_nonlinearity`: the sweep's residuals from the best-fit
//!   line, ppm of full scale, against the rate;
//! - `datasheet_temperature`: the rate output's bias (deg/h) and scale
//!   factor error (ppm) at the factory's calibration against temperature,
//!   two panels (with `[drift]` only).
//!
//! Each figure's data is laid out in `new` (checked: finite, and positive
//! on log axes); drawing only draws.

use super::error::PlotError;
use super::format::{fmt_num, padded_range};
use super::style::{GREY, LIGHT, OUT_COLOR, draw_legend, header, text_style};
use super::{Plot, err};
use gyrocal_sim::datasheet::Datasheet;
use gyrocal_sim::datasheet::temperature::Temperature;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Size of every datasheet figure (pixels).
pub(super) const SIZE: (u32, u32) = (1200, 760);

/// (tau, low, sigma, high) in deg/h per point.
type Bars = Vec<(f64, f64, f64, f64)>;

/// The Allan figure's data.
pub(super) struct AdevFigure {
    bars: [Bars; 2],
    model: [Vec<(f64, f64)>; 2],
    minimum: [Option<(f64, f64)>; 2],
    fit_min_tau_s: f64,
    x: (f64, f64),
    y: (f64, f64),
    subtitle: String,
}

fn log_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = padded_range(values.into_iter().map(f64::log10), 0.0, 0.0);
    (10f64.powf(lo - 0.15), 10f64.powf(hi + 0.15))
}

impl AdevFigure {
    pub(super) fn new(ds: &Datasheet) -> Result<Self, PlotError> {
        let bars: [Bars; 2] = std::array::from_fn(|k| {
            let a = &ds.outputs[k].adev;
            (0..a.tau_s.len())
                .map(|i| (a.tau_s[i], a.ci_low[i], a.sigma_deg_per_h[i], a.ci_high[i]))
                .collect()
        });
        let ok = |v: f64| v.is_finite() && v > 0.0;
        for (k, b) in bars.iter().enumerate() {
            if b.len() < 2
                || b.iter()
                    .any(|p| !(ok(p.0) && ok(p.1) && ok(p.2) && ok(p.3)))
            {
                return Err(PlotError::Data(format!(
                    "datasheet Allan figure: output {} needs two or more finite, positive points",
                    k + 1
                )));
            }
        }
        let model = std::array::from_fn(|k| {
            let c = ds.outputs[k].noise_fit.coefficients;
            bars[k]
                .iter()
                .filter(|p| p.0 >= ds.fit_min_tau_s)
                .map(|p| (p.0, (c[0] / p.0 + c[1] + c[2] * p.0 / 3.0).sqrt() * 3600.0))
                .filter(|p| ok(p.1))
                .collect()
        });
        let minimum = std::array::from_fn(|k| {
            let o = &ds.outputs[k];
            Some((
                o.bias_instability_tau_s?,
                o.bias_instability_deg_per_h? * 0.664,
            ))
        });
        let all = bars.iter().flatten();
        let x = log_range(all.clone().map(|p| p.0));
        let y = log_range(all.flat_map(|p| [p.1, p.3]));
        Ok(Self {
            bars,
            model,
            minimum,
            fit_min_tau_s: ds.fit_min_tau_s,
            x,
            y,
            subtitle: format!(
                "overlapping Allan deviation of the rate output at rest, {} s at {} Hz; bars: one-sigma (68.3 %) chi-square intervals, Greenhall edf",
                fmt_num(ds.seconds, 4),
                fmt_num(ds.series.sample_rate_hz, 4)
            ),
        })
    }
}

impl Plot for AdevFigure {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        let body = header(root, "Datasheet: Allan deviation", &self.subtitle)?;
        let mut chart = ChartBuilder::on(&body)
            .margin(16)
            .margin_right(32)
            .x_label_area_size(56)
            .y_label_area_size(90)
            .build_cartesian_2d(
                (self.x.0..self.x.1).log_scale(),
                (self.y.0..self.y.1).log_scale(),
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .bold_line_style(LIGHT)
            .light_line_style(LIGHT.mix(0.4))
            .x_desc("cluster time τ (s)")
            .y_desc("σ(τ)  (°/h)")
            .axis_desc_style(text_style(16))
            .label_style(text_style(14))
            .x_label_formatter(&|v: &f64| fmt_num(*v, 3))
            .y_label_formatter(&|v: &f64| fmt_num(*v, 3))
            .draw()
            .map_err(err)?;
        for (k, &color) in OUT_COLOR.iter().enumerate() {
            let bars = &self.bars[k];
            chart
                .draw_series(bars.iter().map(|&(t, lo, _, hi)| {
                    PathElement::new([(t, lo), (t, hi)], color.stroke_width(2))
                }))
                .map_err(err)?;
            chart
                .draw_series(
                    bars.iter()
                        .map(|&(t, _, s, _)| Circle::new((t, s), 4, color.filled())),
                )
                .map_err(err)?
                .label(format!("output {}: σ(τ) with its interval", k + 1))
                .legend(move |(x, y)| Circle::new((x + 12, y), 4, color.filled()));
            chart
                .draw_series(DashedLineSeries::new(self.model[k].clone(), 6, 4, color.stroke_width(1)))
                .map_err(err)?
                .label(format!(
                    "output {}: fitted N²/τ + (0.664 B)² + K²τ/3 over τ ≥ {} s (the output filters shape shorter τ)",
                    k + 1,
                    fmt_num(self.fit_min_tau_s, 3)
                ))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], color.stroke_width(1)));
            if let Some(p) = self.minimum[k] {
                chart
                    .draw_series([Circle::new(p, 9, GREY.stroke_width(2))])
                    .map_err(err)?;
            }
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, (10, 14))
    }
}

/// A panel: its y label and one (x, y) series per output.
type Panel = (String, [Vec<(f64, f64)>; 2]);

/// A linear x-y figure of one or two panels, one series per output.
pub(super) struct XyFigure {
    title: String,
    subtitle: String,
    x_desc: String,
    panels: Vec<Panel>,
}

impl XyFigure {
    /// The sweep's residuals.
    pub(super) fn nonlinearity(ds: &Datasheet) -> Result<Self, PlotError> {
        let s = &ds.sweep;
        let series = std::array::from_fn(|k| {
            s.rates_dps
                .iter()
                .zip(&s.residual_ppm)
                .map(|(r, v)| (*r, v[k]))
                .collect()
        });
        Self::checked(XyFigure {
            title: "Datasheet: scale-factor nonlinearity".into(),
            subtitle: format!(
                "residual from the best-fit line over ±{} °/s, ppm of full scale; nonlinearity {} / {} ppm, asymmetry {} / {} ppm (outputs 1 / 2)",
                fmt_num(s.full_scale_dps, 4),
                fmt_num(s.nonlinearity_ppm[0], 3),
                fmt_num(s.nonlinearity_ppm[1], 3),
                fmt_num(s.asymmetry_ppm[0], 3),
                fmt_num(s.asymmetry_ppm[1], 3)
            ),
            x_desc: "rate (°/s)".into(),
            panels: vec![("residual (ppm of full scale)".into(), series)],
        })
    }

    /// Bias and scale-factor error against temperature.
    pub(super) fn temperature(t: &Temperature) -> Result<Self, PlotError> {
        let mut steps: Vec<_> = t.steps.iter().collect();
        steps.sort_by(|a, b| a.temperature_c.total_cmp(&b.temperature_c));
        let col = |f: &dyn Fn(usize, usize) -> f64| -> [Vec<(f64, f64)>; 2] {
            std::array::from_fn(|k| {
                (0..steps.len())
                    .map(|i| (steps[i].temperature_c, f(i, k)))
                    .collect()
            })
        };
        let tc = |v: Option<[f64; 2]>| match v {
            Some(v) => format!("{} / {}", fmt_num(v[0], 3), fmt_num(v[1], 3)),
            None => "n/a (one temperature)".into(),
        };
        Self::checked(XyFigure {
            title: "Datasheet: bias and scale factor against temperature".into(),
            subtitle: format!(
                "factory calibration at {} °C, no self-calibration; TC bias {} °/h/K, TC SF {} ppm/K (outputs 1 / 2)",
                fmt_num(t.steps[0].temperature_c, 4),
                tc(t.bias_tc_deg_per_h_per_k),
                tc(t.sf_tc_ppm_per_k)
            ),
            x_desc: "temperature (°C)".into(),
            panels: vec![
                ("bias (°/h)".into(), col(&|i, k| steps[i].bias_deg_per_h[k])),
                (
                    "scale-factor error (ppm)".into(),
                    col(&|i, k| steps[i].sf_error_ppm[k]),
                ),
            ],
        })
    }

    fn checked(self) -> Result<Self, PlotError> {
        let bad = self
            .panels
            .iter()
            .flat_map(|p| p.1.iter().flatten())
            .find(|p| !(p.0.is_finite() && p.1.is_finite()));
        match bad {
            Some(p) => Err(PlotError::Data(format!(
                "{}: point ({}, {}) is not finite",
                self.title, p.0, p.1
            ))),
            None => Ok(self),
        }
    }
}

impl Plot for XyFigure {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        let body = header(root, &self.title, &self.subtitle)?;
        let areas = body.split_evenly((1, self.panels.len()));
        for (area, (y_desc, series)) in areas.iter().zip(&self.panels) {
            let pts = series.iter().flatten();
            let x = padded_range(pts.clone().map(|p| p.0), 0.05, 0.05);
            let y = padded_range(pts.map(|p| p.1), 0.1, 0.1);
            let mut chart = ChartBuilder::on(area)
                .margin(16)
                .x_label_area_size(50)
                .y_label_area_size(80)
                .build_cartesian_2d(x.0..x.1, y.0..y.1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .bold_line_style(LIGHT)
                .light_line_style(LIGHT.mix(0.4))
                .x_desc(self.x_desc.as_str())
                .y_desc(y_desc.as_str())
                .axis_desc_style(text_style(16))
                .label_style(text_style(14))
                .x_label_formatter(&|v: &f64| fmt_num(*v, 3))
                .y_label_formatter(&|v: &f64| fmt_num(*v, 3))
                .draw()
                .map_err(err)?;
            for (k, s) in series.iter().enumerate() {
                let color = OUT_COLOR[k];
                chart
                    .draw_series(LineSeries::new(s.iter().copied(), color.stroke_width(2)))
                    .map_err(err)?
                    .label(format!("output {}", k + 1))
                    .legend(move |(x, y)| Circle::new((x + 12, y), 4, color.filled()));
                chart
                    .draw_series(s.iter().map(|&p| Circle::new(p, 4, color.filled())))
                    .map_err(err)?;
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .label_font(text_style(14))
                .background_style(WHITE.mix(0.9))
                .border_style(LIGHT)
                .draw()
                .map_err(err)?;
        }
        Ok(())
    }
}
