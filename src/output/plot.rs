//! PNG plots drawn with plotters' bitmap backend and an embedded font (no system fonts).

use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// DejaVu Sans Mono (Bitstream Vera licence, see assets/DejaVuSansMono.LICENSE).
static FONT: &[u8] = include_bytes!("../../assets/DejaVuSansMono.ttf");

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

/// Draws line series into a PNG at `path`.
pub fn lines(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), String> {
    draw(path, title, x_label, y_label, series, false)
}

/// Draws curves in the plane (x, y in m) into a PNG at `path`, one metre on x as long as
/// one on y, so that angles read true (crack paths).
pub fn plane(path: &Path, title: &str, series: &[Series]) -> Result<(), String> {
    draw(path, title, "x (m)", "y (m)", series, true)
}

/// A tick label; a rounding residue of zero (a billionth of the axis's scale) reads 0.
fn tick(v: f64, scale: f64) -> String {
    let v = if v.abs() < 1e-9 * scale { 0.0 } else { v };
    format!("{v:.2e}")
}

fn draw(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    equal: bool,
) -> Result<(), String> {
    register();
    let pts = || series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts().filter(|(x, y)| x.is_finite() && y.is_finite()) {
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
    let mut pad = 0.05 * (y1 - y0).abs().max(1e-300);
    let size = if equal { (760, 760) } else { (900, 560) };
    if equal {
        // A square plot area over the larger of the two ranges, each centred.
        let half = 0.55 * (x1 - x0).max(y1 - y0);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        (x0, x1, y0, y1, pad) = (cx - half, cx + half, cy - half, cy + half, 0.0);
    }
    let root = BitMapBackend::new(path, size).into_drawing_area();
    let e = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .margin_right(48)
        .x_label_area_size(45)
        .y_label_area_size(90)
        .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| tick(*v, x0.abs().max(x1.abs())))
        .y_label_formatter(&|v| tick(*v, y0.abs().max(y1.abs())))
        .draw()
        .map_err(|x| e(&x))?;
    for (i, s) in series.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(
                s.points.iter().copied(),
                colour.stroke_width(2),
            ))
            .map_err(|x| e(&x))?
            .label(s.label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))
}
