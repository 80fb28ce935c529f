//! Fig. 5a: the calibration staircase. Every calibration point is an
//! independent run from power-up; the runs are laid end to end on one time
//! axis. Top row: z as simulated, averaging windows shaded. Bottom row: z
//! averaged over one ripple period 1 / (2 f_cal), with the window means and
//! the exact theory as horizontal segments. One column per output.

use super::error::PlotError;
use gyrocal_sim::experiment::PointResult;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::data::Data;
use super::err;
use super::format::{clip_polyline, eng_exponent, fmt_num, padded_range, scaled_unit, sub};
use super::style::{
    GREY, LIGHT, OUT_COLOR, draw_legend, draw_panel_mesh, header, panel_builder, text_style,
};

/// One calibration run placed on the common time axis.
struct Step<'a> {
    point: &'a PointResult,
    /// Start of the run on the common axis (s).
    start: f64,
    /// z averaged over one ripple period, per output: (common time, z).
    smooth: [Vec<(f64, f64)>; 2],
}

/// Centred moving average of the piecewise-linear `trace` column `k + 1`
/// over `period`, evaluated on `n` times where the whole period lies
/// within the trace. Exact for the piecewise-linear interpolant, so the
/// ripple (a multiple of 1 / period) leaves no residue from sampling.
fn moving_average(trace: &[[f64; 3]], k: usize, period: f64, n: usize) -> Vec<(f64, f64)> {
    let t: Vec<f64> = trace.iter().map(|s| s[0]).collect();
    let z: Vec<f64> = trace.iter().map(|s| s[k + 1]).collect();
    let mut cum = vec![0.0; t.len()];
    for i in 1..t.len() {
        cum[i] = cum[i - 1] + 0.5 * (z[i] + z[i - 1]) * (t[i] - t[i - 1]);
    }
    // Integral from t[0] to `x` of the interpolant.
    let integral = |x: f64| -> f64 {
        let i = t.partition_point(|&v| v <= x).clamp(1, t.len() - 1);
        let (ta, tb, za, zb) = (t[i - 1], t[i], z[i - 1], z[i]);
        let u = x - ta;
        let slope = if tb > ta { (zb - za) / (tb - ta) } else { 0.0 };
        cum[i - 1] + za * u + 0.5 * slope * u * u
    };
    let (first, last) = (t[0] + period / 2.0, t[t.len() - 1] - period / 2.0);
    if last <= first {
        return vec![];
    }
    (0..n)
        .map(|j| {
            let c = first + (last - first) * j as f64 / (n - 1) as f64;
            let v = (integral(c + period / 2.0) - integral(c - period / 2.0)) / period;
            (c, v)
        })
        .collect()
}

/// The calibration runs end to end, each with its ripple-free traces;
/// returns them and the end of the last run (s).
fn lay_out<'a>(cal: &[&'a PointResult]) -> (Vec<Step<'a>>, f64) {
    let mut steps = vec![];
    let mut start = 0.0;
    for p in cal {
        let period = 1.0 / (2.0 * p.cal_hz);
        let smooth = [0, 1].map(|k| {
            moving_average(&p.trace, k, period, 400)
                .into_iter()
                .map(|(t, v)| (start + t, v))
                .collect()
        });
        steps.push(Step {
            point: p,
            start,
            smooth,
        });
        start += p.trace[p.trace.len() - 1][0];
    }
    (steps, start)
}

pub(super) fn draw_staircase<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), PlotError> {
    let r = data.report;
    let (steps, end) = lay_out(&data.cal);
    let freqs: Vec<f64> = data.cal.iter().map(|p| p.cal_hz).collect();
    let body = header(
        root,
        &format!(
            "Fig. 5a — calibration staircase: f_cal = {}…{} Hz",
            fmt_num(freqs[0], 4),
            fmt_num(freqs[freqs.len() - 1], 4),
        ),
        &format!(
            "each step is an independent run from power-up (gyroscope at rest), laid end to end; {} engine",
            r.timing.engine
        ),
    )?;
    let columns = body.split_evenly((1, 2));
    for (k, column) in columns.iter().enumerate() {
        let (top, bottom) = column.split_vertically(column.dim_in_pixel().1 * 45 / 100);
        staircase_raw(&top, data, &steps, k, end)?;
        staircase_smooth(&bottom, &steps, k, end)?;
    }
    Ok(())
}

/// Axes of a staircase panel: time on x (runs end to end), z scaled by
/// 10^exp on y, the averaging windows shaded (labelled in the legend when
/// `label_windows`) and dashed separators between runs.
#[allow(clippy::too_many_arguments)]
fn staircase_axes<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: String,
    k: usize,
    exp: i32,
    (y0, y1): (f64, f64),
    (end, y_labels): (f64, usize),
    steps: &[Step],
    label_windows: bool,
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, PlotError> {
    let mut chart = panel_builder(area, &caption, 46)
        .build_cartesian_2d(0.0..end, y0..y1)
        .map_err(err)?;
    let y_desc = format!("z{}  ({})", sub(k + 1), scaled_unit(exp, "m²/s²"));
    let desc = ("time, runs end to end (s)", y_desc.as_str());
    draw_panel_mesh(&mut chart, desc, (10, y_labels), (15, 13))?;
    let windows = chart
        .draw_series(steps.iter().map(|s| {
            let a = s.start + s.point.settle_s;
            Rectangle::new(
                [(a, y0), (a + s.point.window_s, y1)],
                LIGHT.mix(0.7).filled(),
            )
        }))
        .map_err(err)?;
    if label_windows {
        windows
            .label("averaging window")
            .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 24, y + 6)], LIGHT.filled()));
    }
    for s in steps.iter().skip(1) {
        chart
            .draw_series(DashedLineSeries::new(
                [(s.start, y0), (s.start, y1)],
                4,
                4,
                GREY.stroke_width(1),
            ))
            .map_err(err)?;
    }
    Ok(chart)
}

/// Power of ten and y range (scaled) of the top panel of output `k`: every
/// sample, with room on top for the legend.
fn raw_range(steps: &[Step], k: usize) -> (i32, (f64, f64)) {
    let values = steps
        .iter()
        .flat_map(|s| s.point.trace.iter().map(|q| q[k + 1]));
    let (lo, hi) = padded_range(values, 0.05, 0.4);
    let exp = eng_exponent(lo.abs().max(hi.abs()));
    let scale = 10f64.powi(-exp);
    (exp, (lo * scale, hi * scale))
}

/// Top panel: z as simulated, windows shaded.
fn staircase_raw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &Data,
    steps: &[Step],
    k: usize,
    end: f64,
) -> Result<(), PlotError> {
    let color = OUT_COLOR[k];
    let (exp, (y0, y1)) = raw_range(steps, k);
    let scale = 10f64.powi(-exp);
    let mut chart = staircase_axes(
        area,
        format!("{}: z{} as simulated", data.output_name(k), sub(k + 1)),
        k,
        exp,
        (y0, y1),
        (end, 6),
        steps,
        true,
    )?;
    for (i, s) in steps.iter().enumerate() {
        let series = chart
            .draw_series(LineSeries::new(
                s.point
                    .trace
                    .iter()
                    .map(|q| (s.start + q[0], q[k + 1] * scale)),
                color.stroke_width(1),
            ))
            .map_err(err)?;
        if i == 0 {
            series
                .label(format!("z{} (each run from power-up)", sub(k + 1)))
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 24, y)], color.stroke_width(1))
                });
        }
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, (8, 13))?;
    Ok(())
}

/// Scale and range of a bottom panel.
struct SmoothRange {
    /// Power of ten of the axis.
    exp: i32,
    /// One step of the staircase (unscaled): the room around it.
    room: f64,
    /// The y range, scaled.
    y: (f64, f64),
}

/// The steps of output `k` plus half a step of room around them, a third
/// of the height on top for the labels and the legend.
fn smooth_range(steps: &[Step], k: usize) -> SmoothRange {
    let means: Vec<f64> = steps
        .iter()
        .flat_map(|s| [s.point.z[k], s.point.z_theory[k]])
        .collect();
    let (lo, hi) = padded_range(means.iter().copied(), 0.0, 0.0);
    let step = (hi - lo) / (steps.len() - 1).max(1) as f64;
    let room = if step > 0.0 { step } else { lo.abs() * 0.1 };
    let (lo, hi) = (lo - 0.6 * room, hi + 0.6 * room);
    let hi = hi + (hi - lo) * 0.5;
    let exp = eng_exponent(lo.abs().max(hi.abs()));
    let scale = 10f64.powi(-exp);
    SmoothRange {
        exp,
        room,
        y: (lo * scale, hi * scale),
    }
}

/// Bottom panel: ripple-free z, window means and theory: the staircase.
fn staircase_smooth<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    steps: &[Step],
    k: usize,
    end: f64,
) -> Result<(), PlotError> {
    let SmoothRange {
        exp,
        room,
        y: (y0, y1),
    } = smooth_range(steps, k);
    let scale = 10f64.powi(-exp);
    let mut chart = staircase_axes(
        area,
        format!(
            "z{} averaged over one ripple period 1/(2 f_cal): the staircase",
            sub(k + 1)
        ),
        k,
        exp,
        (y0, y1),
        (end, 8),
        steps,
        false,
    )?;
    let on = Scaled { k, scale };
    draw_ripple_means(&mut chart, steps, on, (y0, y1))?;
    draw_windows(&mut chart, steps, on)?;
    draw_cal_labels(&mut chart, steps, on, room)?;
    draw_legend(&mut chart, SeriesLabelPosition::UpperLeft, (8, 13))?;
    Ok(())
}

/// The staircase chart's coordinates.
type StaircaseChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Output `k`'s values drawn in the chart's units: times `scale`.
#[derive(Clone, Copy)]
struct Scaled {
    k: usize,
    scale: f64,
}

/// Each step's mean over one ripple period, clipped to `(y0, y1)`.
fn draw_ripple_means<DB: DrawingBackend>(
    chart: &mut StaircaseChart<'_, DB>,
    steps: &[Step],
    Scaled { k, scale }: Scaled,
    (y0, y1): (f64, f64),
) -> Result<(), PlotError> {
    let color = OUT_COLOR[k];
    let mut first = true;
    for s in steps {
        let scaled: Vec<(f64, f64)> = s.smooth[k].iter().map(|&(t, v)| (t, v * scale)).collect();
        for piece in clip_polyline(&scaled, y0, y1) {
            let series = chart
                .draw_series(LineSeries::new(piece, color.mix(0.45).stroke_width(2)))
                .map_err(err)?;
            if first {
                series
                    .label("mean over one ripple period")
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 24, y)], color.mix(0.45).stroke_width(2))
                    });
                first = false;
            }
        }
    }
    Ok(())
}

/// The window a step's point averages, from its settling to its end (s).
fn window(s: &Step) -> (f64, f64) {
    let a = s.start + s.point.settle_s;
    (a, a + s.point.window_s)
}

/// Each step's window mean (the fit's data point) and the exact theory
/// over the same window, dashed.
fn draw_windows<DB: DrawingBackend>(
    chart: &mut StaircaseChart<'_, DB>,
    steps: &[Step],
    Scaled { k, scale }: Scaled,
) -> Result<(), PlotError> {
    let color = OUT_COLOR[k];
    chart
        .draw_series(steps.iter().map(|s| {
            let (a, b) = window(s);
            let z = s.point.z[k] * scale;
            PathElement::new([(a, z), (b, z)], color.stroke_width(4))
        }))
        .map_err(err)?
        .label("window mean (the fit's data point)")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], color.stroke_width(4)));
    for (i, s) in steps.iter().enumerate() {
        let (a, b) = window(s);
        let z = s.point.z_theory[k] * scale;
        let series = chart
            .draw_series(DashedLineSeries::new(
                [(a, z), (b, z)],
                5,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(err)?;
        if i == 0 {
            series
                .label("exact theory")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 24, y)], BLACK.stroke_width(1)));
        }
    }
    Ok(())
}

/// Each step's calibration frequency above its window, `room` (in the
/// data's units) times 0.15 over the higher of its mean and its theory.
fn draw_cal_labels<DB: DrawingBackend>(
    chart: &mut StaircaseChart<'_, DB>,
    steps: &[Step],
    Scaled { k, scale }: Scaled,
    room: f64,
) -> Result<(), PlotError> {
    let label_style = text_style(13).pos(plotters::style::text_anchor::Pos::new(
        plotters::style::text_anchor::HPos::Center,
        plotters::style::text_anchor::VPos::Bottom,
    ));
    chart
        .draw_series(steps.iter().map(|s| {
            let (a, b) = window(s);
            let z = s.point.z[k].max(s.point.z_theory[k]) * scale;
            Text::new(
                format!("{} Hz", fmt_num(s.point.cal_hz, 4)),
                ((a + b) / 2.0, z + 0.15 * room * scale),
                label_style.clone(),
            )
        }))
        .map_err(err)?;
    Ok(())
}
