//! The HTML report: one self-contained page (no network), rendered with minijinja from
//! `index.html.j2` and the same JSON that goes to metrics.json.

mod plots;

use anyhow::Result;

const TEMPLATE: &str = include_str!("index.html.j2");

pub fn html(metrics: &serde_json::Value) -> Result<String> {
    let mut env = minijinja::Environment::new();
    env.add_template("index.html", TEMPLATE)?;
    env.add_filter("f", |v: f64, digits: usize| format!("{v:.digits$}"));
    // whole numbers without a trailing ".0" (parameters, counters)
    env.add_filter("num", |v: f64| if v.fract() == 0.0 && v.abs() < 1e15 { format!("{}", v as i64) } else { format!("{v}") });
    env.add_filter("bytes", |v: f64| {
        if v >= 1048576.0 {
            format!("{:.2} MiB", v / 1048576.0)
        } else if v >= 1024.0 {
            format!("{:.1} KiB", v / 1024.0)
        } else {
            format!("{v} B")
        }
    });
    let charts: Vec<minijinja::Value> =
        plots::frame_charts(metrics)?.into_iter().map(|(title, svg)| minijinja::context! { title => title, svg => svg }).collect();
    Ok(env.get_template("index.html")?.render(minijinja::context! { m => metrics, charts => charts })?)
}

#[cfg(test)]
mod tests {
    #[test]
    fn renders_labels_and_numbers() {
        let m = serde_json::json!({
            "scene": "planebox", "width": 4, "height": 4, "adapter": "x", "timer": "t", "repeat": 1, "triangles": 14,
            "light_index": 0, "lights": [{"type": "directional", "direction": [0.0, -1.0, 0.0]}],
            "bvh": {"bytes": 100, "bytes_per_triangle": 7.1},
            "reference": {"total_ms": 1.0, "evaluated_pixels": 10, "edge_pixels": 2, "counters": {"rays_traced": 10}},
            "gbuffer_stages_ms": {"gbuffer": 1.0},
            "techniques": [{"label": "sm:pcf=3", "technique": "sm", "params": {"res": 512.0}, "wrong_pct": 1.25, "false_lit_pct": 0.5, "false_shadow_pct": 0.75,
              "mae": 0.01, "evaluated_pixels": 10, "shadow_data_bytes": 1048576, "stages_ms": {"sm.render": 2.0}, "total_ms": 3.0, "setup_ms": 1.0,
              "counters": {"fetches_per_pixel": 9.0}, "sampling": null,
              "images": {"shaded": "a.png", "error": "b.png", "error_split": "c.png", "extra": []}}]
        });
        let h = super::html(&m).unwrap();
        assert!(h.contains("sm:pcf=3") && h.contains("1.250") && h.contains("1.00 MiB") && h.contains("b.png"));
        assert!(h.contains("res=512<") || h.contains("res=512,") || h.contains("res=512 "), "parameters print as whole numbers");
        assert!(h.contains("<td>9</td>"), "fetches print as whole numbers");
        assert!(!h.contains("http://") && !h.contains("https://"), "report must work offline");
        assert!(!h.contains("moving"), "a still scene says nothing about moving objects");
        let mut moving = m.clone();
        moving["animation"] =
            serde_json::json!({"dynamic_triangles": 12, "start_time": 0.0, "animations": [{"name": "cart"}, {"name": "cable"}]});
        let h = super::html(&moving).unwrap();
        assert!(h.contains("12 moving: cart, cable"), "moving objects are named in the header");
    }
}
