//! Per-frame charts of a camera-path run (seed 004's Figure 7 style): one SVG per figure, one
//! line per technique, drawn with plotters' SVG backend (no fonts, no network).

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use shadowlab_gpu::lab::FrameRecord;

use crate::metrics::Metrics;

/// A chart: its title and the figure of a `frames` record, if the record has one.
type Chart = (&'static str, fn(&FrameRecord) -> Option<f64>);

/// The per-frame figures charted.
pub const CHARTS: &[Chart] = &[
    ("wrong pixels (%)", |r| Some(r.quality.wrong_pct)),
    ("FLIP (mean)", |r| Some(r.flip_mean)),
    ("flicker vs previous frame (%)", |r| r.flicker_pct),
    ("rays traced", |r| r.rays_traced),
    ("time (ms)", |r| Some(r.total_ms)),
];

const PALETTE: &[RGBColor] = &[
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// One SVG per chart that has data, as (title, svg). Empty for single-frame runs.
pub fn frame_charts(metrics: &Metrics) -> Result<Vec<(String, String)>> {
    let frames = metrics.frames;
    if frames < 2 {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    for (title, figure) in CHARTS {
        let series: Vec<(String, Vec<(f64, f64)>)> = metrics
            .techniques
            .iter()
            .map(|t| (t.label.clone(), t.frames.iter().filter_map(|r| Some((r.frame as f64, figure(r)?))).collect::<Vec<_>>()))
            .filter(|(_, pts)| !pts.is_empty())
            .collect();
        if series.is_empty() {
            continue;
        }
        out.push((title.to_string(), chart(title, frames as f64, &series)?));
    }
    Ok(out)
}

fn chart(title: &str, frames: f64, series: &[(String, Vec<(f64, f64)>)]) -> Result<String> {
    let ymax = series.iter().flat_map(|(_, p)| p.iter().map(|q| q.1)).fold(0.0f64, f64::max);
    let ymax = if ymax > 0.0 { ymax * 1.1 } else { 1.0 };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (560, 260)).into_drawing_area();
        let err = |e: &dyn std::fmt::Display| anyhow!("chart '{title}': {e}");
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut c = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 15))
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(52)
            .build_cartesian_2d(0f64..(frames - 1.0).max(1.0), 0f64..ymax)
            .map_err(|e| err(&e))?;
        c.configure_mesh().x_desc("frame").light_line_style(WHITE.mix(0.0)).draw().map_err(|e| err(&e))?;
        for (i, (label, pts)) in series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            c.draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
        }
        c.configure_series_labels().background_style(WHITE.mix(0.85)).border_style(BLACK.mix(0.3)).draw().map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::sample;
    #[test]
    fn one_line_per_technique_and_nothing_for_one_frame() {
        let m = sample::metrics(3);
        let charts = frame_charts(&m).unwrap();
        let titles: Vec<&str> = charts.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(titles, ["wrong pixels (%)", "FLIP (mean)", "flicker vs previous frame (%)", "time (ms)"], "no rays: no ray chart");
        let svg = &charts[0].1;
        assert!(svg.starts_with("<svg") && svg.contains("vsm:blur=5") && svg.contains("sm"));
        let lines = svg.lines().filter(|l| l.contains("<polyline") && l.contains("stroke-width=\"2\"")).count();
        assert_eq!(lines, 4, "two lines and two legend marks");
        assert!(frame_charts(&sample::metrics(1)).unwrap().is_empty());
    }
}

/// The quality/cost charts of a compare report: wrong % against the timed frame's ms and
/// against texel fetches per pixel (a cost every GPU pays), marker area by shadow data bytes,
/// the Pareto front drawn. As (title, svg, the labels left out of that chart and why). A
/// technique that traces rays is left out of the fetch chart: its rays are a cost of another
/// kind.
pub fn tradeoff_charts(metrics: &Metrics) -> Result<Vec<(String, String, Vec<String>)>> {
    use super::scatter::{svg, Point};
    type Cost = (&'static str, fn(&crate::metrics::Technique) -> Option<f64>);
    let costs: [Cost; 2] =
        [("total ms (timed frame)", |t| Some(t.total_ms)), ("texel fetches per pixel", |t| t.counters.get("fetches_per_pixel").copied())];
    let mut out = Vec::new();
    for (name, cost) in costs {
        let (mut points, mut missing) = (Vec::new(), Vec::new());
        let fetches = name.contains("fetches");
        for t in &metrics.techniques {
            match cost(t) {
                _ if fetches && t.counters.contains_key("rays_traced") => missing.push(format!("{} (traces rays)", t.label)),
                Some(c) if c.is_finite() => {
                    points.push(Point { label: t.label.clone(), cost: c, quality: t.quality.wrong_pct, bytes: t.shadow_data_bytes })
                }
                _ => missing.push(format!("{} (no such count)", t.label)),
            }
        }
        if points.len() < 2 {
            continue;
        }
        let title = format!("wrong pixels against {name}");
        let s = svg(&title, name, "wrong pixels (%)", &points)?;
        out.push((title, s, missing));
    }
    Ok(out)
}
