//! PNG plots drawn with plotters' bitmap backend and an embedded font (no system fonts).
//! Plots a user can trust: the legend sits in headroom above the data, never over it;
//! curves after the first are dashed, so one lying on another (a zero K_II on its zero
//! reference) still shows; a series breaks at NaN rows instead of jumping to them, and a
//! lone point is marked.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// DejaVu Sans Mono (Bitstream Vera licence, see assets/DejaVuSansMono.LICENSE).
static FONT: &[u8] = include_bytes!("../../../assets/DejaVuSansMono.ttf");

fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded file is a valid TrueType font; a failure leaves text unrendered.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// A named series of (x, y) points.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Points.
    pub points: Vec<(f64, f64)>,
}

/// One panel of a figure: its y-axis label and its series.
pub struct Panel<'a> {
    /// Y-axis label.
    pub y_label: &'a str,
    /// Series drawn in it.
    pub series: Vec<Series<'a>>,
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Draws line series into a PNG at `path`.
pub fn lines(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), String> {
    figure(path, (900, 560), title, |area| {
        draw(area, x_label, y_label, series, false)
    })
}

/// A white PNG of `size` pixels at `path` with `title` on top; `body` draws below it.
fn figure(
    path: &Path,
    size: (u32, u32),
    title: &str,
    body: impl FnOnce(&Area) -> Result<(), String>,
) -> Result<(), String> {
    register();
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    body(&root.titled(title, ("sans-serif", 22)).map_err(err)?)?;
    root.present().map_err(err)
}

/// Draws panels stacked top to bottom on one time axis into a PNG at `path`; the first
/// panel gets `share` of the height, the others split the rest.
pub fn panels(
    path: &Path,
    title: &str,
    x_label: &str,
    panels: &[Panel],
    share: f64,
) -> Result<(), String> {
    figure(path, (900, 780), title, |area| {
        let mut rest = area.clone();
        let height = rest.dim_in_pixel().1 as f64;
        for (k, p) in panels.iter().enumerate() {
            let left = panels.len() - k;
            let panel = if left == 1 {
                rest.clone()
            } else {
                let h = if k == 0 {
                    share * height
                } else {
                    rest.dim_in_pixel().1 as f64 / left as f64
                };
                let (top, bottom) = rest.split_vertically(h as u32);
                rest = bottom;
                top
            };
            draw(&panel, x_label, p.y_label, &p.series, false)?;
        }
        Ok(())
    })
}

/// Draws curves in the plane (x, y in m) into a PNG at `path`, one metre on x as long as
/// one on y, so that angles read true (crack paths).
pub fn plane(path: &Path, title: &str, labels: [&str; 2], series: &[Series]) -> Result<(), String> {
    figure(path, (760, 800), title, |area| {
        draw(area, labels[0], labels[1], series, true)
    })
}

/// Draws series on log-log axes (positive values only; others are left out) into a PNG
/// at `path`, with markers at the points: error against cost.
pub fn log_log(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), String> {
    let positive = |s: &Series| -> Vec<(f64, f64)> {
        (s.points.iter().copied())
            .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
            .collect()
    };
    let all: Vec<(f64, f64)> = series.iter().flat_map(positive).collect();
    figure(path, (900, 560), title, |area| {
        if all.is_empty() {
            // Nothing a log axis can show (every error 0, or no finished run): say so.
            let style = ("sans-serif", 20).into_text_style(area);
            return (area.draw_text("no positive values to draw", &style, (20, 20))).map_err(err);
        }
        let (x0, x1) =
            (all.iter()).fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
        let (y0, y1) =
            (all.iter()).fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
        // Half a decade around the data, more above for the legend.
        let (x0, x1) = (x0 / 1.5, x1 * 1.5);
        // x ticks at the data's own x values (cell sizes, wall times), each at least an
        // eighth of a decade from the last, so that an axis spanning under a decade still
        // names every point.
        let mut ticks: Vec<f64> = all.iter().map(|p| p.0).collect();
        ticks.sort_by(f64::total_cmp);
        let mut keep: Vec<f64> = Vec::new();
        for t in ticks {
            if keep.last().is_none_or(|&k| (t / k).log10() >= 0.125) {
                keep.push(t);
            }
        }
        let (y0, y1) = (y0 / 2.0, y1 * 2.0 * 10f64.powf(0.25 * series.len() as f64));
        let mut chart = ChartBuilder::on(area)
            .margin(12)
            .margin_right(48)
            .x_label_area_size(45)
            .y_label_area_size(90)
            .build_cartesian_2d(
                (x0..x1).log_scale().with_key_points(keep),
                (y0..y1).log_scale(),
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&|v| format!("{v:.2e}"))
            .y_label_formatter(&|v| format!("{v:.1e}"))
            .draw()
            .map_err(err)?;
        for (i, s) in series.iter().enumerate() {
            let mut pts = positive(s);
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let style = Palette99::pick(i).to_rgba().stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.clone(), style))
                .map_err(err)?
                .label(s.label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
            chart
                .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, style.filled())))
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()
            .map_err(err)
    })
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// A tick label on an axis reaching `scale` in magnitude: 0 as "0" (and a rounding
/// residue of it, a billionth of the scale), plain notation on an axis of moderate scale,
/// scientific otherwise, so that one axis reads in one notation.
fn tick(v: f64, scale: f64) -> String {
    if v.abs() <= 1e-9 * scale {
        return "0".into();
    }
    if (0.1..1e4).contains(&scale) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

/// The finite runs of a series: NaN or infinite points break the line.
fn runs(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    points
        .split(|(x, y)| !(x.is_finite() && y.is_finite()))
        .filter(|r| !r.is_empty())
        .map(<[(f64, f64)]>::to_vec)
        .collect()
}

fn draw(
    area: &Area,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    equal: bool,
) -> Result<(), String> {
    let finite = || {
        (series.iter().flat_map(|s| s.points.iter()))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
    };
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in finite() {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return Ok(());
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        let half = 0.5 * y0.abs().max(1e-300);
        (y0, y1) = (y0 - half, y1 + half);
    }
    // The plotting area in pixels (the margins and label areas set below taken off).
    let (w, h) = area.dim_in_pixel();
    let (plot_w, plot_h) = ((w as f64 - 150.0).max(100.0), (h as f64 - 69.0).max(100.0));
    // Headroom for the legend above the data: each label takes about 20 pixels.
    let legend = (series.len() as f64 * 20.0 + 16.0).min(0.6 * plot_h);
    let span = y1 - y0;
    let mut bottom = y0 - 0.04 * span;
    let mut top = y1 + 0.04 * span;
    top += (top - bottom) * legend / (plot_h - legend);
    if equal {
        // As many metres per pixel on x as on y: widen whichever range is short.
        let sx = 1.08 * (x1 - x0);
        let unit = (sx / plot_w).max((top - bottom) / plot_h);
        let (cx, grow) = (0.5 * (x0 + x1), 0.5 * (unit * plot_h - (top - bottom)));
        (x0, x1) = (cx - 0.5 * unit * plot_w, cx + 0.5 * unit * plot_w);
        (bottom, top) = (bottom - grow, top + grow);
    }
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_right(48)
        .x_label_area_size(45)
        .y_label_area_size(90)
        .build_cartesian_2d(x0..x1, bottom..top)
        .map_err(err)?;
    let (xs, ys) = (x0.abs().max(x1.abs()), bottom.abs().max(top.abs()));
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| tick(*v, xs))
        .y_label_formatter(&|v| tick(*v, ys))
        .draw()
        .map_err(err)?;
    for (i, s) in series.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        let style = colour.stroke_width(if i == 0 { 3 } else { 2 });
        let mut labelled = false;
        for run in runs(&s.points) {
            let drawn = if run.len() == 1 {
                // A lone point (a reference at one time) would draw no line: mark it.
                chart.draw_series(run.into_iter().map(|p| Circle::new(p, 5, style)))
            } else if i == 0 {
                chart.draw_series(LineSeries::new(run, style))
            } else {
                let dash = 6 + 2 * (i as u32 % 4);
                chart.draw_series(DashedLineSeries::new(run, dash, 4, style))
            }
            .map_err(err)?;
            if !labelled {
                drawn
                    .label(s.label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
                labelled = true;
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ticks read as numbers a user would write; NaN rows split a line into its runs.
    #[test]
    fn ticks_and_runs() {
        assert_eq!(tick(0.0, 1.0), "0");
        assert_eq!(tick(1.7e-18, 1e-2), "0");
        assert_eq!(tick(0.25, 1.0), "0.25");
        assert_eq!(tick(1500.0, 2e3), "1500");
        assert_eq!(tick(5e-3, 1.2e-2), "5.00e-3");
        assert_eq!(tick(2.5e7, 1e8), "2.50e7");
        assert_eq!(tick(-3.0e-5, 1e-4), "-3.00e-5");
        let nan = f64::NAN;
        let r = runs(&[(0.0, nan), (1.0, 2.0), (2.0, 3.0), (3.0, nan), (4.0, 1.0)]);
        assert_eq!(r, vec![vec![(1.0, 2.0), (2.0, 3.0)], vec![(4.0, 1.0)]]);
    }
}
