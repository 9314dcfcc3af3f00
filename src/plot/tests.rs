//! Tests of the log-log plots: ranges, ticks, layout and drawing.

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
            assert!(colour_near(&image, pixel, 1, series_colour(index)), "{} point {point:?} at {pixel:?}", s.label);
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
