//! Log-log plots of error against time, drawn without a plotting library.
//!
//! The benchmark commands compare methods by their error against run time,
//! one curve per method, on log-log axes. This module draws such a plot into
//! an [`image::RgbImage`] ([`render_log_log_plot`]) and writes it as a PNG
//! ([`write_log_log_plot`]): a white background, an axes box, light grey
//! gridlines at each power of ten with tick labels (and at 2x and 5x when the
//! axis spans less than two decades, and 3x below one decade), a coloured line with square markers per
//! series, dashed horizontal reference lines, a legend, axis labels and a
//! title. All text is lettered in a built-in 5x7 bitmap font covering
//! printable ASCII; any other character is drawn as `?`.

mod axes;
mod draw;
mod font;
#[cfg(test)]
mod tests;

use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::{ImageFormat, RgbImage};

use axes::*;
use draw::*;
use font::*;

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
    write_log_log_plot_sized(path, DEFAULT_PLOT_SIZE, title, x_label, y_label, series, hlines)
}

/// Like [`write_log_log_plot`] with an image of `size = (width, height)`
/// pixels, at least [`MIN_PLOT_SIZE`].
pub fn write_log_log_plot_sized(
    path: &Path,
    size: (u32, u32),
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    hlines: &[HLine],
) -> Result<(), PlotError> {
    let image = render_log_log_plot(size, title, x_label, y_label, series, hlines)?;
    let mut png = Cursor::new(Vec::new());
    image.write_to(&mut png, ImageFormat::Png)?;
    write_file_atomically(path, png.get_ref())
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
    check_size(size)?;
    let curves: Vec<Vec<(f64, f64)>> = series.iter().map(|s| plottable_points(&s.points)).collect();
    let lines: Vec<&HLine> = hlines.iter().filter(|h| is_positive_finite(h.y)).collect();
    let bounds = DataBounds::of(&curves, &lines).ok_or(PlotError::NoData)?;
    let layout = Layout::new(size, &bounds);
    let mut canvas = Canvas::new(size);
    draw_grid(&mut canvas, &layout);
    draw_hlines(&mut canvas, &layout, &lines);
    for (index, curve) in curves.iter().enumerate() {
        draw_curve(&mut canvas, &layout, curve, series_colour(index));
    }
    canvas.stroke_rect(layout.plot, AXES_COLOUR);
    draw_ticks(&mut canvas, &layout);
    draw_tick_labels(&mut canvas, &layout);
    draw_title_and_axis_labels(&mut canvas, &layout, title, x_label, y_label);
    let label_boxes = draw_hline_labels(&mut canvas, &layout, &lines);
    draw_legend(&mut canvas, &layout, series, &curves, &label_boxes);
    Ok(canvas.image)
}

fn check_size((width, height): (u32, u32)) -> Result<(), PlotError> {
    if width < MIN_PLOT_SIZE.0 || height < MIN_PLOT_SIZE.1 {
        return Err(PlotError::TooSmall { width, height });
    }
    Ok(())
}

fn write_file_atomically(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    crate::output::write_file_atomically(path, bytes)
        .map_err(|source| PlotError::Io { path: path.to_path_buf(), source })
}

// ---------------------------------------------------------------------------
// Data and axes
// ---------------------------------------------------------------------------

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
