//! Where the legend goes: the corner of the plot area that the curves and
//! the reference-line labels leave freest.

use plotters::chart::SeriesLabelPosition;

use super::*;

/// Gap in pixels between the legend and the plot area's edges.
pub(super) const LEGEND_INSET: i32 = 10;
/// Padding inside the legend box.
pub(super) const LEGEND_MARGIN: u32 = 8;
/// Width of the line-and-marker sample before each label.
pub(super) const LEGEND_SAMPLE: u32 = 32;
/// Spacing in pixels of the samples taken along curves to find free space.
const OCCUPANCY_SAMPLE_SPACING: f64 = 3.0;
/// Width and height in pixels of the region a reference line's label takes,
/// left of the plot's right edge and above the line.
const HLINE_LABEL_REGION: (i32, i32) = (200, 22);

/// The legend box's width and height in pixels, for `rows` labels of which
/// the widest is `widest` pixels, as `plotters` lays it out (lines 1.25
/// font sizes apart).
pub(super) fn legend_size(widest: u32, rows: usize, font_size: u32) -> (i32, i32) {
    let text_height = (rows as f64 * f64::from(font_size) * 1.25).ceil() as i32;
    let margin = LEGEND_MARGIN as i32;
    (widest as i32 + LEGEND_SAMPLE as i32 + 2 * margin, text_height + 2 * margin)
}

/// Pixels along every curve and over every reference line's label.
pub(super) fn occupied_pixels(frame: &Frame, curves: &[Vec<(f64, f64)>], lines: &[&HLine]) -> Vec<(i32, i32)> {
    let mut pixels = Vec::new();
    for curve in curves {
        let corners: Vec<(i32, i32)> = curve.iter().map(|&p| frame.to_pixel(p)).collect();
        pixels.extend_from_slice(&corners);
        for pair in corners.windows(2) {
            pixels.extend(samples_along(pair[0], pair[1]));
        }
    }
    let right = frame.x_pixels.1;
    for line in lines {
        let (_, y) = frame.to_pixel((1.0, line.y));
        for dy in (0..HLINE_LABEL_REGION.1).step_by(3) {
            pixels.extend((0..HLINE_LABEL_REGION.0).step_by(3).map(|dx| (right - dx, y - dy)));
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

/// The legend's top-left corner, relative to the plot area, in the corner
/// covering the fewest `occupied` pixels: top right, top left, bottom left,
/// bottom right on ties.
pub(super) fn legend_corner(frame: &Frame, (width, height): (i32, i32), occupied: &[(i32, i32)]) -> (i32, i32) {
    let plot_width = frame.x_pixels.1 - frame.x_pixels.0 + 1;
    let plot_height = frame.y_pixels.1 - frame.y_pixels.0 + 1;
    let (left, right) = (LEGEND_INSET, plot_width - LEGEND_INSET - width);
    let (top, bottom) = (LEGEND_INSET, plot_height - LEGEND_INSET - height);
    let corners = [(right, top), (left, top), (left, bottom), (right, bottom)];
    let covered = |&(x, y): &(i32, i32)| {
        let (x0, y0) = (frame.x_pixels.0 + x, frame.y_pixels.0 + y);
        occupied.iter().filter(|&&(px, py)| px >= x0 && px <= x0 + width && py >= y0 && py <= y0 + height).count()
    };
    corners.into_iter().min_by_key(covered).unwrap_or(corners[0])
}

/// The `plotters` position of a legend whose top-left corner is `corner`.
pub(super) fn legend_position((x, y): (i32, i32)) -> SeriesLabelPosition {
    SeriesLabelPosition::Coordinate(x, y)
}
