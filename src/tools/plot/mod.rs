//! Log-log plots of error against time, drawn with `plotters`.
//!
//! The benchmark commands compare methods by their error against run time,
//! one curve per method, on log-log axes. This module draws such a plot into
//! an [`image::RgbImage`] ([`render_log_log_plot`]) and writes it as a PNG
//! ([`write_log_log_plot`]): a white background, an axes box, light grey
//! gridlines at each power of ten with tick labels (and at 2x and 5x when the
//! axis spans less than two decades, and 3x below one decade), fainter lines
//! at the other multiples where a decade is wide enough, a coloured line with
//! square markers per series, dashed horizontal reference lines with their
//! labels, a legend in the corner the curves leave freest, axis labels and a
//! title. Text is set in DejaVu Sans (the `dejavu` crate embeds it), so the
//! plots look the same on every machine.
//!
//! `plotters` draws; this module chooses what to draw: the axis ranges
//! (whole or half decades around the data, [`axes`]), the ticks and their
//! labels, and where the legend goes.

mod axes;
mod legend;
#[cfg(test)]
mod tests;

use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use image::{ImageFormat, RgbImage};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use axes::*;
use legend::*;

/// One curve: a label for the legend and its points `(x, y)`. Points with
/// `x <= 0` or `y <= 0` or a non-finite coordinate are skipped (log axes);
/// the rest are joined in order of increasing `x`.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The legend entry.
    pub label: String,
    /// The data points `(x, y)`, in any order.
    pub points: Vec<(f64, f64)>,
}

/// An optional horizontal reference line (e.g. the error of "none @ 64 spp"),
/// drawn dashed across the plot with its label. A line with `y <= 0` or a
/// non-finite `y` is skipped.
#[derive(Clone, Debug, PartialEq)]
pub struct HLine {
    /// The text written above the line.
    pub label: String,
    /// The line's height in data units.
    pub y: f64,
}

/// Errors of drawing or writing a plot.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// No series has a point with positive, finite `x` and `y`.
    #[error("nothing to plot: no series has a point with positive, finite x and y")]
    NoData,
    /// The requested image is too small to hold the labels and a plot area.
    #[error("a {width}x{height} plot is too small; the minimum is {min_width}x{min_height}", min_width = MIN_PLOT_SIZE.0, min_height = MIN_PLOT_SIZE.1)]
    TooSmall {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
    },
    /// `plotters` failed to draw (or the embedded font failed to load).
    #[error("cannot draw the plot: {0}")]
    Draw(String),
    /// Encoding the PNG failed.
    #[error("cannot encode the plot as PNG: {0}")]
    Image(#[from] image::ImageError),
    /// Writing the PNG file failed.
    #[error("cannot write the plot to {}: {source}", path.display())]
    Io {
        /// The file that could not be written.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// Width and height in pixels of the plots [`write_log_log_plot`] writes.
pub const DEFAULT_PLOT_SIZE: (u32, u32) = (900, 600);

/// The smallest width and height in pixels a plot may have.
pub const MIN_PLOT_SIZE: (u32, u32) = (320, 240);

/// Writes a [`DEFAULT_PLOT_SIZE`] log-log plot of `series` (and the reference
/// lines `hlines`) to the PNG file `path`. The file is written under a
/// temporary name beside `path` and renamed into place, so a failed write
/// leaves no partial file.
pub fn write_log_log_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    hlines: &[HLine],
) -> Result<(), PlotError> {
    let image = render_log_log_plot(DEFAULT_PLOT_SIZE, title, x_label, y_label, series, hlines)?;
    let mut png = Cursor::new(Vec::new());
    image.write_to(&mut png, ImageFormat::Png)?;
    crate::util::files::write_file_atomically(path, png.get_ref())
        .map_err(|source| PlotError::Io { path: path.to_path_buf(), source })
}

/// Draws a log-log plot of `series` (and the reference lines `hlines`) into
/// an image of `size = (width, height)` pixels, at least [`MIN_PLOT_SIZE`].
/// Both axis ranges are the data's (the reference lines count for `y`)
/// widened to whole or half decades.
pub fn render_log_log_plot(
    size: (u32, u32),
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    hlines: &[HLine],
) -> Result<RgbImage, PlotError> {
    draw_log_log_plot(size, &Labels { title, x: x_label, y: y_label }, series, hlines).map(|(image, _)| image)
}

/// The title and axis labels of a plot.
struct Labels<'a> {
    title: &'a str,
    x: &'a str,
    y: &'a str,
}

/// Where the data ended up: the plot area in pixels (both ends inclusive)
/// and the axis ranges, so tests can predict where a point is drawn.
#[derive(Clone, Debug, PartialEq)]
struct Frame {
    x_pixels: (i32, i32),
    y_pixels: (i32, i32),
    x: Decades,
    y: Decades,
}

impl Frame {
    /// The pixel of the data point `(x, y)`; both must be positive.
    fn to_pixel(&self, (x, y): (f64, f64)) -> (i32, i32) {
        let along = |range: &Decades, (from, to): (i32, i32), value: f64| {
            from + (range.fraction_of_log(value.log10()) * f64::from(to - from)).round() as i32
        };
        (along(&self.x, self.x_pixels, x), along(&self.y, (self.y_pixels.1, self.y_pixels.0), y))
    }
}

const FONT: &str = "sans-serif";
const TITLE_FONT_SIZE: u32 = 22;
const AXIS_LABEL_FONT_SIZE: u32 = 18;
const TICK_FONT_SIZE: u32 = 16;
const LEGEND_FONT_SIZE: u32 = 16;
const HLINE_FONT_SIZE: u32 = 15;
const MARGIN: u32 = 16;
const X_LABEL_AREA: u32 = 56;
const Y_LABEL_AREA: u32 = 76;
/// Least spacing in pixels between labelled ticks.
const MIN_X_LABEL_SPACING: i32 = 80;
const MIN_Y_LABEL_SPACING: i32 = 40;
/// Least pixels per decade for the faint lines at 2x..9x.
const MIN_DECADE_PIXELS_FOR_MINOR_LINES: f64 = 60.0;

const TEXT_COLOUR: RGBColor = RGBColor(25, 25, 25);
const GRID_COLOUR: RGBColor = RGBColor(205, 205, 205);
const MINOR_GRID_COLOUR: RGBColor = RGBColor(236, 236, 236);
const HLINE_COLOUR: RGBColor = RGBColor(95, 95, 95);
const LINE_WIDTH: u32 = 2;
const MARKER_HALF_SIZE: i32 = 3;
const DASH: (u32, u32) = (8, 5);

/// Series colours as 0xRRGGBB (after matplotlib's "tab10"), reused in turn
/// when there are more series than colours.
const PALETTE: [u32; 8] = [0x1f77b4, 0xd62728, 0x2ca02c, 0xff7f0e, 0x9467bd, 0x8c564b, 0xe377c2, 0x17becf];

fn series_colour(index: usize) -> RGBColor {
    let [_, r, g, b] = PALETTE[index % PALETTE.len()].to_be_bytes();
    RGBColor(r, g, b)
}

/// Registers the embedded DejaVu Sans as the `sans-serif` family, once.
fn register_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED
        .get_or_init(|| plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok());
    ok.then_some(()).ok_or_else(|| PlotError::Draw("the embedded DejaVu Sans font does not load".into()))
}

fn draw_error<E: std::error::Error + Send + Sync>(error: DrawingAreaErrorKind<E>) -> PlotError {
    PlotError::Draw(error.to_string())
}

fn draw_log_log_plot(
    size: (u32, u32),
    labels: &Labels,
    series: &[Series],
    hlines: &[HLine],
) -> Result<(RgbImage, Frame), PlotError> {
    check_size(size)?;
    register_font()?;
    let curves: Vec<Vec<(f64, f64)>> = series.iter().map(|s| plottable_points(&s.points)).collect();
    let lines: Vec<&HLine> = hlines.iter().filter(|h| is_positive_finite(h.y)).collect();
    let bounds = DataBounds::of(&curves, &lines).ok_or(PlotError::NoData)?;
    let (x, y) = (Decades::padded(bounds.x_min, bounds.x_max), Decades::padded(bounds.y_min, bounds.y_max));
    let (width, height) = size;
    let mut pixels = vec![255u8; width as usize * height as usize * 3];
    let frame = {
        let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
        let frame = draw_into(&root, labels, (x, y), series, &curves, &lines)?;
        root.present().map_err(draw_error)?;
        frame
    };
    let image = RgbImage::from_raw(width, height, pixels).expect("the buffer holds width x height RGB pixels");
    Ok((image, frame))
}

fn draw_into<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    labels: &Labels,
    (x, y): (Decades, Decades),
    series: &[Series],
    curves: &[Vec<(f64, f64)>],
    lines: &[&HLine],
) -> Result<Frame, PlotError>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(draw_error)?;
    let (width, height) = root.dim_in_pixel();
    let plot_width = width.saturating_sub(Y_LABEL_AREA + 2 * MARGIN) as i32;
    let plot_height = height.saturating_sub(X_LABEL_AREA + TITLE_FONT_SIZE + 3 * MARGIN) as i32;
    let axis = |range: Decades, pixels: i32, spacing: i32| {
        let ticks = range.ticks(label_count(pixels, spacing, range));
        let minor = if f64::from(pixels) / range.decades() >= MIN_DECADE_PIXELS_FOR_MINOR_LINES {
            range.minor_values(&ticks)
        } else {
            Vec::new()
        };
        let values: Vec<f64> = ticks.iter().map(|t| t.value()).collect();
        (range.lo_value()..range.hi_value()).log_scale().with_key_points(values).with_light_points(minor)
    };
    let mut chart = ChartBuilder::on(root)
        .caption(labels.title, (FONT, TITLE_FONT_SIZE).into_font().color(&TEXT_COLOUR))
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(axis(x, plot_width, MIN_X_LABEL_SPACING), axis(y, plot_height, MIN_Y_LABEL_SPACING))
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style((FONT, TICK_FONT_SIZE).into_font().color(&TEXT_COLOUR))
        .axis_desc_style((FONT, AXIS_LABEL_FONT_SIZE).into_font().color(&TEXT_COLOUR))
        .bold_line_style(GRID_COLOUR)
        .light_line_style(MINOR_GRID_COLOUR)
        .axis_style(TEXT_COLOUR)
        .draw()
        .map_err(draw_error)?;
    let (x_pixels, y_pixels) = chart.plotting_area().get_pixel_range();
    let frame =
        Frame { x_pixels: (x_pixels.start, x_pixels.end - 1), y_pixels: (y_pixels.start, y_pixels.end - 1), x, y };

    let (x_lo, x_hi) = (x.lo_value(), x.hi_value());
    for line in lines {
        let style = HLINE_COLOUR.stroke_width(LINE_WIDTH);
        chart
            .draw_series(DashedLineSeries::new([(x_lo, line.y), (x_hi, line.y)], DASH.0, DASH.1, style))
            .map_err(draw_error)?;
        let text = TextStyle::from((FONT, HLINE_FONT_SIZE).into_font())
            .color(&HLINE_COLOUR)
            .pos(Pos::new(HPos::Right, VPos::Bottom));
        let label = EmptyElement::at((x_hi, line.y)) + Text::new(line.label.clone(), (-6, -4), text);
        chart.draw_series(std::iter::once(label)).map_err(draw_error)?;
    }
    for (index, (s, curve)) in series.iter().zip(curves).enumerate() {
        let colour = series_colour(index);
        let label = if curve.is_empty() { format!("{} (no data)", s.label) } else { s.label.clone() };
        chart
            .draw_series(LineSeries::new(curve.iter().copied(), colour.stroke_width(LINE_WIDTH)))
            .map_err(draw_error)?
            .label(label)
            .legend(move |(px, py)| {
                EmptyElement::at((px, py))
                    + PathElement::new([(0, 0), (24, 0)], colour.stroke_width(LINE_WIDTH))
                    + square(colour, (12, 0))
            });
        chart.draw_series(curve.iter().map(|&p| EmptyElement::at(p) + square(colour, (0, 0)))).map_err(draw_error)?;
    }
    let legend_font = (FONT, LEGEND_FONT_SIZE).into_font().color(&TEXT_COLOUR);
    let widest = series
        .iter()
        .map(|s| root.estimate_text_size(&format!("{} (no data)", s.label), &legend_font).map_or(0, |(w, _)| w))
        .max()
        .unwrap_or(0);
    let size = legend_size(widest, series.len(), LEGEND_FONT_SIZE);
    let corner = legend_corner(&frame, size, &occupied_pixels(&frame, curves, lines));
    chart
        .configure_series_labels()
        .position(legend_position(corner))
        .label_font(legend_font)
        .background_style(WHITE)
        .border_style(RGBColor(150, 150, 150))
        .margin(LEGEND_MARGIN)
        .legend_area_size(LEGEND_SAMPLE)
        .draw()
        .map_err(draw_error)?;
    Ok(frame)
}

/// A filled square marker centred `offset` pixels from where it is placed.
fn square(colour: RGBColor, (dx, dy): (i32, i32)) -> Rectangle<(i32, i32)> {
    let h = MARKER_HALF_SIZE;
    Rectangle::new([(dx - h, dy - h), (dx + h, dy + h)], colour.filled())
}

/// The tick label of a value that [`Decades::ticks`] produced.
fn tick_label(value: f64) -> String {
    Tick::nearest(value).label()
}

fn check_size((width, height): (u32, u32)) -> Result<(), PlotError> {
    if width < MIN_PLOT_SIZE.0 || height < MIN_PLOT_SIZE.1 {
        return Err(PlotError::TooSmall { width, height });
    }
    Ok(())
}

fn is_positive_finite(value: f64) -> bool {
    value.is_finite() && value > 0.0
}

/// The points a log-log plot can show, sorted by `x`.
fn plottable_points(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut kept: Vec<(f64, f64)> =
        points.iter().copied().filter(|&(x, y)| is_positive_finite(x) && is_positive_finite(y)).collect();
    kept.sort_by(|a, b| a.0.total_cmp(&b.0));
    kept
}
