//! Shared look of the figures: the embedded font, colours, text styles,
//! the title block and the choice of a free corner for a legend.

use super::error::PlotError;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::sync::OnceLock;

use super::err;
use super::format::tick_formatter;
use plotters::coord::types::RangedCoordf64;

/// DejaVu Sans, Latin-1, Greek and a few symbols (see assets/fonts/README.md).
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");
/// The family every text style names.
const FAMILY: &str = "sans-serif";

/// Colours of output 1 and output 2.
pub(super) const OUT_COLOR: [RGBColor; 2] = [RGBColor(31, 119, 180), RGBColor(214, 39, 40)];
pub(super) const GREY: RGBColor = RGBColor(110, 110, 110);
pub(super) const LIGHT: RGBColor = RGBColor(225, 225, 225);
/// Unit of a scale factor.
pub(super) const SF_UNIT: &str = "(m²/s²)/(°/s)";

pub(super) fn register_font() -> Result<(), PlotError> {
    static DONE: OnceLock<Result<(), PlotError>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).map_err(|_| PlotError::Font)
    })
    .clone()
}

pub(super) fn text_style(size: u32) -> TextStyle<'static> {
    (FAMILY, size).into_font().color(&BLACK)
}

/// Title (and subtitle) across the top; returns the area below.
pub(super) fn header<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    subtitle: &str,
) -> Result<DrawingArea<DB, Shift>, PlotError> {
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
pub(super) fn free_corner(pts: &[(f64, f64)], w: f64, h: f64) -> Option<SeriesLabelPosition> {
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

/// The legend of a chart's labelled series at `position`: `margin` px from
/// the plot's edge, text of `font` px, on a 90% white ground with a light
/// border (the legend of every figure but the field's two).
pub(super) fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    (margin, font): (u32, u32),
) -> Result<(), PlotError> {
    chart
        .configure_series_labels()
        .position(position)
        .margin(margin)
        .label_font(text_style(font))
        .background_style(WHITE.mix(0.9))
        .border_style(LIGHT)
        .draw()
        .map_err(err)
}

/// A panel's chart builder (the readout and calibration lines, the
/// residuals, the staircase): the caption at 17 px, 12 px margins but 24
/// on the right, an 80 px y label area and `x_label_area` px for x.
pub(super) fn panel_builder<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    x_label_area: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(caption, text_style(17))
        .margin(12)
        .margin_right(24)
        .x_label_area_size(x_label_area)
        .y_label_area_size(80);
    builder
}

/// A panel's mesh: light bold lines only, the axes described by `desc`
/// (x, y), `labels` ticks (x, y) formatted for the axes' spans, the
/// descriptions and tick labels at `fonts` px.
pub(super) fn draw_panel_mesh<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    desc: (&str, &str),
    labels: (usize, usize),
    fonts: (u32, u32),
) -> Result<(), PlotError> {
    let (x, y) = (chart.x_range(), chart.y_range());
    chart
        .configure_mesh()
        .max_light_lines(0)
        .bold_line_style(LIGHT)
        .x_desc(desc.0)
        .y_desc(desc.1)
        .axis_desc_style(text_style(fonts.0))
        .label_style(text_style(fonts.1))
        .x_labels(labels.0)
        .y_labels(labels.1)
        .x_label_formatter(&tick_formatter(x.end - x.start))
        .y_label_formatter(&tick_formatter(y.end - y.start))
        .draw()
        .map_err(err)
}
