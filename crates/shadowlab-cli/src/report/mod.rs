//! The HTML report: one self-contained page (no network), rendered with minijinja from
//! `index.html.j2` and the same record that goes to metrics.json ([`Metrics`]).

mod plots;
pub(crate) mod scatter;

use anyhow::Result;
use minijinja::value::{Value, ValueKind};

use crate::metrics::Metrics;

const TEMPLATE: &str = include_str!("index.html.j2");

pub fn html(metrics: &Metrics) -> Result<String> {
    let mut env = minijinja::Environment::new();
    env.add_template("index.html", TEMPLATE)?;
    env.add_filter("f", |v: f64, digits: usize| format!("{v:.digits$}"));
    // whole numbers without a trailing ".0" (parameters, counters); names and booleans as they are
    env.add_filter("num", |v: Value| match f64::try_from(v.clone()) {
        Ok(x) if v.kind() == ValueKind::Number && x.fract() == 0.0 && x.abs() < 1e15 => format!("{}", x as i64),
        Ok(x) if v.kind() == ValueKind::Number => format!("{x}"),
        _ => v.to_string(),
    });
    env.add_filter("bytes", |v: f64| {
        if v >= 1048576.0 {
            format!("{:.2} MiB", v / 1048576.0)
        } else if v >= 1024.0 {
            format!("{:.1} KiB", v / 1024.0)
        } else {
            format!("{v} B")
        }
    });
    let charts: Vec<Value> =
        plots::frame_charts(metrics)?.into_iter().map(|(title, svg)| minijinja::context! { title => title, svg => svg }).collect();
    let tradeoffs: Vec<Value> = plots::tradeoff_charts(metrics)?
        .into_iter()
        .map(|(title, svg, missing)| minijinja::context! { title => title, svg => svg, missing => missing })
        .collect();
    let m = Value::from_serialize(metrics);
    Ok(env.get_template("index.html")?.render(minijinja::context! { m => m, charts => charts, tradeoffs => tradeoffs })?)
}

#[cfg(test)]
mod tests {
    use shadowlab_core::anim::Motion;

    use crate::metrics::{sample, AnimatedObject};

    #[test]
    fn renders_labels_and_numbers() {
        let m = sample::metrics(1);
        let h = super::html(&m).unwrap();
        assert!(h.contains("sm:pcf=3") && h.contains("1.250") && h.contains("1.00 MiB") && h.contains("b.png"));
        assert!(h.contains("res=512<") || h.contains("res=512,") || h.contains("res=512 "), "parameters print as whole numbers");
        assert!(h.contains("<td>9</td>"), "fetches print as whole numbers");
        assert!(h.contains("<td>1.250</td><td>0.0625</td>"), "FLIP sits beside wrong %");
        assert!(h.contains("src=\"d.png\" alt=\"FLIP\""), "the FLIP map is shown with the other images");
        // the SVG namespace is a name, not a fetch
        let loaded = h.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
        assert!(!loaded.contains("http://") && !loaded.contains("https://"), "report must work offline");
        assert!(h.contains("Quality against cost") && h.contains("wrong pixels against total ms"), "the quality/cost chart");
        assert!(h.contains("<table id=\"metrics\">") && h.contains("th.classList.add(\"sortable\")"), "a sortable table");
        assert!(!h.contains("moving"), "a still scene says nothing about moving objects");
        let mut moving = m.clone();
        moving.animation.dynamic_triangles = 12;
        let motion = Motion::Translate { offset: glam::Vec3::X, period: 10.0 };
        moving.animation.animations = ["cart", "cable"].map(|n| AnimatedObject { name: n.into(), triangles: 6, motion }).to_vec();
        let h = super::html(&moving).unwrap();
        assert!(h.contains("12 moving: cart, cable"), "moving objects are named in the header");
    }
}
