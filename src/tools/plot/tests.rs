//! Tests of the log-log plots: ranges, ticks, layout and drawing.

use super::*;

fn series(label: &str, points: &[(f64, f64)]) -> Series {
    Series { label: label.to_string(), points: points.to_vec() }
}

fn render(series: &[Series], hlines: &[HLine]) -> Result<RgbImage, PlotError> {
    render_log_log_plot(DEFAULT_PLOT_SIZE, "Error against time", "time (s)", "error", series, hlines)
}

/// The image and the frame (plot area and axis ranges) of a default plot.
fn draw(series: &[Series], hlines: &[HLine]) -> (RgbImage, Frame) {
    let labels = Labels { title: "Error against time", x: "time (s)", y: "error" };
    draw_log_log_plot(DEFAULT_PLOT_SIZE, &labels, series, hlines).expect("draw")
}

fn colour_near(image: &RgbImage, (x, y): (i32, i32), radius: i32, colour: RGBColor) -> bool {
    let pixels = (y - radius..=y + radius).flat_map(|py| (x - radius..=x + radius).map(move |px| (px, py)));
    pixels.filter_map(|(px, py)| Some((u32::try_from(px).ok()?, u32::try_from(py).ok()?))).any(|(px, py)| {
        px < image.width() && py < image.height() && image.get_pixel(px, py).0 == [colour.0, colour.1, colour.2]
    })
}

/// Pixels with every channel below `level` in the rectangle `[x0, x1) x
/// [y0, y1)`: text (below 100) or text and reference lines (below 160).
fn pixels_below(image: &RgbImage, level: u8, (x0, y0): (u32, u32), (x1, y1): (u32, u32)) -> usize {
    let inside = (y0..y1).flat_map(|y| (x0..x1).map(move |x| (x, y)));
    inside.filter(|&(x, y)| image.get_pixel(x, y).0.iter().all(|&c| c < level)).count()
}

#[test]
fn axis_mapping_puts_decades_at_predicted_pixels() {
    let data = [series("a", &[(1.0, 1.0), (10.0, 0.1), (100.0, 0.01)])];
    let (_, frame) = draw(&data, &[]);
    // Data ending exactly on decades is widened by half a decade each way.
    assert_eq!(frame.x, Decades { lo: -0.5, hi: 2.5 });
    assert_eq!(frame.y, Decades { lo: -2.5, hi: 0.5 });
    let (left, right) = frame.x_pixels;
    let (top, bottom) = frame.y_pixels;
    // The plot area takes most of the image, inside the margins and labels.
    assert!(left > 40 && right < 900 - 10 && right - left > 600, "x pixels {left}..{right}");
    assert!(top > 30 && bottom < 600 - 40 && bottom - top > 400, "y pixels {top}..{bottom}");
    let at = |fraction: f64, from: i32, to: i32| from + (fraction * f64::from(to - from)).round() as i32;
    assert_eq!(frame.to_pixel((10.0, 0.1)), (at(0.5, left, right), at(0.5, bottom, top)));
    assert_eq!(frame.to_pixel((1.0, 1.0)), (at(0.5 / 3.0, left, right), at(2.5 / 3.0, bottom, top)));
    assert_eq!(frame.to_pixel((100.0, 0.01)), (at(2.5 / 3.0, left, right), at(0.5 / 3.0, bottom, top)));
}

#[test]
fn markers_appear_where_the_axis_mapping_predicts() {
    let first = series("first", &[(1.0, 1.0), (3.0, 0.4), (10.0, 0.1), (100.0, 0.01)]);
    let second = series("second", &[(2.0, 0.02), (20.0, 0.05)]);
    let data = [first.clone(), second.clone()];
    let (image, frame) = draw(&data, &[]);
    for (index, s) in data.iter().enumerate() {
        for &point in &s.points {
            let pixel = frame.to_pixel(point);
            assert!(colour_near(&image, pixel, 1, series_colour(index)), "{} point {point:?} at {pixel:?}", s.label);
        }
    }
    // Far from both curves (and from the legend, which avoids the
    // curves), neither colour appears.
    let empty = frame.to_pixel((1.0, 0.01));
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
    let labels = Labels { title: "t", x: "x", y: "y" };
    let (image, frame) =
        draw_log_log_plot(DEFAULT_PLOT_SIZE, &labels, &data, &[HLine { label: "negative".into(), y: -1.0 }])
            .expect("draw");
    assert_eq!(image.dimensions(), DEFAULT_PLOT_SIZE);
    assert_eq!(frame.x, Decades { lo: -0.5, hi: 1.5 });
    assert_eq!(frame.y, Decades { lo: -1.5, hi: 0.0 });
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
    let path = dir.path().join("default.png");
    write_log_log_plot(&path, "t", "x", "y", &data, &hlines).expect("write");
    let written = image::open(&path).expect("decode").to_rgb8();
    assert_eq!(written, render_log_log_plot(DEFAULT_PLOT_SIZE, "t", "x", "y", &data, &hlines).expect("render"));
    let leftovers = std::fs::read_dir(dir.path()).expect("list").count();
    assert_eq!(leftovers, 1, "no temporary files remain");
    let sized = render_log_log_plot((640, 480), "t", "x", "y", &data, &hlines).expect("render");
    assert_eq!(sized.dimensions(), (640, 480));
    assert_eq!(
        render_log_log_plot(MIN_PLOT_SIZE, "t", "x", "y", &data, &hlines).expect("render").dimensions(),
        MIN_PLOT_SIZE
    );
}

#[test]
fn writing_into_a_missing_directory_is_an_io_error() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("missing").join("plot.png");
    let result = write_log_log_plot(&path, "t", "x", "y", &[series("a", &[(1.0, 1.0)])], &[]);
    assert!(matches!(result, Err(PlotError::Io { .. })));
}

#[test]
fn title_labels_and_reference_lines_are_drawn() {
    let data = [series("none", &[(0.5, 0.3), (1.0, 0.2), (8.0, 0.05)])];
    let line = HLine { label: "none @ 64 spp".into(), y: 0.07 };
    let (image, frame) = draw(&data, std::slice::from_ref(&line));
    let (width, height) = image.dimensions();
    let (left, right) = (frame.x_pixels.0 as u32, frame.x_pixels.1 as u32);
    let (top, bottom) = (frame.y_pixels.0 as u32, frame.y_pixels.1 as u32);
    assert!(pixels_below(&image, 100, (0, 0), (width, top)) > 100, "the title is lettered above the plot");
    assert!(pixels_below(&image, 100, (0, bottom + 2), (width, height)) > 100, "x tick labels and axis label");
    assert!(pixels_below(&image, 100, (0, top), (left - 1, bottom)) > 100, "y tick labels and axis label");
    let plain = render(&data, &[]).expect("render");
    assert!(pixels_below(&plain, 100, (0, 0), (width, top)) > 100);
    // The dashed line: its grey appears along the line, with gaps.
    let (_, y) = frame.to_pixel((1.0, line.y));
    let grey = image::Rgb([HLINE_COLOUR.0, HLINE_COLOUR.1, HLINE_COLOUR.2]);
    let on_line = (left..=right).filter(|&x| *image.get_pixel(x, y as u32) == grey).count();
    let span = (right - left) as usize;
    assert!(on_line > span / 3 && on_line < span * 9 / 10, "{on_line} of {span} pixels dashed");
    // Its label sits above the line's right end.
    let label_region = pixels_below(&image, 160, (right - 200, y as u32 - 24), (right, y as u32 - 2));
    assert!(label_region > 50, "{label_region} label pixels");
}

#[test]
fn the_legend_takes_the_freest_corner() {
    // Curves through the top right leave the top left free.
    let data =
        [series("rising", &[(1.0, 0.01), (10.0, 0.1), (100.0, 1.0)]), series("flat", &[(20.0, 1.5), (100.0, 1.5)])];
    let (_, frame) = draw(&data, &[]);
    let curves: Vec<_> = data.iter().map(|s| plottable_points(&s.points)).collect();
    let corner = legend_corner(&frame, (150, 60), &occupied_pixels(&frame, &curves, &[]));
    assert_eq!(corner, (LEGEND_INSET, LEGEND_INSET));
    // With nothing in the top right, the legend goes there.
    let falling = [series("falling", &[(1.0, 1.0), (100.0, 0.01)])];
    let (_, frame) = draw(&falling, &[]);
    let curves: Vec<_> = falling.iter().map(|s| plottable_points(&s.points)).collect();
    let (x, y) = legend_corner(&frame, (150, 60), &occupied_pixels(&frame, &curves, &[]));
    assert_eq!(y, LEGEND_INSET);
    assert!(x > (frame.x_pixels.1 - frame.x_pixels.0) / 2);
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
fn tick_values_round_trip_through_their_labels() {
    for exponent in -6..=6 {
        for mantissa in 1..=9 {
            let tick = Tick { mantissa, exponent };
            assert_eq!(Tick::nearest(tick.value()), tick);
            assert_eq!(tick_label(tick.value()), tick.label());
        }
    }
    assert_eq!(Tick::nearest(9.9999), Tick { mantissa: 1, exponent: 1 });
}

#[test]
fn ranges_snap_to_half_decades_and_ticks_follow_the_span() {
    let narrow = Decades::padded(0.5, 8.0);
    assert_eq!(narrow, Decades { lo: -0.5, hi: 1.0 });
    let labels: Vec<String> = narrow.ticks(10).iter().map(|t| t.label()).collect();
    assert_eq!(labels, ["0.5", "1", "2", "5", "10"]);
    let wide = Decades::padded(2e-4, 3.0);
    assert_eq!(wide, Decades { lo: -4.0, hi: 0.5 });
    let labels: Vec<String> = wide.ticks(10).iter().map(|t| t.label()).collect();
    assert_eq!(labels, ["1e-4", "1e-3", "0.01", "0.1", "1"]);
    let crowded = Decades::padded(1e-40, 1e40);
    assert!(crowded.ticks(8).len() <= 9);
    let single = Decades::padded(3.0, 3.0);
    assert_eq!(single, Decades { lo: 0.0, hi: 0.5 });
    let labels: Vec<String> = single.ticks(10).iter().map(|t| t.label()).collect();
    assert_eq!(labels, ["1", "2", "3"]);
}
