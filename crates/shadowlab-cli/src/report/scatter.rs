//! Quality/cost scatter plots (the compare report's and the sweep report's): a quality figure
//! (wrong % or mean FLIP) against a cost, marker area by memory (shadow data bytes), the Pareto
//! front drawn and marked, every point labelled. SVG from plotters (no fonts,
//! no network). Costs spanning more than a factor 20 are drawn on a log10 axis.

use anyhow::{anyhow, Result};
use plotters::prelude::*;

/// Indices of the points (cost, quality) on the Pareto front, both minimised: no other point
/// is at most as costly and at most as wrong, and better in one. Sorted by cost, then quality;
/// equal points are all on the front; non-finite points are never on it.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| finite(&points[i]))
        .filter(|&i| {
            let p = points[i];
            !points.iter().any(|q| finite(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0).then(points[a].1.total_cmp(&points[b].1)).then(a.cmp(&b)));
    front
}

/// One point of a scatter.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub label: String,
    pub cost: f64,
    /// The quality figure (lower is better): wrong % or mean FLIP.
    pub quality: f64,
    pub bytes: u64,
}

const FRONT: RGBColor = RGBColor(214, 39, 40);
const OTHER: RGBColor = RGBColor(31, 119, 180);

/// Marker radius in pixels: 3 to 14, its area growing with the bytes (relative to the largest).
pub fn radius(bytes: u64, max_bytes: u64) -> i32 {
    if max_bytes == 0 {
        return 3;
    }
    3 + (11.0 * (bytes as f64 / max_bytes as f64).sqrt()).round() as i32
}

/// Whether the costs are drawn on a log axis (all positive, spanning more than 20x).
pub fn log_axis(points: &[Point]) -> bool {
    let lo = points.iter().map(|p| p.cost).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p.cost).fold(f64::NEG_INFINITY, f64::max);
    lo > 0.0 && hi / lo > 20.0
}

/// The SVG of one scatter; `cost_name` labels the x axis, `quality_name` the y axis.
pub fn svg(title: &str, cost_name: &str, quality_name: &str, points: &[Point]) -> Result<String> {
    let points: Vec<&Point> = points.iter().filter(|p| p.cost.is_finite() && p.quality.is_finite()).collect();
    let log = log_axis(&points.iter().map(|p| (*p).clone()).collect::<Vec<_>>());
    let x = |c: f64| if log { c.log10() } else { c };
    let xs: Vec<f64> = points.iter().map(|p| x(p.cost)).collect();
    let (mut x0, mut x1) = (xs.iter().copied().fold(f64::INFINITY, f64::min), xs.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    if !x0.is_finite() {
        (x0, x1) = (0.0, 1.0);
    }
    let pad = if x1 > x0 { (x1 - x0) * 0.08 } else { x0.abs().max(1.0) * 0.1 };
    let (x0, x1) = if log { (x0 - pad, x1 + pad) } else { ((x0 - pad).max(0.0_f64.min(x0)), x1 + pad) };
    let ymax = points.iter().map(|p| p.quality).fold(0.0f64, f64::max);
    let ymax = if ymax > 0.0 { ymax * 1.15 } else { 1.0 };
    let max_bytes = points.iter().map(|p| p.bytes).max().unwrap_or(0);
    let front = pareto_front(&points.iter().map(|p| (p.cost, p.quality)).collect::<Vec<_>>());
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (760, 460)).into_drawing_area();
        let err = |e: &dyn std::fmt::Display| anyhow!("scatter '{title}': {e}");
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut c = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 15))
            .margin(10)
            .x_label_area_size(44)
            .y_label_area_size(52)
            .build_cartesian_2d(x0..x1, 0f64..ymax)
            .map_err(|e| err(&e))?;
        let x_desc = if log { format!("{cost_name} (log scale)") } else { cost_name.to_string() };
        let bytes_axis = cost_name.contains("bytes");
        let fmt_x = |v: &f64| {
            let c = if log { 10f64.powf(*v) } else { *v };
            if bytes_axis && c >= 1024.0 {
                let (d, u) = if c >= 1048576.0 { (1048576.0, "MiB") } else { (1024.0, "KiB") };
                format!("{:.1} {u}", c / d)
            } else if c.abs() >= 1e6 {
                format!("{c:.2e}")
            } else if c.abs() >= 100.0 || c == c.round() {
                format!("{c:.0}")
            } else {
                format!("{c:.2}")
            }
        };
        c.configure_mesh()
            .x_desc(x_desc)
            .y_desc(quality_name)
            .x_label_formatter(&fmt_x)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(|e| err(&e))?;
        let fpts: Vec<(f64, f64)> = front.iter().map(|&i| (xs[i], points[i].quality)).collect();
        c.draw_series(LineSeries::new(fpts, FRONT.stroke_width(2))).map_err(|e| err(&e))?;
        for (i, p) in points.iter().enumerate() {
            let on = front.contains(&i);
            let r = radius(p.bytes, max_bytes);
            let style = if on { FRONT.mix(0.55).filled() } else { OTHER.mix(0.35).filled() };
            c.draw_series(std::iter::once(Circle::new((xs[i], p.quality), r, style))).map_err(|e| err(&e))?;
            c.draw_series(std::iter::once(Circle::new((xs[i], p.quality), r, if on { FRONT } else { OTHER }.stroke_width(1))))
                .map_err(|e| err(&e))?;
            let text = Text::new(p.label.clone(), (r + 3, -4), ("sans-serif", 11).into_font().color(&BLACK.mix(0.8)));
            c.draw_series(std::iter::once(EmptyElement::at((xs[i], p.quality)) + text)).map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(label: &str, cost: f64, wrong: f64, bytes: u64) -> Point {
        Point { label: label.into(), cost, quality: wrong, bytes }
    }

    #[test]
    fn the_pareto_front_keeps_only_undominated_points() {
        // (cost, wrong): 0 dominates 3 (cheaper and better); 4 equals 0, 7 equals 1; 5 is NaN
        let pts = [(1.0, 5.0), (3.0, 1.0), (2.0, 2.0), (2.5, 6.0), (1.0, 5.0), (f64::NAN, 0.0), (0.5, 9.0), (3.0, 1.0)];
        assert_eq!(pareto_front(&pts), vec![6, 0, 4, 2, 1, 7]);
        assert_eq!(pareto_front(&[]), Vec::<usize>::new());
        assert_eq!(pareto_front(&[(1.0, 1.0)]), vec![0]);
        // a point equal in cost but worse is dominated
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 2.0), (2.0, 1.0)]), vec![0]);
    }

    #[test]
    fn markers_grow_with_memory_and_the_front_is_drawn() {
        assert_eq!((radius(0, 100), radius(100, 100), radius(25, 100), radius(5, 0)), (3, 14, 9, 3));
        let pts = [p("cheap", 1.0, 5.0, 10), p("good", 4.0, 1.0, 1000), p("bad", 3.0, 6.0, 100)];
        let s = svg("planebox", "total ms", "wrong pixels (%)", &pts).unwrap();
        assert!(s.starts_with("<svg") && s.contains("cheap") && s.contains("good") && s.contains("bad"), "labels drawn");
        assert!(s.contains("total ms") && s.contains("wrong pixels (%)"));
        assert_eq!(s.matches("<circle").count(), 6, "a filled disc and an outline per point");
        let front_lines = s.lines().filter(|l| l.contains("<polyline") && l.contains("stroke-width=\"2\"")).count();
        assert_eq!(front_lines, 1, "one front line");
        assert!(!log_axis(&pts) && log_axis(&[p("a", 1.0, 1.0, 1), p("b", 100.0, 1.0, 1)]));
        let s = svg("x", "shadow data (bytes)", "mean FLIP", &[p("a", 1024.0, 1.0, 1024), p("b", 16e6, 0.5, 16_000_000)]).unwrap();
        assert!(s.contains("(log scale)"));
        assert!(svg("empty", "ms", "wrong pixels (%)", &[]).unwrap().starts_with("<svg"));
    }
}
