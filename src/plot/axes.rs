//! Log-log axes: data bounds, decade ranges, ticks and the plot's layout.

use super::*;

/// The extent of the data in data units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct DataBounds {
    pub(super) x_min: f64,
    pub(super) x_max: f64,
    pub(super) y_min: f64,
    pub(super) y_max: f64,
}

impl DataBounds {
    /// The bounds of all curve points and reference lines; `None` without a
    /// single curve point (reference lines alone give no `x` range).
    pub(super) fn of(curves: &[Vec<(f64, f64)>], lines: &[&HLine]) -> Option<Self> {
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

    pub(super) fn include_y(&mut self, y: f64) {
        self.y_min = self.y_min.min(y);
        self.y_max = self.y_max.max(y);
    }
}

/// How close (in decades) data may come to the end of an axis before the
/// axis is widened by another half decade.
pub(super) const AXIS_MARGIN_DECADES: f64 = 0.02;

/// Slack for comparing tick positions with the axis ends.
pub(super) const LOG_EPSILON: f64 = 1e-9;

/// An axis range in decades: `lo` and `hi` are base-10 logarithms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct LogRange {
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl LogRange {
    /// The smallest range of whole or half decades holding `[min, max]` with
    /// a little margin; never empty.
    pub(super) fn padded(min: f64, max: f64) -> Self {
        let lo = ((min.log10() - AXIS_MARGIN_DECADES) * 2.0).floor() / 2.0;
        let hi = ((max.log10() + AXIS_MARGIN_DECADES) * 2.0).ceil() / 2.0;
        if hi > lo {
            LogRange { lo, hi }
        } else {
            LogRange { lo: lo - 0.5, hi: lo + 0.5 }
        }
    }

    pub(super) fn decades(&self) -> f64 {
        self.hi - self.lo
    }

    pub(super) fn contains_log(&self, log: f64) -> bool {
        log >= self.lo - LOG_EPSILON && log <= self.hi + LOG_EPSILON
    }

    /// Where `log` (a base-10 logarithm) lies along the range, 0 at `lo` and
    /// 1 at `hi`.
    pub(super) fn fraction_of_log(&self, log: f64) -> f64 {
        (log - self.lo) / self.decades()
    }

    /// The powers of ten whose exponents lie within the range.
    pub(super) fn decade_exponents(&self) -> impl Iterator<Item = i32> + '_ {
        let first = self.lo.floor() as i32;
        let last = self.hi.ceil() as i32;
        (first..=last).filter(|&e| self.contains_log(f64::from(e)))
    }

    /// The multiples of each power of ten that get a labelled tick: 1, 2 and
    /// 5 when the range spans less than two decades (and 3 too below one
    /// decade), else 1 alone.
    pub(super) fn tick_mantissas(&self) -> &'static [u8] {
        match self.decades() {
            d if d < 1.0 => &[1, 2, 3, 5],
            d if d < 2.0 => &[1, 2, 5],
            _ => &[1],
        }
    }

    /// Labelled ticks at [`Self::tick_mantissas`] times each power of ten, or
    /// at every `step`-th power of ten when more than `max_labels` decades
    /// would be crowded.
    pub(super) fn ticks(&self, max_labels: usize) -> Vec<Tick> {
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
pub(super) fn decade_step(decades: f64, max_labels: usize) -> i32 {
    let per_label = (decades / max_labels.max(1) as f64).ceil();
    per_label.clamp(1.0, f64::from(i32::MAX)) as i32
}

/// A labelled tick at `mantissa * 10^exponent`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Tick {
    pub(super) mantissa: u8,
    pub(super) exponent: i32,
}

impl Tick {
    pub(super) fn log10(self) -> f64 {
        f64::from(self.exponent) + f64::from(self.mantissa).log10()
    }

    pub(super) fn is_decade(self) -> bool {
        self.mantissa == 1
    }

    /// Plain decimals from 0.01 to 5000 ("0.05", "10"), else short
    /// scientific notation ("1e-3", "2e4").
    pub(super) fn label(self) -> String {
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
pub(super) struct Rect {
    pub(super) left: i32,
    pub(super) top: i32,
    pub(super) right: i32,
    pub(super) bottom: i32,
}

impl Rect {
    pub(super) fn with_size(left: i32, top: i32, width: i32, height: i32) -> Self {
        Rect { left, top, right: left + width - 1, bottom: top + height - 1 }
    }

    pub(super) fn contains(&self, (x, y): (i32, i32)) -> bool {
        (self.left..=self.right).contains(&x) && (self.top..=self.bottom).contains(&y)
    }

    pub(super) fn width(&self) -> i32 {
        self.right - self.left + 1
    }

    pub(super) fn height(&self) -> i32 {
        self.bottom - self.top + 1
    }
}

pub(super) const TICK_SCALE: i32 = 2;
pub(super) const LABEL_SCALE: i32 = 2;
pub(super) const TITLE_SCALE: i32 = 3;
pub(super) const OUTER_PAD: i32 = 12;
pub(super) const TICK_LENGTH: i32 = 6;
pub(super) const MINOR_TICK_LENGTH: i32 = 3;
pub(super) const TICK_LABEL_GAP: i32 = 5;
pub(super) const AXIS_LABEL_GAP: i32 = 10;
pub(super) const RIGHT_MARGIN: i32 = 34;
/// Least spacing between labelled decades, in pixels.
pub(super) const MIN_X_LABEL_SPACING: i32 = 80;
pub(super) const MIN_Y_LABEL_SPACING: i32 = 40;
/// Least pixels per decade for unlabelled decade gridlines and minor ticks.
pub(super) const MIN_DECADE_PIXELS_FOR_GRID: f64 = 8.0;
pub(super) const MIN_DECADE_PIXELS_FOR_MINOR_TICKS: f64 = 40.0;

/// Where the plot area lies in the image, and the axes' ranges and ticks.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Layout {
    pub(super) size: (i32, i32),
    pub(super) plot: Rect,
    pub(super) x: LogRange,
    pub(super) y: LogRange,
    pub(super) x_ticks: Vec<Tick>,
    pub(super) y_ticks: Vec<Tick>,
}

impl Layout {
    pub(super) fn new(size: (u32, u32), bounds: &DataBounds) -> Self {
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

    pub(super) fn x_pixel_of_log(&self, log: f64) -> i32 {
        let span = f64::from(self.plot.right - self.plot.left);
        self.plot.left + (self.x.fraction_of_log(log) * span).round() as i32
    }

    pub(super) fn y_pixel_of_log(&self, log: f64) -> i32 {
        let span = f64::from(self.plot.bottom - self.plot.top);
        self.plot.bottom - (self.y.fraction_of_log(log) * span).round() as i32
    }

    /// The pixel of the data point `(x, y)`; both must be positive.
    pub(super) fn to_pixel(&self, (x, y): (f64, f64)) -> (i32, i32) {
        (self.x_pixel_of_log(x.log10()), self.y_pixel_of_log(y.log10()))
    }

    pub(super) fn pixels_per_x_decade(&self) -> f64 {
        f64::from(self.plot.width()) / self.x.decades()
    }

    pub(super) fn pixels_per_y_decade(&self) -> f64 {
        f64::from(self.plot.height()) / self.y.decades()
    }
}

/// How many decade labels fit along `pixels` at `spacing` apart, judged by
/// the label count per decade of `range`.
pub(super) fn label_count(pixels: i32, spacing: i32, range: LogRange) -> usize {
    let fitting = usize::try_from((pixels / spacing.max(1)).max(2)).unwrap_or(2);
    (fitting / range.tick_mantissas().len()).max(1)
}

pub(super) fn to_i32(value: u32) -> i32 {
    i32::try_from(value).unwrap_or(i32::MAX)
}
