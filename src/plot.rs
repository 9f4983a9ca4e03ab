//! PNG line charts with plotters' bitmap backend and a bundled font (DejaVu Sans, see
//! assets/DejaVuSans-LICENSE.txt), so plots look the same on every machine. Files are written
//! to a temporary name and renamed.

use std::path::Path;
use std::sync::Once;

use plotters::element::DashedPathElement;
use plotters::prelude::*;

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bundled font is valid OpenType; a failure would leave plotters without a font
        // and show as an error when drawing text.
        let _ =
            plotters::style::register_font("sans-serif", FontStyle::Normal, include_bytes!("../assets/DejaVuSans.ttf"));
    });
}

/// One curve: label, points, colour index.
pub struct Curve<'a> {
    pub label: &'a str,
    pub points: Vec<(f64, f64)>,
    pub dashed: bool,
}

/// Tableau's ten qualitative colours; with three line patterns, thirty distinct styles.
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

#[derive(Clone, Copy, PartialEq)]
enum Pattern {
    Solid,
    Dashed,
    Dotted,
}

/// A curve's colour and pattern: a library scheme's own wherever its name starts the label (one
/// style per scheme in every figure), otherwise the curve's place in its panel; `dashed`
/// curves (the redistributed mass) keep their scheme's colour with another pattern.
fn style(curve: &Curve, k: usize) -> (RGBColor, Pattern) {
    let first = curve.label.split([' ', '(', ',']).next().unwrap_or("");
    let index = crate::driver::all_schemes().iter().position(|s| *s == first).unwrap_or(k);
    let pattern = match (index / COLOURS.len()) % 3 {
        0 => Pattern::Solid,
        1 => Pattern::Dashed,
        _ => Pattern::Dotted,
    };
    let pattern = match (curve.dashed, pattern) {
        (false, p) => p,
        (true, Pattern::Solid) => Pattern::Dashed,
        (true, _) => Pattern::Dotted,
    };
    (COLOURS[index % COLOURS.len()], pattern)
}

/// Tick labels for values over [lo, hi]: as many decimals as the tick spacing needs, exponent
/// form for very small or large magnitudes, never `-0`; whole numbers only on an integer axis.
fn ticks(lo: f64, hi: f64, integer: bool) -> impl Fn(&f64) -> String {
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    let magnitude = lo.abs().max(hi.abs());
    let decimals = (-(span / 10.0).log10().floor()).clamp(0.0, 6.0) as usize;
    let exponent = magnitude >= 1e6 || (magnitude < 1e-3 && magnitude > 0.0);
    move |v: &f64| {
        let v = if v.abs() < span * 1e-9 { 0.0 } else { *v };
        if integer {
            return if (v - v.round()).abs() < 1e-9 { format!("{}", v.round() as i64) } else { String::new() };
        }
        let text = if exponent { format!("{v:.1e}") } else { format!("{v:.decimals$}") };
        match text.strip_prefix('-') {
            Some(rest) if rest.chars().all(|c| matches!(c, '0' | '.' | 'e')) => rest.to_string(),
            _ => text,
        }
    }
}

/// Draws `panels` stacked vertically (title, y label, curves) over a shared x label.
pub fn panels(path: &Path, x_label: &str, panels: &[(&str, &str, Vec<Curve<'_>>)]) -> Result<(), String> {
    register_font();
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp.png",
        path.file_name().map(|n| n.to_string_lossy()).unwrap_or_default(),
        std::process::id()
    ));
    let result = draw(&tmp, x_label, panels).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn draw(path: &Path, x_label: &str, panels: &[(&str, &str, Vec<Curve<'_>>)]) -> Result<(), String> {
    let height = 380 * panels.len().max(1) as u32;
    let root = BitMapBackend::new(path, (1200, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let areas = root.split_evenly((panels.len().max(1), 1));
    for (area, (title, y_label, curves)) in areas.iter().zip(panels) {
        // The legend has its own column right of the plot: it never covers data or axes.
        let (plot, legend) = area.split_horizontally(area.dim_in_pixel().0 - 250);
        panel(&plot, title, x_label, y_label, curves)?;
        draw_legend(&legend, curves)?;
    }
    root.present().map_err(|e| e.to_string())
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

fn panel(area: &Area, title: &str, x_label: &str, y_label: &str, curves: &[Curve]) -> Result<(), String> {
    let finite = |(x, y): &&(f64, f64)| x.is_finite() && y.is_finite();
    let points: Vec<(f64, f64)> = curves.iter().flat_map(|c| c.points.iter().filter(finite)).copied().collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y) in &points {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if points.is_empty() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    // Counts (Newton iterations, active points) have whole ticks.
    let integer = !points.is_empty() && points.iter().all(|(_, y)| y.fract() == 0.0) && y1 - y0 <= 1e6;
    let pad = ((y1 - y0) * 0.05).max(if integer { 0.5 } else { 1e-12 * y1.abs().max(1.0) });
    let (ylo, yhi) = (y0 - pad, y1 + pad);
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .margin_top(6)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1.max(x0 + 1e-12), ylo..yhi)
        .map_err(|e| e.to_string())?;
    let (x_ticks, y_ticks) = (ticks(x0, x1, false), ticks(ylo, yhi, integer));
    let y_count = if integer { ((yhi - ylo).floor() as usize + 1).clamp(2, 11) } else { 10 };
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .y_labels(y_count)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| e.to_string())?;
    for (k, c) in curves.iter().enumerate() {
        let (colour, pattern) = style(c, k);
        let line = ShapeStyle { color: colour.to_rgba(), filled: false, stroke_width: 2 };
        let data = c.points.iter().copied().filter(|p| finite(&p));
        match pattern {
            // Segment by segment: plotters joins a wide path's segments with miters, which
            // shoot far out of the panel where an oscillating curve turns sharply.
            Pattern::Solid => {
                let points: Vec<(f64, f64)> = data.collect();
                chart.draw_series(points.windows(2).map(|w| PathElement::new(vec![w[0], w[1]], line))).map(|_| ())
            }
            Pattern::Dashed => chart.draw_series(DashedLineSeries::new(data, 10, 5, line)).map(|_| ()),
            Pattern::Dotted => chart.draw_series(DashedLineSeries::new(data, 2, 4, line)).map(|_| ()),
        }
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// The curves' labels with their line styles, top down, in as many rows as fit.
fn draw_legend(area: &Area, curves: &[Curve]) -> Result<(), String> {
    if curves.is_empty() {
        return Ok(());
    }
    let (_, h) = area.dim_in_pixel();
    let row = ((h as i32 - 40) / curves.len() as i32).clamp(10, 22);
    let size = (row - 4).clamp(9, 14);
    for (k, c) in curves.iter().enumerate() {
        let (colour, pattern) = style(c, k);
        let y = 34 + row * k as i32;
        let line = ShapeStyle { color: colour.to_rgba(), filled: false, stroke_width: 2 };
        let sample = vec![(8, y), (40, y)];
        match pattern {
            Pattern::Solid => area.draw(&PathElement::new(sample, line)),
            Pattern::Dashed => area.draw(&DashedPathElement::new(sample, 8, 4, line)),
            Pattern::Dotted => area.draw(&DashedPathElement::new(sample, 2, 4, line)),
        }
        .map_err(|e| e.to_string())?;
        area.draw(&Text::new(c.label.to_string(), (48, y - size / 2 - 1), ("sans-serif", size)))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}
