//! Drawing on the raster: colours, lines, grid, ticks, labels, curves and
//! the legend placed where it hides the least.

use image::{Rgb, RgbImage};

use super::*;

// ---------------------------------------------------------------------------
// Colours
// ---------------------------------------------------------------------------

pub(super) type Colour = Rgb<u8>;

pub(super) const BACKGROUND: Colour = Rgb([255, 255, 255]);
pub(super) const TEXT_COLOUR: Colour = Rgb([25, 25, 25]);
pub(super) const AXES_COLOUR: Colour = Rgb([40, 40, 40]);
pub(super) const DECADE_GRID_COLOUR: Colour = Rgb([205, 205, 205]);
pub(super) const MINOR_GRID_COLOUR: Colour = Rgb([232, 232, 232]);
pub(super) const HLINE_COLOUR: Colour = Rgb([95, 95, 95]);
pub(super) const LEGEND_BORDER_COLOUR: Colour = Rgb([150, 150, 150]);

/// Series colours (after matplotlib's "tab10"), reused in turn when there
/// are more series than colours.
pub(super) const PALETTE: [Colour; 8] = [
    Rgb([31, 119, 180]),
    Rgb([214, 39, 40]),
    Rgb([44, 160, 44]),
    Rgb([255, 127, 14]),
    Rgb([148, 103, 189]),
    Rgb([140, 86, 75]),
    Rgb([227, 119, 194]),
    Rgb([23, 190, 207]),
];

pub(super) fn series_colour(index: usize) -> Colour {
    PALETTE[index % PALETTE.len()]
}

// ---------------------------------------------------------------------------
// Canvas: clipped pixel drawing
// ---------------------------------------------------------------------------

pub(super) const LINE_THICKNESS: i32 = 2;
pub(super) const MARKER_HALF_SIZE: i32 = 3;
pub(super) const DASH_LENGTH: i32 = 8;
pub(super) const DASH_GAP: i32 = 5;

/// An image with drawing operations that ignore pixels outside it.
pub(super) struct Canvas {
    pub(super) image: RgbImage,
}

impl Canvas {
    pub(super) fn new((width, height): (u32, u32)) -> Self {
        Canvas { image: RgbImage::from_pixel(width, height, BACKGROUND) }
    }

    pub(super) fn put(&mut self, x: i32, y: i32, colour: Colour) {
        let (Ok(x), Ok(y)) = (u32::try_from(x), u32::try_from(y)) else { return };
        if x < self.image.width() && y < self.image.height() {
            self.image.put_pixel(x, y, colour);
        }
    }

    pub(super) fn fill_rect(&mut self, rect: Rect, colour: Colour) {
        for y in rect.top..=rect.bottom {
            for x in rect.left..=rect.right {
                self.put(x, y, colour);
            }
        }
    }

    pub(super) fn stroke_rect(&mut self, rect: Rect, colour: Colour) {
        self.fill_rect(Rect { bottom: rect.top, ..rect }, colour);
        self.fill_rect(Rect { top: rect.bottom, ..rect }, colour);
        self.fill_rect(Rect { right: rect.left, ..rect }, colour);
        self.fill_rect(Rect { left: rect.right, ..rect }, colour);
    }

    pub(super) fn thick_dot(&mut self, x: i32, y: i32, colour: Colour) {
        self.fill_rect(Rect::with_size(x, y, LINE_THICKNESS, LINE_THICKNESS), colour);
    }

    /// A line `LINE_THICKNESS` pixels thick, by Bresenham's algorithm.
    pub(super) fn line(&mut self, from: (i32, i32), to: (i32, i32), colour: Colour) {
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

    pub(super) fn dashed_horizontal_line(&mut self, left: i32, right: i32, y: i32, colour: Colour) {
        for x in left..=right {
            if (x - left) % (DASH_LENGTH + DASH_GAP) < DASH_LENGTH {
                self.fill_rect(Rect::with_size(x, y, 1, LINE_THICKNESS), colour);
            }
        }
    }

    pub(super) fn marker(&mut self, (x, y): (i32, i32), colour: Colour) {
        let size = 2 * MARKER_HALF_SIZE + 1;
        self.fill_rect(Rect::with_size(x - MARKER_HALF_SIZE, y - MARKER_HALF_SIZE, size, size), colour);
    }

    /// Letters `text` with its top left corner at `(x, y)`.
    pub(super) fn text(&mut self, text: &str, (x, y): (i32, i32), scale: i32, colour: Colour) {
        for (column, row) in text_pixels(text) {
            self.fill_rect(Rect::with_size(x + column * scale, y + row * scale, scale, scale), colour);
        }
    }

    /// Letters `text` turned a quarter turn anticlockwise, reading upwards;
    /// `(x, y)` is the bottom left corner of the turned text.
    pub(super) fn text_upwards(&mut self, text: &str, (x, y): (i32, i32), scale: i32, colour: Colour) {
        for (column, row) in text_pixels(text) {
            self.fill_rect(Rect::with_size(x + row * scale, y - (column + 1) * scale + 1, scale, scale), colour);
        }
    }

    /// Letters `text` over a one pixel white outline, legible over lines.
    pub(super) fn text_with_halo(&mut self, text: &str, (x, y): (i32, i32), scale: i32, colour: Colour) {
        for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
            self.text(text, (x + dx, y + dy), scale, BACKGROUND);
        }
        self.text(text, (x, y), scale, colour);
    }
}

// ---------------------------------------------------------------------------
// Plot elements
// ---------------------------------------------------------------------------

pub(super) fn draw_vertical_gridline(canvas: &mut Canvas, layout: &Layout, x: i32, colour: Colour) {
    canvas.fill_rect(Rect { left: x, right: x, ..layout.plot }, colour);
}

pub(super) fn draw_horizontal_gridline(canvas: &mut Canvas, layout: &Layout, y: i32, colour: Colour) {
    canvas.fill_rect(Rect { top: y, bottom: y, ..layout.plot }, colour);
}

/// Light grid lines at the labelled 2x and 5x ticks, then darker ones at
/// the decades (all decades when they are far enough apart).
pub(super) fn draw_grid(canvas: &mut Canvas, layout: &Layout) {
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
pub(super) fn gridline_decades(range: LogRange, ticks: &[Tick], pixels_per_decade: f64) -> Vec<i32> {
    let every_decade = pixels_per_decade >= MIN_DECADE_PIXELS_FOR_GRID;
    let labelled = |e: &i32| ticks.iter().any(|t| t.is_decade() && t.exponent == *e);
    range.decade_exponents().filter(|e| every_decade || labelled(e)).collect()
}

/// Tick marks below and left of the axes box: long at labelled ticks,
/// short at unlabelled 2x..9x values when decades are wide enough.
pub(super) fn draw_ticks(canvas: &mut Canvas, layout: &Layout) {
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
pub(super) fn minor_tick_logs(range: LogRange, ticks: &[Tick], pixels_per_decade: f64) -> Vec<f64> {
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

pub(super) fn draw_tick_labels(canvas: &mut Canvas, layout: &Layout) {
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

pub(super) fn draw_title_and_axis_labels(
    canvas: &mut Canvas,
    layout: &Layout,
    title: &str,
    x_label: &str,
    y_label: &str,
) {
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
pub(super) fn largest_scale_fitting(text: &str, width: i32, preferred: i32) -> i32 {
    (1..=preferred).rev().find(|&scale| text_width(text, scale) <= width).unwrap_or(1)
}

pub(super) fn draw_hlines(canvas: &mut Canvas, layout: &Layout, lines: &[&HLine]) {
    for line in lines {
        let y = layout.y_pixel_of_log(line.y.log10());
        canvas.dashed_horizontal_line(layout.plot.left + 1, layout.plot.right - 1, y, HLINE_COLOUR);
    }
}

/// Where the label of the reference line at pixel row `y` goes: right
/// aligned in the plot, just above the line, or below it near the top.
pub(super) fn hline_label_box(layout: &Layout, label: &str, y: i32) -> Rect {
    let (width, height) = (text_width(label, LABEL_SCALE), text_height(LABEL_SCALE));
    let left = layout.plot.right - 6 - width;
    let above = y - 3 - text_descent(LABEL_SCALE) - height;
    let top = if above > layout.plot.top + 2 { above } else { y + LINE_THICKNESS + 4 };
    Rect::with_size(left, top, width, height)
}

/// Letters each reference line's label and returns the boxes they cover.
pub(super) fn draw_hline_labels(canvas: &mut Canvas, layout: &Layout, lines: &[&HLine]) -> Vec<Rect> {
    let mut boxes = Vec::new();
    for line in lines {
        let y = layout.y_pixel_of_log(line.y.log10());
        let label_box = hline_label_box(layout, &line.label, y);
        canvas.text_with_halo(&line.label, (label_box.left, label_box.top), LABEL_SCALE, HLINE_COLOUR);
        boxes.push(label_box);
    }
    boxes
}

pub(super) fn draw_curve(canvas: &mut Canvas, layout: &Layout, points: &[(f64, f64)], colour: Colour) {
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

pub(super) const LEGEND_PAD: i32 = 8;
pub(super) const LEGEND_INSET: i32 = 10;
pub(super) const LEGEND_SAMPLE_LENGTH: i32 = 28;
pub(super) const LEGEND_ROW_GAP: i32 = 8;
/// Spacing in pixels of the samples taken along curves to find free space.
pub(super) const OCCUPANCY_SAMPLE_SPACING: f64 = 3.0;
/// Spacing in pixels of the samples taken over label boxes.
pub(super) const LABEL_SAMPLE_STEP: usize = 3;

/// The legend entries: every series, noting those without plottable points.
pub(super) fn legend_entries(series: &[Series], curves: &[Vec<(f64, f64)>]) -> Vec<(String, Colour)> {
    let label = |s: &Series, curve: &[(f64, f64)]| {
        if curve.is_empty() {
            format!("{} (no data)", s.label)
        } else {
            s.label.clone()
        }
    };
    series.iter().zip(curves).enumerate().map(|(index, (s, curve))| (label(s, curve), series_colour(index))).collect()
}

pub(super) fn legend_size(entries: &[(String, Colour)]) -> (i32, i32) {
    let widest = entries.iter().map(|(label, _)| text_width(label, LABEL_SCALE)).max().unwrap_or(0);
    let rows = i32::try_from(entries.len()).unwrap_or(i32::MAX);
    let row_height = text_height(LABEL_SCALE) + LEGEND_ROW_GAP;
    let width = LEGEND_PAD + LEGEND_SAMPLE_LENGTH + LEGEND_PAD + widest + LEGEND_PAD;
    (width, 2 * LEGEND_PAD + rows * row_height - LEGEND_ROW_GAP)
}

/// The legend box in the corner of the plot covering the fewest curve and
/// label pixels; top right, top left, bottom left, bottom right on ties.
pub(super) fn legend_box(layout: &Layout, size: (i32, i32), occupied: &[(i32, i32)]) -> Rect {
    let plot = layout.plot;
    let (left, right) = (plot.left + LEGEND_INSET, plot.right - LEGEND_INSET - size.0 + 1);
    let (top, bottom) = (plot.top + LEGEND_INSET, plot.bottom - LEGEND_INSET - size.1 + 1);
    let corners = [(right, top), (left, top), (left, bottom), (right, bottom)];
    let boxes = corners.map(|(x, y)| Rect::with_size(x, y, size.0, size.1));
    let covered = |rect: &Rect| occupied.iter().filter(|&&p| rect.contains(p)).count();
    boxes.into_iter().min_by_key(covered).unwrap_or(boxes[0])
}

/// Pixels along every curve and inside every label box, for placing the legend.
pub(super) fn occupied_pixels(layout: &Layout, curves: &[Vec<(f64, f64)>], label_boxes: &[Rect]) -> Vec<(i32, i32)> {
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

pub(super) fn samples_along(from: (i32, i32), to: (i32, i32)) -> impl Iterator<Item = (i32, i32)> {
    let (dx, dy) = (f64::from(to.0 - from.0), f64::from(to.1 - from.1));
    let count = (dx.hypot(dy) / OCCUPANCY_SAMPLE_SPACING).ceil().max(1.0) as i32;
    (1..count).map(move |i| {
        let t = f64::from(i) / f64::from(count);
        (from.0 + (t * dx).round() as i32, from.1 + (t * dy).round() as i32)
    })
}

pub(super) fn draw_legend(
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
