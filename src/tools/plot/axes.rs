//! Log-log axes: data bounds, decade ranges, ticks and their labels.

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
pub(super) struct Decades {
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl Decades {
    /// The smallest range of whole or half decades holding `[min, max]` with
    /// a little margin; never empty.
    pub(super) fn padded(min: f64, max: f64) -> Self {
        let lo = ((min.log10() - AXIS_MARGIN_DECADES) * 2.0).floor() / 2.0;
        let hi = ((max.log10() + AXIS_MARGIN_DECADES) * 2.0).ceil() / 2.0;
        if hi > lo {
            Decades { lo, hi }
        } else {
            Decades { lo: lo - 0.5, hi: lo + 0.5 }
        }
    }

    pub(super) fn decades(&self) -> f64 {
        self.hi - self.lo
    }

    /// The ends in data units.
    pub(super) fn lo_value(&self) -> f64 {
        10f64.powf(self.lo)
    }

    pub(super) fn hi_value(&self) -> f64 {
        10f64.powf(self.hi)
    }

    fn contains_log(&self, log: f64) -> bool {
        log >= self.lo - LOG_EPSILON && log <= self.hi + LOG_EPSILON
    }

    /// Where `log` (a base-10 logarithm) lies along the range, 0 at `lo` and
    /// 1 at `hi`.
    pub(super) fn fraction_of_log(&self, log: f64) -> f64 {
        (log - self.lo) / self.decades()
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

    /// The values 1x..9x of each power of ten within the range that are not
    /// among `ticks`: the faint gridlines.
    pub(super) fn minor_values(&self, ticks: &[Tick]) -> Vec<f64> {
        let first = self.lo.floor() as i32;
        let last = self.hi.ceil() as i32;
        (first..=last)
            .flat_map(|exponent| (1..=9).map(move |mantissa| Tick { mantissa, exponent }))
            .filter(|tick| self.contains_log(tick.log10()) && !ticks.contains(tick))
            .map(Tick::value)
            .collect()
    }
}

/// Every how many decades to label so that at most about `max_labels` fit.
pub(super) fn decade_step(decades: f64, max_labels: usize) -> i32 {
    let per_label = (decades / max_labels.max(1) as f64).ceil();
    per_label.clamp(1.0, f64::from(i32::MAX)) as i32
}

/// How many decade labels fit along `pixels` at `spacing` apart, judged by
/// the label count per decade of `range`.
pub(super) fn label_count(pixels: i32, spacing: i32, range: Decades) -> usize {
    let fitting = usize::try_from((pixels / spacing.max(1)).max(2)).unwrap_or(2);
    (fitting / range.tick_mantissas().len()).max(1)
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

    pub(super) fn value(self) -> f64 {
        f64::from(self.mantissa) * 10f64.powi(self.exponent)
    }

    /// The tick `mantissa * 10^exponent` (mantissa 1 to 9) nearest `value`
    /// (positive): the inverse of [`Self::value`] for the ticks plotted.
    pub(super) fn nearest(value: f64) -> Self {
        let mut exponent = value.log10().floor() as i32;
        let mut mantissa = (value / 10f64.powi(exponent)).round();
        if mantissa >= 10.0 {
            exponent += 1;
            mantissa = 1.0;
        }
        Tick { mantissa: mantissa.clamp(1.0, 9.0) as u8, exponent }
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
