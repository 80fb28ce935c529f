//! The figures, PNG and SVG of each: the paper's, drawn from a finished
//! run, one file per figure beside this one, and the Allan deviation of a
//! rate series (`allan`).
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
//!
//! Layout: `data` (the report checked and sorted), `format` (numbers and
//! ranges), `style` (font, colours, title block), `line_panel` (the
//! linear-fit panel of Figs. 4 and 5b), then one file per figure. Each
//! figure computes what a panel shows (fits, intercepts, scales, ranges)
//! apart from drawing it.

mod allan;
mod calibration;
mod data;
mod datasheet;
pub mod error;
mod field;
pub(crate) mod field_rate;
mod format;
mod line_panel;
mod readout;
mod residuals;
mod staircase;
mod style;
mod sweep;

pub use error::PlotError;
use gyrocal_sim::allan::AllanAnalysis;
use gyrocal_sim::report::Report;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

use data::Data;

/// The figures of a run, in the order they are written.
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

/// Something that draws itself on a whole drawing area.
trait Plot {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// One figure of a run.
struct RunFigure<'a> {
    fig: Figure,
    data: &'a Data<'a>,
}

impl Plot for RunFigure<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        match self.fig {
            Figure::Readout => readout::draw_readout(root, self.data),
            Figure::Staircase => staircase::draw_staircase(root, self.data),
            Figure::Calibration => calibration::draw_calibration(root, self.data),
            Figure::Residuals => residuals::draw_residuals(root, self.data),
        }
    }
}

/// Write every figure of `report` into `dir` (created if missing) as PNG
/// and SVG; returns the files written, in order. Errors are one line that
/// names the file (or folder) at fault; the report is checked before any
/// file is written, and a file that fails leaves the ones before it whole
/// and no temporary file behind.
pub fn write_figures(report: &Report, dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    style::register_font()?;
    let data = Data::new(report)?;
    std::fs::create_dir_all(dir).map_err(|e| PlotError::write(dir, e))?;
    let mut written = vec![];
    for fig in Figure::ALL {
        let plot = RunFigure { fig, data: &data };
        written.extend(write_plot(&plot, fig.size(), dir, fig.name())?);
    }
    Ok(written)
}

/// Write the Allan deviation of `analysis` into `dir` (created if missing)
/// as `name`.png and `name`.svg, titled `title`; returns the two files.
/// Errors as [`write_figures`]; the analysis is checked first (at least two
/// positive, finite points).
#[allow(dead_code)] // reason: the field command (issue 9) will call it; tests/plots.rs draws it
pub fn write_allan_figure(
    analysis: &AllanAnalysis,
    title: &str,
    dir: &Path,
    name: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    style::register_font()?;
    let plot = allan::AllanFigure::new(analysis, title)?;
    std::fs::create_dir_all(dir).map_err(|e| PlotError::write(dir, e))?;
    write_plot(&plot, allan::SIZE, dir, name)
}

/// [`write_allan_figure`] with a predicted curve, `(tau s, sigma deg/s)`
/// pairs labelled `label`, drawn over the measured deviation.
#[allow(dead_code)] // reason: `gyrocal allan` calls it; tests/plots.rs includes this file without it
pub fn write_allan_figure_with_prediction(
    analysis: &AllanAnalysis,
    prediction: &[(f64, f64)],
    label: &str,
    title: &str,
    dir: &Path,
    name: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    style::register_font()?;
    let plot = allan::AllanFigure::new(analysis, title)?.with_prediction(prediction, label)?;
    std::fs::create_dir_all(dir).map_err(|e| PlotError::write(dir, e))?;
    write_plot(&plot, allan::SIZE, dir, name)
}

/// Write a field scenario's figure into `dir` (created if missing) as
/// `name`.png and `name`.svg; returns the two files. Errors as
/// [`write_figures`]; the report is checked first.
#[allow(dead_code)] // reason: tests/plots.rs includes this module; `gyrocal field` calls it
pub fn write_field_figure(
    report: &gyrocal_sim::field::scenario::FieldReport,
    title: &str,
    dir: &Path,
    name: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    style::register_font()?;
    let plot = field::FieldPanel::new(report, title)?;
    std::fs::create_dir_all(dir).map_err(|e| PlotError::write(dir, e))?;
    write_plot(&plot, field::SIZE, dir, name)
}

/// Write a sweep's figure into `dir` (created if missing) as `name`.png
/// and `name`.svg; returns the two files. Errors as [`write_figures`]; the
/// report is checked first (at least one device finished).
#[allow(dead_code)] // reason: tests/plots.rs includes this module; `gyrocal sweep` calls it
pub fn write_sweep_figure(
    report: &gyrocal_sim::sweep::SweepReport,
    title: &str,
    dir: &Path,
    name: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    style::register_font()?;
    let plot = sweep::SweepFigure::new(report, title)?;
    std::fs::create_dir_all(dir).map_err(|e| PlotError::write(dir, e))?;
    write_plot(&plot, sweep::SIZE, dir, name)
}

/// Write the datasheet's figures into `dir` (created if missing):
/// `datasheet_adev`, `datasheet_nonlinearity` and, with `[drift]`,
/// `datasheet_temperature`, PNG and SVG; every figure is laid out (and
/// checked) before the first file is written.
#[allow(dead_code)] // reason: tests/plots.rs includes this module; `gyrocal datasheet` calls it
pub fn write_datasheet_figures(
    ds: &gyrocal_sim::datasheet::Datasheet,
    dir: &Path,
) -> Result<Vec<PathBuf>, PlotError> {
    style::register_font()?;
    let adev = datasheet::AdevFigure::new(ds)?;
    let nonlinearity = datasheet::XyFigure::nonlinearity(ds)?;
    let temperature = ds
        .temperature
        .as_ref()
        .map(datasheet::XyFigure::temperature)
        .transpose()?;
    std::fs::create_dir_all(dir).map_err(|e| PlotError::write(dir, e))?;
    let mut written = write_plot(&adev, datasheet::SIZE, dir, "datasheet_adev")?;
    written.extend(write_plot(
        &nonlinearity,
        datasheet::SIZE,
        dir,
        "datasheet_nonlinearity",
    )?);
    if let Some(t) = temperature {
        written.extend(write_plot(
            &t,
            datasheet::SIZE,
            dir,
            "datasheet_temperature",
        )?);
    }
    Ok(written)
}

/// `plot` as `dir/name.png` then `dir/name.svg`.
fn write_plot<P: Plot>(
    plot: &P,
    size: (u32, u32),
    dir: &Path,
    name: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    let png_path = dir.join(format!("{name}.png"));
    let drawing = |path: &Path| {
        let path = path.to_path_buf();
        move |e| PlotError::Drawing {
            path,
            error: Box::new(e),
        }
    };
    let png = render_png(plot, size).map_err(drawing(&png_path))?;
    write_atomic(&png_path, &png)?;
    let svg_path = dir.join(format!("{name}.svg"));
    let svg = render_svg(plot, size).map_err(drawing(&svg_path))?;
    write_atomic(&svg_path, svg.as_bytes())?;
    Ok(vec![png_path, svg_path])
}

/// Write `bytes` atomically (`gyrocal_verify::write_atomically`),
/// with the error as one line naming the file.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    gyrocal_verify::write_atomically(path, bytes).map_err(|e| PlotError::write(path, e))
}

fn render_png<P: Plot>(plot: &P, (w, h): (u32, u32)) -> Result<Vec<u8>, PlotError> {
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        plot.draw_on(&root)?;
        root.present().map_err(err)?;
    }
    let mut out = vec![];
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(err)?;
    writer.write_image_data(&rgb).map_err(err)?;
    writer.finish().map_err(err)?;
    Ok(out)
}

fn render_svg<P: Plot>(plot: &P, size: (u32, u32)) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        plot.draw_on(&root)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// A drawing backend's or encoder's error, as its message.
fn err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Backend(e.to_string())
}
