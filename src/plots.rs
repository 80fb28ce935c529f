//! The paper's figures, drawn from a finished run: PNG and SVG of each.
//!
//! - `fig4_readout`: readout scale factor (paper Fig. 4). Window means of
//!   both outputs against the rotation rate, their least-squares lines and
//!   the exact theory at the same rates, one panel per output. The outputs
//!   sit on offsets that can be 10^5 times the signal (a detuned mode): a
//!   panel whose offset would flatten the line shows z less the fitted
//!   intercept (the theory points less the theory's own intercept; the
//!   residual figure shows the difference of offsets).
//! - `fig5a_staircase`: the calibration staircase (paper Fig. 5a). Every
//!   calibration point is an independent run from power-up; the runs are
//!   laid end to end on one time axis. Top row: z as simulated, averaging
//!   windows shaded (the 2 f_cal ripple is far larger than a step). Bottom
//!   row: z averaged over one ripple period 1 / (2 f_cal), which removes
//!   the ripple and shows the steps, with the window means (what the fit
//!   uses) and the exact theory as horizontal segments. One column per
//!   output; the paper's output is the detuned one.
//! - `fig5b_calibration`: calibration scale factor (paper Fig. 5b): window
//!   means against the virtual rate 360 f_cal, fitted lines, theory.
//! - `fig_residuals`: simulated minus exact theory at every point, in ppm
//!   of the signal the fit measures at that output (|SF| times the span of
//!   the rates), less its mean (stated in the legend: an offset error does
//!   not move the scale factor), readout and calibration, with the relative
//!   scale-factor errors in the panel captions.
//!
//! Text is drawn with a subset of DejaVu Sans embedded in the binary
//! (`assets/fonts/`), so no font library or installed font is needed at
//! build or run time. Every file is written to a temporary file in the
//! target folder and renamed into place: a reader never sees half a file.

use gyrocal_sim::experiment::{Mode, PointResult};
use gyrocal_sim::report::Report;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// DejaVu Sans, Latin-1, Greek and a few symbols (see assets/fonts/README.md).
static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans-subset.ttf");
/// The family every text style names.
const FAMILY: &str = "sans-serif";

/// Colours of output 1 and output 2.
const OUT_COLOR: [RGBColor; 2] = [RGBColor(31, 119, 180), RGBColor(214, 39, 40)];
const GREY: RGBColor = RGBColor(110, 110, 110);
const LIGHT: RGBColor = RGBColor(225, 225, 225);
/// Unit of a scale factor.
const SF_UNIT: &str = "(m²/s²)/(°/s)";

/// The figures, in the order they are written.
#[derive(Clone, Copy, Debug)]
enum Figure {
    Readout,
    Staircase,
    Calibration,
    Residuals,
}

impl Figure {
    const ALL: [Figure; 4] = [
        Figure::Readout,
        Figure::Staircase,
        Figure::Calibration,
        Figure::Residuals,
    ];

    fn name(self) -> &'static str {
        match self {
            Figure::Readout => "fig4_readout",
            Figure::Staircase => "fig5a_staircase",
            Figure::Calibration => "fig5b_calibration",
            Figure::Residuals => "fig_residuals",
        }
    }

    fn size(self) -> (u32, u32) {
        match self {
            Figure::Staircase => (1600, 1000),
            _ => (1400, 640),
        }
    }
}

/// Write every figure of `report` into `dir` (created if missing) as PNG
/// and SVG; returns the files written, in order. Errors are one line that
/// names the file (or folder) at fault; the report is checked before any
/// file is written, and a file that fails leaves the ones before it whole
/// and no temporary file behind.
pub fn write_figures(report: &Report, dir: &Path) -> Result<Vec<PathBuf>, String> {
    register_font()?;
    let data = Data::new(report)?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut written = vec![];
    for fig in Figure::ALL {
        let (w, h) = fig.size();
        let png_path = dir.join(format!("{}.png", fig.name()));
        let png = render_png(fig, &data, (w, h))
            .map_err(|e| format!("{}: drawing failed: {e}", png_path.display()))?;
        write_atomic(&png_path, &png)?;
        written.push(png_path);
        let svg_path = dir.join(format!("{}.svg", fig.name()));
        let svg = render_svg(fig, &data, (w, h))
            .map_err(|e| format!("{}: drawing failed: {e}", svg_path.display()))?;
        write_atomic(&svg_path, svg.as_bytes())?;
        written.push(svg_path);
    }
    Ok(written)
}

fn register_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
            .map_err(|_| "assets/fonts/DejaVuSans-subset.ttf: not a usable font".to_string())
    })
    .clone()
}

/// Write `bytes` atomically (`gyrocal_verify::write_atomically`),
/// with the error as one line naming the file.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    gyrocal_verify::write_atomically(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

fn render_png(fig: Figure, data: &Data, (w, h): (u32, u32)) -> Result<Vec<u8>, String> {
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        draw(fig, &root, data)?;
        root.present().map_err(|e| e.to_string())?;
    }
    let mut out = vec![];
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&rgb).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

fn render_svg(fig: Figure, data: &Data, size: (u32, u32)) -> Result<String, String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(fig, &root, data)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
}

fn draw<DB: DrawingBackend>(
    fig: Figure,
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(err)?;
    match fig {
        Figure::Readout => draw_readout(root, data),
        Figure::Staircase => draw_staircase(root, data),
        Figure::Calibration => draw_calibration(root, data),
        Figure::Residuals => draw_residuals(root, data),
    }
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// The report, checked and sorted for drawing.
struct Data<'a> {
    report: &'a Report,
    readout: Vec<&'a PointResult>,
    /// Calibration points by increasing frequency.
    cal: Vec<&'a PointResult>,
}

impl<'a> Data<'a> {
    fn new(report: &'a Report) -> Result<Self, String> {
        let pick = |mode: Mode| -> Vec<&PointResult> {
            report.points.iter().filter(|p| p.mode == mode).collect()
        };
        let readout = pick(Mode::Readout);
        let mut cal = pick(Mode::Calibration);
        cal.sort_by(|a, b| a.cal_hz.total_cmp(&b.cal_hz));
        for (what, points) in [("readout", &readout), ("calibration", &cal)] {
            if points.len() < 2 {
                return Err(format!(
                    "figures: the report has {} {what} points, at least 2 are needed",
                    points.len()
                ));
            }
            for p in points.iter() {
                let values = [p.rate_dps, p.z[0], p.z[1], p.z_theory[0], p.z_theory[1]];
                if values.iter().any(|v| !v.is_finite()) {
                    return Err(format!(
                        "figures: {what} point at {} deg/s has a non-finite value (z {:?}, theory {:?})",
                        p.rate_dps, p.z, p.z_theory
                    ));
                }
            }
        }
        for p in &cal {
            if p.trace.len() < 2 || p.trace.iter().flatten().any(|v| !v.is_finite()) {
                return Err(format!(
                    "figures: calibration point at {} Hz has no usable trace ({} samples; traces are not serialized, figures need the report of a run)",
                    p.cal_hz,
                    p.trace.len()
                ));
            }
        }
        let scalars = [
            report.sf_read_per_dps,
            report.sf_cal_per_dps,
            report.intercept_read,
            report.intercept_cal,
            report.theory.sf_read_per_dps,
            report.theory.sf_cal_per_dps,
        ];
        if scalars.iter().flatten().any(|v| !v.is_finite()) {
            return Err("figures: the report has a non-finite scale factor or intercept".into());
        }
        Ok(Self {
            report,
            readout,
            cal,
        })
    }

    /// "output 2 (f₂ − f_c = +250.0 Hz, detuned: the paper's output)".
    fn output_name(&self, k: usize) -> String {
        let d = &self.report.device;
        let offset = [d.f1_hz, d.f2_hz][k] - d.carrier_hz;
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

// ---------------------------------------------------------------- numbers

fn sup(n: i32) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            '9' => '⁹',
            c => c,
        })
        .collect()
}

fn sub(n: usize) -> char {
    char::from_u32(0x2080 + n as u32).unwrap_or('?')
}

/// `v` with `digits` significant digits as "−6.024×10⁻¹⁶".
fn fmt_sci(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    let m = v / 10f64.powi(e);
    let (m, e) = if format!("{:.*}", digits - 1, m.abs()).starts_with("10") {
        (m / 10.0, e + 1)
    } else {
        (m, e)
    };
    let mant = format!("{:.*}", digits - 1, m).replace('-', "−");
    if e == 0 {
        mant
    } else {
        format!("{mant}×10{}", sup(e))
    }
}

/// `v` with up to `digits` significant digits, plain between 10⁻³ and
/// 10⁵ ("1.533", "10"), else as `fmt_sci`.
fn fmt_num(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    if !(-3..5).contains(&e) {
        return fmt_sci(v, digits);
    }
    let decimals = (digits as i32 - 1 - e).max(0) as usize;
    let s = format!("{:.*}", decimals, v);
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    s.replace('-', "−")
}

/// Engineering exponent (a multiple of 3) for values up to `max_abs`.
fn eng_exponent(max_abs: f64) -> i32 {
    if max_abs > 0.0 && max_abs.is_finite() {
        3 * (max_abs.log10().floor() as i32).div_euclid(3)
    } else {
        0
    }
}

/// A unit with a power of ten in front: "10⁻¹⁸ m²/s²".
fn scaled_unit(exp: i32, unit: &str) -> String {
    if exp == 0 {
        unit.to_string()
    } else {
        format!("10{} {unit}", sup(exp))
    }
}

/// Tick labels with as many decimals as a span of `span` over about 8
/// ticks needs.
fn tick_formatter(span: f64) -> impl Fn(&f64) -> String {
    let step = span.abs() / 8.0;
    let decimals = if step > 0.0 && step.is_finite() {
        (-step.log10()).ceil().clamp(0.0, 6.0) as usize
    } else {
        0
    };
    move |v: &f64| {
        let s = format!("{:.*}", decimals, v);
        let s = if s
            .trim_start_matches('-')
            .chars()
            .all(|c| c == '0' || c == '.')
        {
            s.trim_start_matches('-').to_string()
        } else {
            s
        };
        s.replace('-', "−")
    }
}

/// [min, max] of `values`, widened by `lo` and `hi` times the span (and
/// never empty).
fn padded_range(values: impl IntoIterator<Item = f64>, lo: f64, hi: f64) -> (f64, f64) {
    let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        a = a.min(v);
        b = b.max(v);
    }
    if !(a.is_finite() && b.is_finite()) {
        return (-1.0, 1.0);
    }
    let span = if b > a {
        b - a
    } else if a != 0.0 {
        a.abs() * 0.1
    } else {
        1.0
    };
    (a - lo * span, b + hi * span)
}

/// Pieces of the polyline `pts` inside y in [lo, hi], cut exactly at the
/// bounds (plotters does not clip lines to the plotting area).
fn clip_polyline(pts: &[(f64, f64)], lo: f64, hi: f64) -> Vec<Vec<(f64, f64)>> {
    let mut pieces = vec![];
    let mut cur: Vec<(f64, f64)> = vec![];
    let inside = |y: f64| y >= lo && y <= hi;
    let cross = |a: (f64, f64), b: (f64, f64), y: f64| {
        let t = (y - a.1) / (b.1 - a.1);
        (a.0 + t * (b.0 - a.0), y)
    };
    for (i, &p) in pts.iter().enumerate() {
        if i == 0 {
            if inside(p.1) {
                cur.push(p);
            }
            continue;
        }
        let q = pts[i - 1];
        // The part of segment q-p within the band, in order from q to p.
        let mut seg = vec![];
        if inside(q.1) {
            seg.push(q);
        }
        let mut crossings: Vec<(f64, f64)> = [lo, hi]
            .iter()
            .filter(|&&y| (q.1 - y) * (p.1 - y) < 0.0)
            .map(|&y| cross(q, p, y))
            .collect();
        crossings.sort_by(|a, b| ((a.0 - q.0).abs()).total_cmp(&(b.0 - q.0).abs()));
        seg.extend(crossings);
        if inside(p.1) {
            seg.push(p);
        }
        if seg.is_empty() {
            if cur.len() > 1 {
                pieces.push(std::mem::take(&mut cur));
            }
            cur.clear();
            continue;
        }
        if cur.is_empty() {
            cur.extend(seg.iter().copied());
        } else {
            cur.extend(seg.iter().skip(1).copied());
        }
        if !inside(p.1) {
            if cur.len() > 1 {
                pieces.push(std::mem::take(&mut cur));
            }
            cur.clear();
        }
    }
    if cur.len() > 1 {
        pieces.push(cur);
    }
    pieces
}

// ----------------------------------------------------------------- layout

fn text_style(size: u32) -> TextStyle<'static> {
    (FAMILY, size).into_font().color(&BLACK)
}

/// Title (and subtitle) across the top; returns the area below.
fn header<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    subtitle: &str,
) -> Result<DrawingArea<DB, Shift>, String> {
    let (top, body) = root.split_vertically(70);
    let (w, _) = top.dim_in_pixel();
    let centre = |size| {
        text_style(size).pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Top,
        ))
    };
    top.draw(&Text::new(
        title.to_string(),
        (w as i32 / 2, 10),
        centre(24),
    ))
    .map_err(err)?;
    top.draw(&Text::new(
        subtitle.to_string(),
        (w as i32 / 2, 42),
        centre(16).color(&GREY),
    ))
    .map_err(err)?;
    Ok(body)
}

/// The corner of a plot, in fractions of its width and height, where the
/// points `pts` (normalized to [0, 1]) leave a `w` x `h` box free.
fn free_corner(pts: &[(f64, f64)], w: f64, h: f64) -> Option<SeriesLabelPosition> {
    use SeriesLabelPosition::*;
    let boxes = [
        (UpperLeft, 0.0, 1.0 - h),
        (UpperRight, 1.0 - w, 1.0 - h),
        (LowerRight, 1.0 - w, 0.0),
        (LowerLeft, 0.0, 0.0),
    ];
    boxes.into_iter().find_map(|(pos, x0, y0)| {
        let hit = pts.iter().any(|&(x, y)| {
            x >= x0 - 0.02 && x <= x0 + w + 0.02 && y >= y0 - 0.02 && y <= y0 + h + 0.02
        });
        (!hit).then_some(pos)
    })
}

/// A linear fit panel: simulated points, the least-squares line, exact
/// theory points.
struct LinePanel {
    caption: String,
    x_label: String,
    /// A second x axis on top: (unit of its ticks, factor from the bottom
    /// axis).
    top_axis: Option<(&'static str, f64)>,
    /// Output index (colour, names).
    k: usize,
    /// Rate (x) and z of the simulated points.
    sim: Vec<(f64, f64)>,
    /// The same for the exact theory.
    theory: Vec<(f64, f64)>,
    /// Fitted slope and intercept of the simulated points.
    fit: (f64, f64),
    /// Fitted slope of the theory points.
    theory_slope: f64,
}

fn draw_line_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &LinePanel,
) -> Result<(), String> {
    let k = p.k;
    let color = OUT_COLOR[k];
    let (x0, x1) = padded_range(p.sim.iter().map(|q| q.0), 0.06, 0.06);
    let line = |x: f64| p.fit.0 * x + p.fit.1;
    // Where the intercept dwarfs the change of the line over the plot, the
    // line would look flat: show each series less its own fitted intercept
    // (the slope is what the figure is about; the residual figure shows
    // the offsets).
    let theory_intercept = {
        let n = p.theory.len() as f64;
        let mx = p.theory.iter().map(|q| q.0).sum::<f64>() / n;
        let my = p.theory.iter().map(|q| q.1).sum::<f64>() / n;
        my - p.theory_slope * mx
    };
    let line_span = (line(x1) - line(x0)).abs();
    let (offset, theory_offset) = if p.fit.1.abs() > 0.5 * line_span {
        (p.fit.1, theory_intercept)
    } else {
        (0.0, 0.0)
    };
    let ys: Vec<f64> = p
        .sim
        .iter()
        .map(|q| q.1 - offset)
        .chain(p.theory.iter().map(|q| q.1 - theory_offset))
        .chain([line(x0) - offset, line(x1) - offset])
        .collect();
    let exp = eng_exponent(ys.iter().fold(0.0f64, |m, v| m.max(v.abs())));
    let scale = 10f64.powi(-exp);
    let sim: Vec<(f64, f64)> = p
        .sim
        .iter()
        .map(|q| (q.0, (q.1 - offset) * scale))
        .collect();
    let theory: Vec<(f64, f64)> = p
        .theory
        .iter()
        .map(|q| (q.0, (q.1 - theory_offset) * scale))
        .collect();
    let (mut y0, mut y1) = padded_range(ys.iter().map(|v| v * scale), 0.08, 0.08);
    if y1 <= y0 {
        (y0, y1) = (y0 - 1.0, y1 + 1.0);
    }
    // A corner free of data for the legend (and the intercept note), else
    // room on top.
    let mut samples: Vec<(f64, f64)> = (0..=40)
        .map(|i| {
            let x = x0 + (x1 - x0) * i as f64 / 40.0;
            (x, (line(x) - offset) * scale)
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
    let quantity = if offset == 0.0 {
        format!("z{}", sub(k + 1))
    } else {
        format!("z{} − b{}", sub(k + 1), sub(k + 1))
    };
    let y_label = format!("{quantity}  ({})", scaled_unit(exp, "m²/s²"));
    let top_factor = p.top_axis.map_or(1.0, |a| a.1);
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(&p.caption, text_style(17))
        .margin(12)
        .margin_right(24)
        .x_label_area_size(56)
        .y_label_area_size(80);
    if p.top_axis.is_some() {
        builder.top_x_label_area_size(34);
    }
    let mut chart = builder
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?
        .set_secondary_coord(x0 * top_factor..x1 * top_factor, y0..y1);
    chart
        .configure_mesh()
        .max_light_lines(0)
        .bold_line_style(LIGHT)
        .x_desc(p.x_label.as_str())
        .y_desc(y_label.as_str())
        .axis_desc_style(text_style(16))
        .label_style(text_style(14))
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&tick_formatter(x1 - x0))
        .y_label_formatter(&tick_formatter(y1 - y0))
        .draw()
        .map_err(err)?;
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
        .draw_series(LineSeries::new(
            [x0, x1].map(|x| (x, (line(x) - offset) * scale)),
            color.stroke_width(2),
        ))
        .map_err(err)?
        .label(format!("least-squares fit: {}", sf_note(p.fit.0)))
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], color.stroke_width(2)));
    chart
        .draw_series(sim.iter().map(|&q| Circle::new(q, 4, color.filled())))
        .map_err(err)?
        .label("simulated (window means)")
        .legend(move |(x, y)| Circle::new((x + 12, y), 4, color.filled()));
    chart
        .draw_series(
            theory
                .iter()
                .map(|&q| Circle::new(q, 8, BLACK.stroke_width(1))),
        )
        .map_err(err)?
        .label(format!("exact theory: {}", sf_note(p.theory_slope)))
        .legend(|(x, y)| Circle::new((x + 12, y), 8, BLACK.stroke_width(1)));
    let lower = matches!(
        corner,
        SeriesLabelPosition::LowerRight | SeriesLabelPosition::LowerLeft
    );
    let right = matches!(
        corner,
        SeriesLabelPosition::LowerRight | SeriesLabelPosition::UpperRight
    );
    chart
        .configure_series_labels()
        .position(corner)
        .margin(10)
        .label_font(text_style(14))
        .background_style(WHITE.mix(0.9))
        .border_style(LIGHT)
        .draw()
        .map_err(err)?;
    if offset != 0.0 {
        // Under (or over) the legend, in the same corner.
        let notes = [
            format!(
                "b{} = {} m²/s² (fitted intercept)",
                sub(k + 1),
                fmt_sci(offset, 6)
            ),
            format!(
                "theory less its own intercept, b{} {} {} m²/s²",
                sub(k + 1),
                if theory_offset >= offset { "+" } else { "−" },
                fmt_sci((theory_offset - offset).abs(), 2)
            ),
        ];
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let (bx, by) = area.get_base_pixel();
        let anchor = plotters::style::text_anchor::Pos::new(
            if right {
                plotters::style::text_anchor::HPos::Right
            } else {
                plotters::style::text_anchor::HPos::Left
            },
            plotters::style::text_anchor::VPos::Top,
        );
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
                text_style(14).color(&GREY).pos(anchor),
            ))
            .map_err(err)?;
        }
    }
    Ok(())
}

// ---------------------------------------------------------------- figures

fn draw_readout<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), String> {
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
            fit: (r.sf_read_per_dps[k], r.intercept_read[k]),
            theory_slope: r.theory.sf_read_per_dps[k],
        };
        draw_line_panel(area, &panel)?;
    }
    Ok(())
}

fn draw_calibration<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), String> {
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
            fmt_num(r.ratio[0], 4),
            fmt_num(r.ratio[1], 4),
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
            fit: (r.sf_cal_per_dps[k], r.intercept_cal[k]),
            theory_slope: r.theory.sf_cal_per_dps[k],
        };
        draw_line_panel(area, &panel)?;
    }
    Ok(())
}

fn draw_residuals<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), String> {
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
            r.sf_read_per_dps,
            r.theory.sf_read_per_dps,
        ),
        (
            "calibration",
            "virtual rate 360·f_cal (°/s)",
            &data.cal,
            r.sf_cal_per_dps,
            r.theory.sf_cal_per_dps,
        ),
    ];
    for (area, (what, x_label, points, sf, sf_theory)) in panels.iter().zip(sets) {
        let (xmin, xmax) = padded_range(points.iter().map(|p| p.rate_dps), 0.0, 0.0);
        let span = xmax - xmin;
        // (ppm values less their mean, the mean)
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
        let (x0, x1) = padded_range(points.iter().map(|p| p.rate_dps), 0.06, 0.06);
        let all = series.iter().flat_map(|s| s.0.iter().map(|q| q.1));
        let (y0, y1) = padded_range(all.chain([0.0]), 0.1, 0.6);
        let rel = |k: usize| fmt_sci(sf[k] / sf_theory[k] - 1.0, 2);
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!(
                    "{what}: SF_sim / SF_theory − 1 = {} (output 1), {} (output 2)",
                    rel(0),
                    rel(1)
                ),
                text_style(17),
            )
            .margin(12)
            .margin_right(24)
            .x_label_area_size(56)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .max_light_lines(0)
            .bold_line_style(LIGHT)
            .x_desc(x_label)
            .y_desc("(z − z_theory) / (|SF|·span), less its mean  (ppm)")
            .axis_desc_style(text_style(16))
            .label_style(text_style(14))
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&tick_formatter(x1 - x0))
            .y_label_formatter(&tick_formatter(y1 - y0))
            .draw()
            .map_err(err)?;
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
            chart
                .draw_series(s.iter().map(|&q| Circle::new(q, 4, color.filled())))
                .map_err(err)?
                .label(format!(
                    "output {}{}: mean {} ppm",
                    k + 1,
                    if r.detuned_output == Some(k) {
                        " (detuned)"
                    } else {
                        ""
                    },
                    fmt_num(*mean, 3)
                ))
                .legend(move |(x, y)| Circle::new((x + 12, y), 4, color.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .margin(10)
            .label_font(text_style(14))
            .background_style(WHITE.mix(0.9))
            .border_style(LIGHT)
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

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

fn draw_staircase<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &Data,
) -> Result<(), String> {
    let r = data.report;
    let mut steps = vec![];
    let mut start = 0.0;
    for p in &data.cal {
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
    let end = start;
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
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, text_style(17))
        .margin(12)
        .margin_right(24)
        .x_label_area_size(46)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..end, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .bold_line_style(LIGHT)
        .x_desc("time, runs end to end (s)")
        .y_desc(format!("z{}  ({})", sub(k + 1), scaled_unit(exp, "m²/s²")))
        .axis_desc_style(text_style(15))
        .label_style(text_style(13))
        .x_labels(10)
        .y_labels(y_labels)
        .x_label_formatter(&tick_formatter(end))
        .y_label_formatter(&tick_formatter(y1 - y0))
        .draw()
        .map_err(err)?;
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

/// Top panel: z as simulated, windows shaded.
fn staircase_raw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &Data,
    steps: &[Step],
    k: usize,
    end: f64,
) -> Result<(), String> {
    let color = OUT_COLOR[k];
    let values = steps
        .iter()
        .flat_map(|s| s.point.trace.iter().map(|q| q[k + 1]));
    // Room on top for the legend.
    let (lo, hi) = padded_range(values, 0.05, 0.4);
    let exp = eng_exponent(lo.abs().max(hi.abs()));
    let scale = 10f64.powi(-exp);
    let (y0, y1) = (lo * scale, hi * scale);
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
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .margin(8)
        .label_font(text_style(13))
        .background_style(WHITE.mix(0.9))
        .border_style(LIGHT)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Bottom panel: ripple-free z, window means and theory: the staircase.
fn staircase_smooth<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    steps: &[Step],
    k: usize,
    end: f64,
) -> Result<(), String> {
    let color = OUT_COLOR[k];
    let means: Vec<f64> = steps
        .iter()
        .flat_map(|s| [s.point.z[k], s.point.z_theory[k]])
        .collect();
    // The steps plus half a step of room around them, a third of the
    // height on top for the labels and the legend.
    let (lo, hi) = padded_range(means.iter().copied(), 0.0, 0.0);
    let step = (hi - lo) / (steps.len() - 1).max(1) as f64;
    let room = if step > 0.0 { step } else { lo.abs() * 0.1 };
    let (lo, hi) = (lo - 0.6 * room, hi + 0.6 * room);
    let hi = hi + (hi - lo) * 0.5;
    let exp = eng_exponent(lo.abs().max(hi.abs()));
    let scale = 10f64.powi(-exp);
    let (y0, y1) = (lo * scale, hi * scale);
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
    let window = |s: &Step| {
        let a = s.start + s.point.settle_s;
        (a, a + s.point.window_s)
    };
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
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .margin(8)
        .label_font(text_style(13))
        .background_style(WHITE.mix(0.9))
        .border_style(LIGHT)
        .draw()
        .map_err(err)?;
    Ok(())
}
