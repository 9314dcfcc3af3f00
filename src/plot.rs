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

use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::{ImageFormat, Rgb, RgbImage};

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
    let io_error = |source| PlotError::Io { path: path.to_path_buf(), source };
    let name = path
        .file_name()
        .ok_or_else(|| io_error(std::io::Error::new(std::io::ErrorKind::InvalidInput, "the path has no file name")))?;
    let temporary = path.with_file_name(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id()));
    let result = std::fs::write(&temporary, bytes).and_then(|()| std::fs::rename(&temporary, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result.map_err(io_error)
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

/// The extent of the data in data units.
#[derive(Clone, Copy, Debug, PartialEq)]
struct DataBounds {
    x_min: f64,
    x_max: f64,
    y_min: f64,
    y_max: f64,
}

impl DataBounds {
    /// The bounds of all curve points and reference lines; `None` without a
    /// single curve point (reference lines alone give no `x` range).
    fn of(curves: &[Vec<(f64, f64)>], lines: &[&HLine]) -> Option<Self> {
        let mut points = curves.iter().flatten();
        let &(x, y) = points.next()?;
        let mut bounds = DataBounds { x_min: x, x_max: x, y_min: y, y_max: y };
        for &(x, y) in points {
            bounds.x_min = bounds.x_min.min(x);
            bounds.x_max = bounds.x_max.max(x);
            bounds.include_y(y);
        }
        for line in lines {
            bounds.include_y(line.y);
        }
        Some(bounds)
    }

    fn include_y(&mut self, y: f64) {
        self.y_min = self.y_min.min(y);
        self.y_max = self.y_max.max(y);
    }
}

/// How close (in decades) data may come to the end of an axis before the
/// axis is widened by another half decade.
const AXIS_MARGIN_DECADES: f64 = 0.02;

/// Slack for comparing tick positions with the axis ends.
const LOG_EPSILON: f64 = 1e-9;

/// An axis range in decades: `lo` and `hi` are base-10 logarithms.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LogRange {
    lo: f64,
    hi: f64,
}

impl LogRange {
    /// The smallest range of whole or half decades holding `[min, max]` with
    /// a little margin; never empty.
    fn padded(min: f64, max: f64) -> Self {
        let lo = ((min.log10() - AXIS_MARGIN_DECADES) * 2.0).floor() / 2.0;
        let hi = ((max.log10() + AXIS_MARGIN_DECADES) * 2.0).ceil() / 2.0;
        if hi > lo {
            LogRange { lo, hi }
        } else {
            LogRange { lo: lo - 0.5, hi: lo + 0.5 }
        }
    }

    fn decades(&self) -> f64 {
        self.hi - self.lo
    }

    fn contains_log(&self, log: f64) -> bool {
        log >= self.lo - LOG_EPSILON && log <= self.hi + LOG_EPSILON
    }

    /// Where `log` (a base-10 logarithm) lies along the range, 0 at `lo` and
    /// 1 at `hi`.
    fn fraction_of_log(&self, log: f64) -> f64 {
        (log - self.lo) / self.decades()
    }

    /// The powers of ten whose exponents lie within the range.
    fn decade_exponents(&self) -> impl Iterator<Item = i32> + '_ {
        let first = self.lo.floor() as i32;
        let last = self.hi.ceil() as i32;
        (first..=last).filter(|&e| self.contains_log(f64::from(e)))
    }

    /// The multiples of each power of ten that get a labelled tick: 1, 2 and
    /// 5 when the range spans less than two decades (and 3 too below one
    /// decade), else 1 alone.
    fn tick_mantissas(&self) -> &'static [u8] {
        match self.decades() {
            d if d < 1.0 => &[1, 2, 3, 5],
            d if d < 2.0 => &[1, 2, 5],
            _ => &[1],
        }
    }

    /// Labelled ticks at [`Self::tick_mantissas`] times each power of ten, or
    /// at every `step`-th power of ten when more than `max_labels` decades
    /// would be crowded.
    fn ticks(&self, max_labels: usize) -> Vec<Tick> {
        let mantissas = self.tick_mantissas();
        let step = decade_step(self.decades(), max_labels);
        let first = self.lo.floor() as i32;
        let last = self.hi.ceil() as i32;
        (first..=last)
            .filter(|e| e.rem_euclid(step) == 0)
            .flat_map(|exponent| mantissas.iter().map(move |&mantissa| Tick { mantissa, exponent }))
            .filter(|tick| self.contains_log(tick.log10()))
            .collect()
    }
}

/// Every how many decades to label so that at most about `max_labels` fit.
fn decade_step(decades: f64, max_labels: usize) -> i32 {
    let per_label = (decades / max_labels.max(1) as f64).ceil();
    per_label.clamp(1.0, f64::from(i32::MAX)) as i32
}

/// A labelled tick at `mantissa * 10^exponent`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Tick {
    mantissa: u8,
    exponent: i32,
}

impl Tick {
    fn log10(self) -> f64 {
        f64::from(self.exponent) + f64::from(self.mantissa).log10()
    }

    fn is_decade(self) -> bool {
        self.mantissa == 1
    }

    /// Plain decimals from 0.01 to 5000 ("0.05", "10"), else short
    /// scientific notation ("1e-3", "2e4").
    fn label(self) -> String {
        let zeros = |count: u32| "0".repeat(count as usize);
        match self.exponent {
            0..=3 => format!("{}{}", self.mantissa, zeros(self.exponent.unsigned_abs())),
            -2..=-1 => format!("0.{}{}", zeros(self.exponent.unsigned_abs() - 1), self.mantissa),
            _ => format!("{}e{}", self.mantissa, self.exponent),
        }
    }
}

/// An axis-aligned rectangle of pixels; all four edges are inclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rect {
    left: i32,
    top: i32,
    right: i32,
    bottom: i32,
}

impl Rect {
    fn with_size(left: i32, top: i32, width: i32, height: i32) -> Self {
        Rect { left, top, right: left + width - 1, bottom: top + height - 1 }
    }

    fn contains(&self, (x, y): (i32, i32)) -> bool {
        (self.left..=self.right).contains(&x) && (self.top..=self.bottom).contains(&y)
    }

    fn width(&self) -> i32 {
        self.right - self.left + 1
    }

    fn height(&self) -> i32 {
        self.bottom - self.top + 1
    }
}

const TICK_SCALE: i32 = 2;
const LABEL_SCALE: i32 = 2;
const TITLE_SCALE: i32 = 3;
const OUTER_PAD: i32 = 12;
const TICK_LENGTH: i32 = 6;
const MINOR_TICK_LENGTH: i32 = 3;
const TICK_LABEL_GAP: i32 = 5;
const AXIS_LABEL_GAP: i32 = 10;
const RIGHT_MARGIN: i32 = 34;
/// Least spacing between labelled decades, in pixels.
const MIN_X_LABEL_SPACING: i32 = 80;
const MIN_Y_LABEL_SPACING: i32 = 40;
/// Least pixels per decade for unlabelled decade gridlines and minor ticks.
const MIN_DECADE_PIXELS_FOR_GRID: f64 = 8.0;
const MIN_DECADE_PIXELS_FOR_MINOR_TICKS: f64 = 40.0;

/// Where the plot area lies in the image, and the axes' ranges and ticks.
#[derive(Clone, Debug, PartialEq)]
struct Layout {
    size: (i32, i32),
    plot: Rect,
    x: LogRange,
    y: LogRange,
    x_ticks: Vec<Tick>,
    y_ticks: Vec<Tick>,
}

impl Layout {
    fn new(size: (u32, u32), bounds: &DataBounds) -> Self {
        let (width, height) = (to_i32(size.0), to_i32(size.1));
        let x = LogRange::padded(bounds.x_min, bounds.x_max);
        let y = LogRange::padded(bounds.y_min, bounds.y_max);
        let top = OUTER_PAD + text_height(TITLE_SCALE) + OUTER_PAD;
        let bottom_margin = TICK_LENGTH
            + TICK_LABEL_GAP
            + text_height(TICK_SCALE)
            + AXIS_LABEL_GAP
            + text_height(LABEL_SCALE)
            + OUTER_PAD;
        let plot_height = height - top - bottom_margin;
        let y_ticks = y.ticks(label_count(plot_height, MIN_Y_LABEL_SPACING, y));
        let widest_y_label = y_ticks.iter().map(|t| text_width(&t.label(), TICK_SCALE)).max().unwrap_or(0);
        let left =
            OUTER_PAD + text_height(LABEL_SCALE) + AXIS_LABEL_GAP + widest_y_label + TICK_LABEL_GAP + TICK_LENGTH;
        let plot_width = width - left - RIGHT_MARGIN;
        let x_ticks = x.ticks(label_count(plot_width, MIN_X_LABEL_SPACING, x));
        let plot = Rect::with_size(left, top, plot_width, plot_height);
        Layout { size: (width, height), plot, x, y, x_ticks, y_ticks }
    }

    fn x_pixel_of_log(&self, log: f64) -> i32 {
        let span = f64::from(self.plot.right - self.plot.left);
        self.plot.left + (self.x.fraction_of_log(log) * span).round() as i32
    }

    fn y_pixel_of_log(&self, log: f64) -> i32 {
        let span = f64::from(self.plot.bottom - self.plot.top);
        self.plot.bottom - (self.y.fraction_of_log(log) * span).round() as i32
    }

    /// The pixel of the data point `(x, y)`; both must be positive.
    fn to_pixel(&self, (x, y): (f64, f64)) -> (i32, i32) {
        (self.x_pixel_of_log(x.log10()), self.y_pixel_of_log(y.log10()))
    }

    fn pixels_per_x_decade(&self) -> f64 {
        f64::from(self.plot.width()) / self.x.decades()
    }

    fn pixels_per_y_decade(&self) -> f64 {
        f64::from(self.plot.height()) / self.y.decades()
    }
}

/// How many decade labels fit along `pixels` at `spacing` apart, judged by
/// the label count per decade of `range`.
fn label_count(pixels: i32, spacing: i32, range: LogRange) -> usize {
    let fitting = usize::try_from((pixels / spacing.max(1)).max(2)).unwrap_or(2);
    (fitting / range.tick_mantissas().len()).max(1)
}

fn to_i32(value: u32) -> i32 {
    i32::try_from(value).unwrap_or(i32::MAX)
}

// ---------------------------------------------------------------------------
// Colours
// ---------------------------------------------------------------------------

type Colour = Rgb<u8>;

const BACKGROUND: Colour = Rgb([255, 255, 255]);
const TEXT_COLOUR: Colour = Rgb([25, 25, 25]);
const AXES_COLOUR: Colour = Rgb([40, 40, 40]);
const DECADE_GRID_COLOUR: Colour = Rgb([205, 205, 205]);
const MINOR_GRID_COLOUR: Colour = Rgb([232, 232, 232]);
const HLINE_COLOUR: Colour = Rgb([95, 95, 95]);
const LEGEND_BORDER_COLOUR: Colour = Rgb([150, 150, 150]);

/// Series colours (after matplotlib's "tab10"), reused in turn when there
/// are more series than colours.
const PALETTE: [Colour; 8] = [
    Rgb([31, 119, 180]),
    Rgb([214, 39, 40]),
    Rgb([44, 160, 44]),
    Rgb([255, 127, 14]),
    Rgb([148, 103, 189]),
    Rgb([140, 86, 75]),
    Rgb([227, 119, 194]),
    Rgb([23, 190, 207]),
];

fn series_colour(index: usize) -> Colour {
    PALETTE[index % PALETTE.len()]
}

// ---------------------------------------------------------------------------
// Canvas: clipped pixel drawing
// ---------------------------------------------------------------------------

const LINE_THICKNESS: i32 = 2;
const MARKER_HALF_SIZE: i32 = 3;
const DASH_LENGTH: i32 = 8;
const DASH_GAP: i32 = 5;

/// An image with drawing operations that ignore pixels outside it.
struct Canvas {
    image: RgbImage,
}

impl Canvas {
    fn new((width, height): (u32, u32)) -> Self {
        Canvas { image: RgbImage::from_pixel(width, height, BACKGROUND) }
    }

    fn put(&mut self, x: i32, y: i32, colour: Colour) {
        let (Ok(x), Ok(y)) = (u32::try_from(x), u32::try_from(y)) else { return };
        if x < self.image.width() && y < self.image.height() {
            self.image.put_pixel(x, y, colour);
        }
    }

    fn fill_rect(&mut self, rect: Rect, colour: Colour) {
        for y in rect.top..=rect.bottom {
            for x in rect.left..=rect.right {
                self.put(x, y, colour);
            }
        }
    }

    fn stroke_rect(&mut self, rect: Rect, colour: Colour) {
        self.fill_rect(Rect { bottom: rect.top, ..rect }, colour);
        self.fill_rect(Rect { top: rect.bottom, ..rect }, colour);
        self.fill_rect(Rect { right: rect.left, ..rect }, colour);
        self.fill_rect(Rect { left: rect.right, ..rect }, colour);
    }

    fn thick_dot(&mut self, x: i32, y: i32, colour: Colour) {
        self.fill_rect(Rect::with_size(x, y, LINE_THICKNESS, LINE_THICKNESS), colour);
    }

    /// A line `LINE_THICKNESS` pixels thick, by Bresenham's algorithm.
    fn line(&mut self, from: (i32, i32), to: (i32, i32), colour: Colour) {
        let (mut x, mut y) = from;
        let (dx, step_x) = ((to.0 - x).abs(), if x < to.0 { 1 } else { -1 });
        let (dy, step_y) = (-(to.1 - y).abs(), if y < to.1 { 1 } else { -1 });
        let mut error = dx + dy;
        loop {
            self.thick_dot(x, y, colour);
            if (x, y) == to {
                break;
            }
            let doubled = 2 * error;
            if doubled >= dy {
                error += dy;
                x += step_x;
            }
            if doubled <= dx {
                error += dx;
                y += step_y;
            }
        }
    }

    fn dashed_horizontal_line(&mut self, left: i32, right: i32, y: i32, colour: Colour) {
        for x in left..=right {
            if (x - left) % (DASH_LENGTH + DASH_GAP) < DASH_LENGTH {
                self.fill_rect(Rect::with_size(x, y, 1, LINE_THICKNESS), colour);
            }
        }
    }

    fn marker(&mut self, (x, y): (i32, i32), colour: Colour) {
        let size = 2 * MARKER_HALF_SIZE + 1;
        self.fill_rect(Rect::with_size(x - MARKER_HALF_SIZE, y - MARKER_HALF_SIZE, size, size), colour);
    }

    /// Letters `text` with its top left corner at `(x, y)`.
    fn text(&mut self, text: &str, (x, y): (i32, i32), scale: i32, colour: Colour) {
        for (column, row) in text_pixels(text) {
            self.fill_rect(Rect::with_size(x + column * scale, y + row * scale, scale, scale), colour);
        }
    }

    /// Letters `text` turned a quarter turn anticlockwise, reading upwards;
    /// `(x, y)` is the bottom left corner of the turned text.
    fn text_upwards(&mut self, text: &str, (x, y): (i32, i32), scale: i32, colour: Colour) {
        for (column, row) in text_pixels(text) {
            self.fill_rect(Rect::with_size(x + row * scale, y - (column + 1) * scale + 1, scale, scale), colour);
        }
    }

    /// Letters `text` over a one pixel white outline, legible over lines.
    fn text_with_halo(&mut self, text: &str, (x, y): (i32, i32), scale: i32, colour: Colour) {
        for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
            self.text(text, (x + dx, y + dy), scale, BACKGROUND);
        }
        self.text(text, (x, y), scale, colour);
    }
}

// ---------------------------------------------------------------------------
// Plot elements
// ---------------------------------------------------------------------------

fn draw_vertical_gridline(canvas: &mut Canvas, layout: &Layout, x: i32, colour: Colour) {
    canvas.fill_rect(Rect { left: x, right: x, ..layout.plot }, colour);
}

fn draw_horizontal_gridline(canvas: &mut Canvas, layout: &Layout, y: i32, colour: Colour) {
    canvas.fill_rect(Rect { top: y, bottom: y, ..layout.plot }, colour);
}

/// Light grid lines at the labelled 2x and 5x ticks, then darker ones at
/// the decades (all decades when they are far enough apart).
fn draw_grid(canvas: &mut Canvas, layout: &Layout) {
    for tick in layout.x_ticks.iter().filter(|t| !t.is_decade()) {
        draw_vertical_gridline(canvas, layout, layout.x_pixel_of_log(tick.log10()), MINOR_GRID_COLOUR);
    }
    for tick in layout.y_ticks.iter().filter(|t| !t.is_decade()) {
        draw_horizontal_gridline(canvas, layout, layout.y_pixel_of_log(tick.log10()), MINOR_GRID_COLOUR);
    }
    for exponent in gridline_decades(layout.x, &layout.x_ticks, layout.pixels_per_x_decade()) {
        draw_vertical_gridline(canvas, layout, layout.x_pixel_of_log(f64::from(exponent)), DECADE_GRID_COLOUR);
    }
    for exponent in gridline_decades(layout.y, &layout.y_ticks, layout.pixels_per_y_decade()) {
        draw_horizontal_gridline(canvas, layout, layout.y_pixel_of_log(f64::from(exponent)), DECADE_GRID_COLOUR);
    }
}

/// The decades that get a gridline: all of them, or only the labelled ones
/// when decades are too close together.
fn gridline_decades(range: LogRange, ticks: &[Tick], pixels_per_decade: f64) -> Vec<i32> {
    let every_decade = pixels_per_decade >= MIN_DECADE_PIXELS_FOR_GRID;
    let labelled = |e: &i32| ticks.iter().any(|t| t.is_decade() && t.exponent == *e);
    range.decade_exponents().filter(|e| every_decade || labelled(e)).collect()
}

/// Tick marks below and left of the axes box: long at labelled ticks,
/// short at unlabelled 2x..9x values when decades are wide enough.
fn draw_ticks(canvas: &mut Canvas, layout: &Layout) {
    let plot = layout.plot;
    let x_mark = |x: i32, length: i32| Rect { left: x, right: x, top: plot.bottom + 1, bottom: plot.bottom + length };
    let y_mark = |y: i32, length: i32| Rect { top: y, bottom: y, left: plot.left - length, right: plot.left - 1 };
    for log in minor_tick_logs(layout.x, &layout.x_ticks, layout.pixels_per_x_decade()) {
        canvas.fill_rect(x_mark(layout.x_pixel_of_log(log), MINOR_TICK_LENGTH), AXES_COLOUR);
    }
    for log in minor_tick_logs(layout.y, &layout.y_ticks, layout.pixels_per_y_decade()) {
        canvas.fill_rect(y_mark(layout.y_pixel_of_log(log), MINOR_TICK_LENGTH), AXES_COLOUR);
    }
    for tick in &layout.x_ticks {
        canvas.fill_rect(x_mark(layout.x_pixel_of_log(tick.log10()), TICK_LENGTH), AXES_COLOUR);
    }
    for tick in &layout.y_ticks {
        canvas.fill_rect(y_mark(layout.y_pixel_of_log(tick.log10()), TICK_LENGTH), AXES_COLOUR);
    }
}

/// Logarithms of the unlabelled values 2..9 times a power of ten within
/// `range`, or none when decades are too narrow to show them.
fn minor_tick_logs(range: LogRange, ticks: &[Tick], pixels_per_decade: f64) -> Vec<f64> {
    if pixels_per_decade < MIN_DECADE_PIXELS_FOR_MINOR_TICKS {
        return Vec::new();
    }
    let first = range.lo.floor() as i32;
    let last = range.hi.ceil() as i32;
    let labelled = |e: i32, m: u8| ticks.iter().any(|t| t.exponent == e && t.mantissa == m);
    (first..=last)
        .flat_map(|e| (2..=9u8).filter(move |&m| !labelled(e, m)).map(move |m| f64::from(e) + f64::from(m).log10()))
        .filter(|&log| range.contains_log(log))
        .collect()
}

fn draw_tick_labels(canvas: &mut Canvas, layout: &Layout) {
    let label_top = layout.plot.bottom + TICK_LENGTH + TICK_LABEL_GAP;
    for tick in &layout.x_ticks {
        let label = tick.label();
        let x = layout.x_pixel_of_log(tick.log10()) - text_width(&label, TICK_SCALE) / 2;
        canvas.text(&label, (x, label_top), TICK_SCALE, TEXT_COLOUR);
    }
    let label_right = layout.plot.left - TICK_LENGTH - TICK_LABEL_GAP;
    for tick in &layout.y_ticks {
        let label = tick.label();
        let y = layout.y_pixel_of_log(tick.log10()) - text_height(TICK_SCALE) / 2;
        canvas.text(&label, (label_right - text_width(&label, TICK_SCALE), y), TICK_SCALE, TEXT_COLOUR);
    }
}

fn draw_title_and_axis_labels(canvas: &mut Canvas, layout: &Layout, title: &str, x_label: &str, y_label: &str) {
    let (width, height) = layout.size;
    let title_scale = largest_scale_fitting(title, width - 2 * OUTER_PAD, TITLE_SCALE);
    let title_x = (width - text_width(title, title_scale)) / 2;
    let title_y = OUTER_PAD + (text_height(TITLE_SCALE) - text_height(title_scale)) / 2;
    canvas.text(title, (title_x, title_y), title_scale, TEXT_COLOUR);

    let plot = layout.plot;
    let x_label_x = plot.left + (plot.width() - text_width(x_label, LABEL_SCALE)) / 2;
    canvas.text(x_label, (x_label_x, height - OUTER_PAD - text_height(LABEL_SCALE)), LABEL_SCALE, TEXT_COLOUR);

    let y_label_bottom = plot.top + (plot.height() + text_width(y_label, LABEL_SCALE)) / 2;
    canvas.text_upwards(y_label, (OUTER_PAD, y_label_bottom), LABEL_SCALE, TEXT_COLOUR);
}

/// `preferred` or a smaller scale at which `text` fits in `width`; at least 1.
fn largest_scale_fitting(text: &str, width: i32, preferred: i32) -> i32 {
    (1..=preferred).rev().find(|&scale| text_width(text, scale) <= width).unwrap_or(1)
}

fn draw_hlines(canvas: &mut Canvas, layout: &Layout, lines: &[&HLine]) {
    for line in lines {
        let y = layout.y_pixel_of_log(line.y.log10());
        canvas.dashed_horizontal_line(layout.plot.left + 1, layout.plot.right - 1, y, HLINE_COLOUR);
    }
}

/// Where the label of the reference line at pixel row `y` goes: right
/// aligned in the plot, just above the line, or below it near the top.
fn hline_label_box(layout: &Layout, label: &str, y: i32) -> Rect {
    let (width, height) = (text_width(label, LABEL_SCALE), text_height(LABEL_SCALE));
    let left = layout.plot.right - 6 - width;
    let above = y - 3 - text_descent(LABEL_SCALE) - height;
    let top = if above > layout.plot.top + 2 { above } else { y + LINE_THICKNESS + 4 };
    Rect::with_size(left, top, width, height)
}

/// Letters each reference line's label and returns the boxes they cover.
fn draw_hline_labels(canvas: &mut Canvas, layout: &Layout, lines: &[&HLine]) -> Vec<Rect> {
    let mut boxes = Vec::new();
    for line in lines {
        let y = layout.y_pixel_of_log(line.y.log10());
        let label_box = hline_label_box(layout, &line.label, y);
        canvas.text_with_halo(&line.label, (label_box.left, label_box.top), LABEL_SCALE, HLINE_COLOUR);
        boxes.push(label_box);
    }
    boxes
}

fn draw_curve(canvas: &mut Canvas, layout: &Layout, points: &[(f64, f64)], colour: Colour) {
    let pixels: Vec<(i32, i32)> = points.iter().map(|&p| layout.to_pixel(p)).collect();
    for pair in pixels.windows(2) {
        canvas.line(pair[0], pair[1], colour);
    }
    for &pixel in &pixels {
        canvas.marker(pixel, colour);
    }
}

// ---------------------------------------------------------------------------
// Legend
// ---------------------------------------------------------------------------

const LEGEND_PAD: i32 = 8;
const LEGEND_INSET: i32 = 10;
const LEGEND_SAMPLE_LENGTH: i32 = 28;
const LEGEND_ROW_GAP: i32 = 8;
/// Spacing in pixels of the samples taken along curves to find free space.
const OCCUPANCY_SAMPLE_SPACING: f64 = 3.0;
/// Spacing in pixels of the samples taken over label boxes.
const LABEL_SAMPLE_STEP: usize = 3;

/// The legend entries: every series, noting those without plottable points.
fn legend_entries(series: &[Series], curves: &[Vec<(f64, f64)>]) -> Vec<(String, Colour)> {
    let label = |s: &Series, curve: &[(f64, f64)]| {
        if curve.is_empty() {
            format!("{} (no data)", s.label)
        } else {
            s.label.clone()
        }
    };
    series.iter().zip(curves).enumerate().map(|(index, (s, curve))| (label(s, curve), series_colour(index))).collect()
}

fn legend_size(entries: &[(String, Colour)]) -> (i32, i32) {
    let widest = entries.iter().map(|(label, _)| text_width(label, LABEL_SCALE)).max().unwrap_or(0);
    let rows = i32::try_from(entries.len()).unwrap_or(i32::MAX);
    let row_height = text_height(LABEL_SCALE) + LEGEND_ROW_GAP;
    let width = LEGEND_PAD + LEGEND_SAMPLE_LENGTH + LEGEND_PAD + widest + LEGEND_PAD;
    (width, 2 * LEGEND_PAD + rows * row_height - LEGEND_ROW_GAP)
}

/// The legend box in the corner of the plot covering the fewest curve and
/// label pixels; top right, top left, bottom left, bottom right on ties.
fn legend_box(layout: &Layout, size: (i32, i32), occupied: &[(i32, i32)]) -> Rect {
    let plot = layout.plot;
    let (left, right) = (plot.left + LEGEND_INSET, plot.right - LEGEND_INSET - size.0 + 1);
    let (top, bottom) = (plot.top + LEGEND_INSET, plot.bottom - LEGEND_INSET - size.1 + 1);
    let corners = [(right, top), (left, top), (left, bottom), (right, bottom)];
    let boxes = corners.map(|(x, y)| Rect::with_size(x, y, size.0, size.1));
    let covered = |rect: &Rect| occupied.iter().filter(|&&p| rect.contains(p)).count();
    boxes.into_iter().min_by_key(covered).unwrap_or(boxes[0])
}

/// Pixels along every curve and inside every label box, for placing the legend.
fn occupied_pixels(layout: &Layout, curves: &[Vec<(f64, f64)>], label_boxes: &[Rect]) -> Vec<(i32, i32)> {
    let mut pixels = Vec::new();
    for curve in curves {
        let corners: Vec<(i32, i32)> = curve.iter().map(|&p| layout.to_pixel(p)).collect();
        pixels.extend_from_slice(&corners);
        for pair in corners.windows(2) {
            pixels.extend(samples_along(pair[0], pair[1]));
        }
    }
    for rect in label_boxes {
        for y in (rect.top..=rect.bottom).step_by(LABEL_SAMPLE_STEP) {
            pixels.extend((rect.left..=rect.right).step_by(LABEL_SAMPLE_STEP).map(|x| (x, y)));
        }
    }
    pixels
}

fn samples_along(from: (i32, i32), to: (i32, i32)) -> impl Iterator<Item = (i32, i32)> {
    let (dx, dy) = (f64::from(to.0 - from.0), f64::from(to.1 - from.1));
    let count = (dx.hypot(dy) / OCCUPANCY_SAMPLE_SPACING).ceil().max(1.0) as i32;
    (1..count).map(move |i| {
        let t = f64::from(i) / f64::from(count);
        (from.0 + (t * dx).round() as i32, from.1 + (t * dy).round() as i32)
    })
}

fn draw_legend(
    canvas: &mut Canvas,
    layout: &Layout,
    series: &[Series],
    curves: &[Vec<(f64, f64)>],
    label_boxes: &[Rect],
) {
    let entries = legend_entries(series, curves);
    if entries.is_empty() {
        return;
    }
    let occupied = occupied_pixels(layout, curves, label_boxes);
    let frame = legend_box(layout, legend_size(&entries), &occupied);
    canvas.fill_rect(frame, BACKGROUND);
    canvas.stroke_rect(frame, LEGEND_BORDER_COLOUR);
    let row_height = text_height(LABEL_SCALE) + LEGEND_ROW_GAP;
    for (row, (label, colour)) in (0..).zip(&entries) {
        let top = frame.top + LEGEND_PAD + row * row_height;
        let middle = top + text_height(LABEL_SCALE) / 2;
        let sample_left = frame.left + LEGEND_PAD;
        let sample_right = sample_left + LEGEND_SAMPLE_LENGTH - LINE_THICKNESS;
        canvas.line((sample_left, middle - 1), (sample_right, middle - 1), *colour);
        canvas.marker(((sample_left + sample_right) / 2, middle), *colour);
        canvas.text(label, (sample_left + LEGEND_SAMPLE_LENGTH + LEGEND_PAD, top), LABEL_SCALE, TEXT_COLOUR);
    }
}

// ---------------------------------------------------------------------------
// Bitmap font
// ---------------------------------------------------------------------------

const GLYPH_WIDTH: i32 = 5;
const GLYPH_HEIGHT: i32 = 7;
/// Horizontal distance between the starts of adjacent glyphs, in font pixels.
const GLYPH_ADVANCE: i32 = GLYPH_WIDTH + 1;
/// How many rows the descending letters (g, p, q, y) hang below the baseline.
const GLYPH_DESCENT: i32 = 2;
const FIRST_GLYPH: char = ' ';
const LAST_GLYPH: char = '~';

/// Width in pixels of `text` lettered at `scale`.
fn text_width(text: &str, scale: i32) -> i32 {
    let characters = i32::try_from(text.chars().count()).unwrap_or(i32::MAX / GLYPH_ADVANCE);
    if characters == 0 {
        0
    } else {
        (characters * GLYPH_ADVANCE - 1) * scale
    }
}

/// Height in pixels of text lettered at `scale`, from the top of capitals to
/// the baseline.
fn text_height(scale: i32) -> i32 {
    GLYPH_HEIGHT * scale
}

/// How far in pixels descending letters reach below the baseline at `scale`.
fn text_descent(scale: i32) -> i32 {
    GLYPH_DESCENT * scale
}

/// How many rows `character`'s glyph is drawn below the top of the line.
fn glyph_drop(character: char) -> i32 {
    if matches!(character, 'g' | 'p' | 'q' | 'y') {
        GLYPH_DESCENT
    } else {
        0
    }
}

/// The glyph of `character`: seven rows of five bits, the top row first and
/// the leftmost pixel in bit 4. Characters outside printable ASCII are `?`.
fn glyph(character: char) -> [u8; 7] {
    let character = if (FIRST_GLYPH..=LAST_GLYPH).contains(&character) { character } else { '?' };
    FONT[(u32::from(character) - u32::from(FIRST_GLYPH)) as usize]
}

/// The lit font pixels `(column, row)` of `text` lettered from `(0, 0)`.
fn text_pixels(text: &str) -> impl Iterator<Item = (i32, i32)> + '_ {
    (0..).zip(text.chars()).flat_map(|(index, character)| {
        let (rows, drop) = (glyph(character), glyph_drop(character));
        (0..GLYPH_HEIGHT).flat_map(move |row| {
            let bits = rows[row as usize];
            (0..GLYPH_WIDTH)
                .filter(move |column| bits & (0b10000 >> column) != 0)
                .map(move |column| (index * GLYPH_ADVANCE + column, row + drop))
        })
    })
}

/// 5x7 glyphs for ASCII 32 (space) to 126 (`~`); see [`glyph`]. The
/// descending letters are drawn [`GLYPH_DESCENT`] rows lower.
#[rustfmt::skip]
const FONT: [[u8; 7]; 95] = [
    [0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b00000], // ' '
    [0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00000, 0b00100], // '!'
    [0b01010, 0b01010, 0b01010, 0b00000, 0b00000, 0b00000, 0b00000], // '"'
    [0b01010, 0b01010, 0b11111, 0b01010, 0b11111, 0b01010, 0b01010], // '#'
    [0b00100, 0b01111, 0b10100, 0b01110, 0b00101, 0b11110, 0b00100], // '$'
    [0b11000, 0b11001, 0b00010, 0b00100, 0b01000, 0b10011, 0b00011], // '%'
    [0b01100, 0b10010, 0b10100, 0b01000, 0b10101, 0b10010, 0b01101], // '&'
    [0b00100, 0b00100, 0b01000, 0b00000, 0b00000, 0b00000, 0b00000], // '''
    [0b00010, 0b00100, 0b01000, 0b01000, 0b01000, 0b00100, 0b00010], // '('
    [0b01000, 0b00100, 0b00010, 0b00010, 0b00010, 0b00100, 0b01000], // ')'
    [0b00000, 0b00100, 0b10101, 0b01110, 0b10101, 0b00100, 0b00000], // '*'
    [0b00000, 0b00100, 0b00100, 0b11111, 0b00100, 0b00100, 0b00000], // '+'
    [0b00000, 0b00000, 0b00000, 0b00000, 0b01100, 0b00100, 0b01000], // ','
    [0b00000, 0b00000, 0b00000, 0b11111, 0b00000, 0b00000, 0b00000], // '-'
    [0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b01100, 0b01100], // '.'
    [0b00000, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0b00000], // '/'
    [0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110], // '0'
    [0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110], // '1'
    [0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111], // '2'
    [0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110], // '3'
    [0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010], // '4'
    [0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110], // '5'
    [0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110], // '6'
    [0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000], // '7'
    [0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110], // '8'
    [0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100], // '9'
    [0b00000, 0b01100, 0b01100, 0b00000, 0b01100, 0b01100, 0b00000], // ':'
    [0b00000, 0b01100, 0b01100, 0b00000, 0b01100, 0b00100, 0b01000], // ';'
    [0b00010, 0b00100, 0b01000, 0b10000, 0b01000, 0b00100, 0b00010], // '<'
    [0b00000, 0b00000, 0b11111, 0b00000, 0b11111, 0b00000, 0b00000], // '='
    [0b01000, 0b00100, 0b00010, 0b00001, 0b00010, 0b00100, 0b01000], // '>'
    [0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b00000, 0b00100], // '?'
    [0b01110, 0b10001, 0b00001, 0b01101, 0b10101, 0b10101, 0b01110], // '@'
    [0b01110, 0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001], // 'A'
    [0b11110, 0b10001, 0b10001, 0b11110, 0b10001, 0b10001, 0b11110], // 'B'
    [0b01110, 0b10001, 0b10000, 0b10000, 0b10000, 0b10001, 0b01110], // 'C'
    [0b11100, 0b10010, 0b10001, 0b10001, 0b10001, 0b10010, 0b11100], // 'D'
    [0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b11111], // 'E'
    [0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b10000], // 'F'
    [0b01110, 0b10001, 0b10000, 0b10111, 0b10001, 0b10001, 0b01111], // 'G'
    [0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001, 0b10001], // 'H'
    [0b01110, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110], // 'I'
    [0b00111, 0b00010, 0b00010, 0b00010, 0b00010, 0b10010, 0b01100], // 'J'
    [0b10001, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010, 0b10001], // 'K'
    [0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b11111], // 'L'
    [0b10001, 0b11011, 0b10101, 0b10101, 0b10001, 0b10001, 0b10001], // 'M'
    [0b10001, 0b10001, 0b11001, 0b10101, 0b10011, 0b10001, 0b10001], // 'N'
    [0b01110, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110], // 'O'
    [0b11110, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000, 0b10000], // 'P'
    [0b01110, 0b10001, 0b10001, 0b10001, 0b10101, 0b10010, 0b01101], // 'Q'
    [0b11110, 0b10001, 0b10001, 0b11110, 0b10100, 0b10010, 0b10001], // 'R'
    [0b01111, 0b10000, 0b10000, 0b01110, 0b00001, 0b00001, 0b11110], // 'S'
    [0b11111, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100], // 'T'
    [0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110], // 'U'
    [0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100], // 'V'
    [0b10001, 0b10001, 0b10001, 0b10101, 0b10101, 0b10101, 0b01010], // 'W'
    [0b10001, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001, 0b10001], // 'X'
    [0b10001, 0b10001, 0b10001, 0b01010, 0b00100, 0b00100, 0b00100], // 'Y'
    [0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0b11111], // 'Z'
    [0b01110, 0b01000, 0b01000, 0b01000, 0b01000, 0b01000, 0b01110], // '['
    [0b00000, 0b10000, 0b01000, 0b00100, 0b00010, 0b00001, 0b00000], // '\'
    [0b01110, 0b00010, 0b00010, 0b00010, 0b00010, 0b00010, 0b01110], // ']'
    [0b00100, 0b01010, 0b10001, 0b00000, 0b00000, 0b00000, 0b00000], // '^'
    [0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b11111], // '_'
    [0b01000, 0b00100, 0b00010, 0b00000, 0b00000, 0b00000, 0b00000], // '`'
    [0b00000, 0b00000, 0b01110, 0b00001, 0b01111, 0b10001, 0b01111], // 'a'
    [0b10000, 0b10000, 0b10110, 0b11001, 0b10001, 0b10001, 0b11110], // 'b'
    [0b00000, 0b00000, 0b01110, 0b10000, 0b10000, 0b10001, 0b01110], // 'c'
    [0b00001, 0b00001, 0b01101, 0b10011, 0b10001, 0b10001, 0b01111], // 'd'
    [0b00000, 0b00000, 0b01110, 0b10001, 0b11111, 0b10000, 0b01110], // 'e'
    [0b00110, 0b01001, 0b01000, 0b11100, 0b01000, 0b01000, 0b01000], // 'f'
    [0b01111, 0b10001, 0b10001, 0b10001, 0b01111, 0b00001, 0b01110], // 'g' (descends)
    [0b10000, 0b10000, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001], // 'h'
    [0b00100, 0b00000, 0b01100, 0b00100, 0b00100, 0b00100, 0b01110], // 'i'
    [0b00010, 0b00000, 0b00110, 0b00010, 0b00010, 0b10010, 0b01100], // 'j'
    [0b10000, 0b10000, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010], // 'k'
    [0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110], // 'l'
    [0b00000, 0b00000, 0b11010, 0b10101, 0b10101, 0b10001, 0b10001], // 'm'
    [0b00000, 0b00000, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001], // 'n'
    [0b00000, 0b00000, 0b01110, 0b10001, 0b10001, 0b10001, 0b01110], // 'o'
    [0b11110, 0b10001, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000], // 'p' (descends)
    [0b01111, 0b10001, 0b10001, 0b10001, 0b01111, 0b00001, 0b00001], // 'q' (descends)
    [0b00000, 0b00000, 0b10110, 0b11001, 0b10000, 0b10000, 0b10000], // 'r'
    [0b00000, 0b00000, 0b01110, 0b10000, 0b01110, 0b00001, 0b11110], // 's'
    [0b01000, 0b01000, 0b11100, 0b01000, 0b01000, 0b01001, 0b00110], // 't'
    [0b00000, 0b00000, 0b10001, 0b10001, 0b10001, 0b10011, 0b01101], // 'u'
    [0b00000, 0b00000, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100], // 'v'
    [0b00000, 0b00000, 0b10001, 0b10001, 0b10101, 0b10101, 0b01010], // 'w'
    [0b00000, 0b00000, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001], // 'x'
    [0b10001, 0b10001, 0b10001, 0b10001, 0b01111, 0b00001, 0b01110], // 'y' (descends)
    [0b00000, 0b00000, 0b11111, 0b00010, 0b00100, 0b01000, 0b11111], // 'z'
    [0b00010, 0b00100, 0b00100, 0b01000, 0b00100, 0b00100, 0b00010], // '{'
    [0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100], // '|'
    [0b01000, 0b00100, 0b00100, 0b00010, 0b00100, 0b00100, 0b01000], // '}'
    [0b00000, 0b00000, 0b01000, 0b10101, 0b00010, 0b00000, 0b00000], // '~'
];

#[cfg(test)]
mod tests {
    use super::*;

    fn series(label: &str, points: &[(f64, f64)]) -> Series {
        Series { label: label.to_string(), points: points.to_vec() }
    }

    fn render(series: &[Series], hlines: &[HLine]) -> Result<RgbImage, PlotError> {
        render_log_log_plot(DEFAULT_PLOT_SIZE, "Error against time", "time (s)", "error", series, hlines)
    }

    /// The layout `render_log_log_plot` uses for these inputs.
    fn layout_of(series: &[Series], hlines: &[HLine]) -> Layout {
        let curves: Vec<_> = series.iter().map(|s| plottable_points(&s.points)).collect();
        let lines: Vec<&HLine> = hlines.iter().filter(|h| is_positive_finite(h.y)).collect();
        Layout::new(DEFAULT_PLOT_SIZE, &DataBounds::of(&curves, &lines).expect("data"))
    }

    fn colour_near(image: &RgbImage, (x, y): (i32, i32), radius: i32, colour: Colour) -> bool {
        let pixels = (y - radius..=y + radius).flat_map(|py| (x - radius..=x + radius).map(move |px| (px, py)));
        pixels
            .filter_map(|(px, py)| Some((u32::try_from(px).ok()?, u32::try_from(py).ok()?)))
            .any(|(px, py)| px < image.width() && py < image.height() && *image.get_pixel(px, py) == colour)
    }

    #[test]
    fn axis_mapping_puts_decades_at_predicted_pixels() {
        let data = [series("a", &[(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)])];
        let layout = layout_of(&data, &[]);
        // Data ending exactly on decades is widened by half a decade each way.
        assert_eq!(layout.x, LogRange { lo: -0.5, hi: 2.5 });
        assert_eq!(layout.y, LogRange { lo: -2.5, hi: 0.5 });
        let plot = layout.plot;
        let at = |fraction: f64, from: i32, to: i32| from + (fraction * f64::from(to - from)).round() as i32;
        assert_eq!(layout.to_pixel((10.0, 0.1)), (at(0.5, plot.left, plot.right), at(0.5, plot.bottom, plot.top)));
        assert_eq!(
            layout.to_pixel((1.0, 1.0)),
            (at(0.5 / 3.0, plot.left, plot.right), at(2.5 / 3.0, plot.bottom, plot.top))
        );
        assert_eq!(
            layout.to_pixel((100.0, 0.01)),
            (at(2.5 / 3.0, plot.left, plot.right), at(0.5 / 3.0, plot.bottom, plot.top))
        );
    }

    #[test]
    fn markers_appear_where_the_axis_mapping_predicts() {
        let first = series("first", &[(1.0, 1.0), (3.0, 0.4), (10.0, 0.1), (100.0, 0.01)]);
        let second = series("second", &[(2.0, 0.02), (20.0, 0.05)]);
        let data = [first.clone(), second.clone()];
        let image = render(&data, &[]).expect("render");
        let layout = layout_of(&data, &[]);
        for (index, s) in data.iter().enumerate() {
            for &point in &s.points {
                let pixel = layout.to_pixel(point);
                assert!(
                    colour_near(&image, pixel, 1, series_colour(index)),
                    "{} point {point:?} at {pixel:?}",
                    s.label
                );
            }
        }
        // Far from both curves (and from the legend, which avoids the
        // curves), neither colour appears.
        let empty = layout.to_pixel((1.0, 0.01));
        assert!(!colour_near(&image, empty, 8, series_colour(0)));
        assert!(!colour_near(&image, empty, 8, series_colour(1)));
    }

    #[test]
    fn points_outside_log_axes_are_skipped() {
        let points =
            [(0.0, 1.0), (-1.0, 2.0), (1.0, 0.0), (2.0, -3.0), (f64::NAN, 1.0), (f64::INFINITY, 1.0), (1.0, f64::NAN)];
        let mut with_valid = points.to_vec();
        with_valid.extend([(10.0, 0.5), (1.0, 0.05)]);
        assert_eq!(plottable_points(&with_valid), vec![(1.0, 0.05), (10.0, 0.5)]);
        let data = [series("mixed", &with_valid), series("all invalid", &points)];
        let image = render(&data, &[HLine { label: "negative".into(), y: -1.0 }]).expect("render");
        assert_eq!(image.dimensions(), DEFAULT_PLOT_SIZE);
        let layout = layout_of(&data, &[]);
        assert_eq!(layout.x, LogRange { lo: -0.5, hi: 1.5 });
        assert_eq!(layout.y, LogRange { lo: -1.5, hi: 0.0 });
    }

    #[test]
    fn no_plottable_point_is_no_data() {
        let invalid = [series("bad", &[(0.0, 1.0), (1.0, -1.0), (f64::NAN, f64::NAN)])];
        assert!(matches!(render(&invalid, &[]), Err(PlotError::NoData)));
        assert!(matches!(render(&[], &[HLine { label: "line".into(), y: 0.1 }]), Err(PlotError::NoData)));
        assert!(matches!(render(&[series("empty", &[])], &[]), Err(PlotError::NoData)));
    }

    #[test]
    fn too_small_an_image_is_refused() {
        let data = [series("a", &[(1.0, 1.0)])];
        let result = render_log_log_plot((100, 80), "", "", "", &data, &[]);
        assert!(matches!(result, Err(PlotError::TooSmall { width: 100, height: 80 })));
    }

    #[test]
    fn written_png_decodes_with_the_requested_size() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let data = [series("none", &[(0.5, 0.3), (1.0, 0.2), (8.0, 0.05)])];
        let hlines = [HLine { label: "none @ 64 spp".into(), y: 0.07 }];
        let default_path = dir.path().join("default.png");
        write_log_log_plot(&default_path, "t", "x", "y", &data, &hlines).expect("write");
        assert_eq!(image::open(&default_path).expect("decode").to_rgb8().dimensions(), DEFAULT_PLOT_SIZE);
        let sized_path = dir.path().join("sized.png");
        write_log_log_plot_sized(&sized_path, (640, 480), "t", "x", "y", &data, &hlines).expect("write");
        assert_eq!(image::open(&sized_path).expect("decode").to_rgb8().dimensions(), (640, 480));
        let leftovers = std::fs::read_dir(dir.path()).expect("list").count();
        assert_eq!(leftovers, 2, "no temporary files remain");
    }

    #[test]
    fn writing_into_a_missing_directory_is_an_io_error() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("missing").join("plot.png");
        let result = write_log_log_plot(&path, "t", "x", "y", &[series("a", &[(1.0, 1.0)])], &[]);
        assert!(matches!(result, Err(PlotError::Io { .. })));
    }

    #[test]
    fn every_printable_glyph_but_space_is_lit_and_distinct() {
        assert!(glyph(' ').iter().all(|&row| row == 0));
        for character in '!'..='~' {
            assert!(glyph(character).iter().any(|&row| row != 0), "glyph {character:?} is empty");
        }
        for (index, rows) in FONT.iter().enumerate() {
            assert!(rows.iter().all(|&row| row < 1 << GLYPH_WIDTH), "glyph {index} is wider than 5 pixels");
            assert!(!FONT[..index].contains(rows), "glyph {index} repeats an earlier one");
        }
        assert_eq!(glyph('\u{e9}'), glyph('?'));
    }

    #[test]
    fn text_is_lettered_in_the_text_colour() {
        let mut canvas = Canvas::new((40, 20));
        canvas.text("1", (2, 3), 2, TEXT_COLOUR);
        // '1' has its foot row (0b01110) lit from column 1 to 3.
        assert_eq!(*canvas.image.get_pixel(2 + 2, 3 + 6 * 2), TEXT_COLOUR);
        assert_eq!(*canvas.image.get_pixel(2, 3 + 6 * 2), BACKGROUND);
        assert_eq!(text_width("ab", 2), (2 * GLYPH_ADVANCE - 1) * 2);
        assert_eq!(text_width("", 3), 0);
        let lowest_row = |text: &str| text_pixels(text).map(|(_, row)| row).max();
        assert_eq!(lowest_row("Ab"), Some(GLYPH_HEIGHT - 1));
        assert_eq!(lowest_row("gap"), Some(GLYPH_HEIGHT - 1 + GLYPH_DESCENT));
    }

    #[test]
    fn tick_labels_are_short() {
        let label = |mantissa, exponent| Tick { mantissa, exponent }.label();
        assert_eq!(label(1, -3), "1e-3");
        assert_eq!(label(1, -2), "0.01");
        assert_eq!(label(5, -1), "0.5");
        assert_eq!(label(1, 0), "1");
        assert_eq!(label(1, 1), "10");
        assert_eq!(label(2, 2), "200");
        assert_eq!(label(5, 3), "5000");
        assert_eq!(label(1, 4), "1e4");
    }

    #[test]
    fn ranges_snap_to_half_decades_and_ticks_follow_the_span() {
        let narrow = LogRange::padded(0.5, 8.0);
        assert_eq!(narrow, LogRange { lo: -0.5, hi: 1.0 });
        let labels: Vec<String> = narrow.ticks(10).iter().map(|t| t.label()).collect();
        assert_eq!(labels, ["0.5", "1", "2", "5", "10"]);
        let wide = LogRange::padded(2e-4, 3.0);
        assert_eq!(wide, LogRange { lo: -4.0, hi: 0.5 });
        let labels: Vec<String> = wide.ticks(10).iter().map(|t| t.label()).collect();
        assert_eq!(labels, ["1e-4", "1e-3", "0.01", "0.1", "1"]);
        let crowded = LogRange::padded(1e-40, 1e40);
        assert!(crowded.ticks(8).len() <= 9);
        let single = LogRange::padded(3.0, 3.0);
        assert_eq!(single, LogRange { lo: 0.0, hi: 0.5 });
        let labels: Vec<String> = single.ticks(10).iter().map(|t| t.label()).collect();
        assert_eq!(labels, ["1", "2", "3"]);
    }
}
