//! The sweep's report page (`index.html`, offline): a scatter of quality against a cost per
//! setup and over the setups (mean and worst case), the quality (wrong %, the primary figure,
//! or mean FLIP) and the cost (time, shadow data bytes, or a counter every point has) chosen
//! on the page, the recommendation and the tables.

use anyhow::Result;
use minijinja::context;

use super::choose::Aggregate;
use super::json::Sweep;
use super::record::Row;
use crate::report::scatter::pareto_front;
use crate::report::scatter::{self, Point};

const TEMPLATE: &str = include_str!("sweep.html.j2");

/// How a row reads a cost (None: the row has none).
type RowCost = Box<dyn Fn(&Row) -> Option<f64>>;
/// How an aggregate reads a cost: its mean (false) or worst case (true) over the setups.
type AggregateCost = Box<dyn Fn(&Aggregate, bool) -> Option<f64>>;

/// The costs a scatter can use: an id, a title and how a row / an aggregate reads it.
struct Cost {
    id: String,
    title: String,
    row: RowCost,
    agg: AggregateCost,
}

fn costs(s: &Sweep) -> Vec<Cost> {
    let mut v = vec![
        Cost {
            id: "ms".into(),
            title: "total ms (timed frame)".into(),
            row: Box::new(|r| Some(r.total_ms)),
            agg: Box::new(|a, worst| Some(if worst { a.worst_total_ms } else { a.mean_total_ms })),
        },
        Cost {
            id: "bytes".into(),
            title: "shadow data (bytes)".into(),
            row: Box::new(|r| Some(r.shadow_data_bytes as f64)),
            agg: Box::new(|a, _| Some(a.max_shadow_data_bytes as f64)),
        },
    ];
    let names: std::collections::BTreeSet<String> = s.rows.iter().flat_map(|r| r.counters.keys().cloned()).collect();
    // offered where some view can plot it: every row of a setup has it
    let plottable = |n: &String| s.setups.iter().any(|st| s.rows.iter().filter(|r| r.setup == st.name).all(|r| r.counters.contains_key(n)));
    for n in names.into_iter().filter(|n| is_cost_counter(n) && plottable(n)) {
        let (a, b) = (n.clone(), n.clone());
        v.push(Cost {
            id: format!("counter-{}", crate::output::slug(&n)),
            title: n.clone(),
            row: Box::new(move |r| r.counters.get(&a).copied()),
            agg: Box::new(move |g, worst| if worst { g.worst_counters.get(&b) } else { g.mean_counters.get(&b) }.copied()),
        });
    }
    v
}

/// A quality figure a scatter can plot (lower is better): an id, a title, and how a row / an
/// aggregate (mean or worst case over the setups) reads it.
struct Quality {
    id: &'static str,
    title: &'static str,
    row: fn(&Row) -> f64,
    agg: fn(&Aggregate, bool) -> f64,
}

/// Wrong % first (the primary figure, the page's default and the recommendation's), then FLIP.
const QUALITIES: &[Quality] = &[
    Quality {
        id: "wrong",
        title: "wrong pixels (%)",
        row: |r| r.quality.wrong_pct,
        agg: |a, worst| if worst { a.worst_wrong_pct } else { a.mean_wrong_pct },
    },
    Quality {
        id: "flip",
        title: "mean FLIP",
        row: |r| r.flip_mean,
        agg: |a, worst| if worst { a.worst_flip_mean } else { a.mean_flip_mean },
    },
];

/// Counters that measure work or memory (fetches, rays, pieces, bytes, reads, texels, map
/// renders, compute dispatches), offered as hardware-independent costs; the others (split
/// distances, box sizes, depth ranges) describe a result, not its cost.
pub const COST_COUNTERS: &[&str] = &["fetch", "ray", "pieces", "bytes", "reads", "texels", "renders", "dispatches"];

fn is_cost_counter(name: &str) -> bool {
    COST_COUNTERS.iter().any(|c| name.contains(c)) && !name.starts_with("ray_traced_cascade")
}

/// Points of a view for one cost; None unless every point has the cost.
fn points<T>(
    items: &[T],
    label: impl Fn(&T) -> String,
    cost: impl Fn(&T) -> Option<f64>,
    quality: impl Fn(&T) -> f64,
    bytes: impl Fn(&T) -> u64,
) -> Option<Vec<Point>> {
    if items.is_empty() {
        return None;
    }
    items.iter().map(|t| Some(Point { label: label(t), cost: cost(t)?, quality: quality(t), bytes: bytes(t) })).collect()
}

/// The terminal's and the page's words on the recommendation (none without a budget).
pub fn recommendation_lines(s: &Sweep) -> Vec<String> {
    let Some(r) = &s.recommendation else { return Vec::new() };
    let mut v = Vec::new();
    let budget = r.budget.describe();
    match &r.best {
        Some(b) => {
            v.push(format!(
                "recommended for {budget}: {} (mean wrong {:.3} %, worst {:.3} %, worst {:.2} ms, {} B shadow data)",
                b.label, b.mean_wrong_pct, b.worst_wrong_pct, b.worst_total_ms, b.max_shadow_data_bytes
            ));
            if let Some(next) = r.runners_up.first() {
                v.push(format!("margin to the runner-up: {:.3} percentage points of wrong pixels", next.margin_pct));
                let names: Vec<String> = r.runners_up.iter().map(|c| format!("{} (+{:.3})", c.label, c.margin_pct)).collect();
                v.push(format!("runners-up: {}", names.join(", ")));
            } else {
                v.push("no runner-up: it is the only spec within the budget".into());
            }
        }
        None => v.push(format!("nothing within {budget} ({} specs ran on every setup)", r.considered)),
    }
    v.push(format!(
        "{} of {} specs that ran on every setup are within the budget (worst case over the setups)",
        r.within_budget, r.considered
    ));
    if s.software_adapter && r.budget.ms.is_some() {
        v.push(SOFTWARE_NOTE.into());
    }
    v
}

/// What a time budget means on a CPU adapter.
pub const SOFTWARE_NOTE: &str = "note: time on lavapipe is not your GPU's: total_ms is the wall clock of a software (CPU) adapter; \
for a hardware-independent budget use --budget-bytes or --budget-mb (shadow data), or rerun the sweep on the target GPU";

pub fn html(s: &Sweep) -> Result<String> {
    let mut views: Vec<(String, String, Option<usize>, bool)> = Vec::new();
    if s.setups.len() > 1 {
        views.push(("mean".into(), "mean over setups".into(), None, false));
        views.push(("worst".into(), "worst case over setups".into(), None, true));
    }
    for (i, st) in s.setups.iter().enumerate() {
        views.push((format!("setup-{i}"), format!("setup {}", st.name), Some(i), false));
    }
    let costs = costs(s);
    let complete: Vec<Aggregate> = s.aggregates.iter().filter(|a| a.setups == s.setups.len()).cloned().collect();
    let mut plots = Vec::new();
    let mut fronts = Vec::new();
    for (vid, vtitle, setup, worst) in &views {
        for q in QUALITIES {
            for c in &costs {
                let pts = match setup {
                    Some(i) => {
                        let rows: Vec<&Row> = s.rows.iter().filter(|r| r.setup == s.setups[*i].name).collect();
                        points(&rows, |r| r.label.clone(), |r| (c.row)(r), |r| (q.row)(r), |r| r.shadow_data_bytes)
                    }
                    None => {
                        points(&complete, |a| a.label.clone(), |a| (c.agg)(a, *worst), |a| (q.agg)(a, *worst), |a| a.max_shadow_data_bytes)
                    }
                };
                let svg = match &pts {
                    Some(p) => Some(scatter::svg(&format!("{vtitle}: {} against {}", q.title, c.title), &c.title, q.title, p)?),
                    None => None,
                };
                if let Some(p) = &pts {
                    let front = pareto_front(&p.iter().map(|p| (p.cost, p.quality)).collect::<Vec<_>>());
                    let labels: Vec<String> = front.iter().map(|&i| p[i].label.clone()).collect();
                    fronts.push(context! { view => vid, quality => q.id, cost => c.id, labels => labels });
                }
                plots.push(context! { view => vid, quality => q.id, cost => c.id, svg => svg });
            }
        }
    }
    let mut env = minijinja::Environment::new();
    env.add_template("sweep.html", TEMPLATE)?;
    env.add_filter("f", |v: f64, digits: usize| format!("{v:.digits$}"));
    env.add_filter("bytes", |v: f64| {
        if v >= 1048576.0 {
            format!("{:.2} MiB", v / 1048576.0)
        } else if v >= 1024.0 {
            format!("{:.1} KiB", v / 1024.0)
        } else {
            format!("{v} B")
        }
    });
    let view_list: Vec<_> = views.iter().map(|(id, title, _, _)| context! { id => id, title => title }).collect();
    let cost_list: Vec<_> = costs.iter().map(|c| context! { id => c.id, title => c.title }).collect();
    let quality_list: Vec<_> = QUALITIES.iter().map(|q| context! { id => q.id, title => q.title }).collect();
    Ok(env.get_template("sweep.html")?.render(context! {
        s => minijinja::Value::from_serialize(s),
        views => view_list,
        costs => cost_list,
        qualities => quality_list,
        plots => plots,
        fronts => fronts,
        recommendation => recommendation_lines(s),
        software_note => s.software_adapter.then_some(SOFTWARE_NOTE),
    })?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::choose::Budget;
    use crate::sweep::record::tests::row;
    use crate::sweep::record::SetupInfo;
    use crate::sweep::{assemble, Header};

    fn sweep(budget: Budget) -> Sweep {
        let setup = |n: &str| SetupInfo { name: n.into(), source: n.into(), scene_source: n.into(), width: 8, height: 8, labels: vec![] };
        let mut rows = vec![
            row("a", "sm", 3.0, 1.0, 1024),
            row("a", "lt", 1.0, 4.0, 4096),
            row("b", "sm", 5.0, 2.0, 1024),
            row("b", "lt", 0.5, 9.0, 4096),
        ];
        for r in &mut rows {
            r.counters.insert("fetches_per_pixel".into(), 4.0);
        }
        rows[1].counters.insert("rays_traced".into(), 10.0);
        let h = Header { frames: 1, repeat: 1, light: 0, time: None, setups: vec![setup("a"), setup("b")], plan: vec![] };
        assemble(h, None, rows, budget, (4, 0, 2), vec![])
    }

    #[test]
    fn the_page_has_a_plot_per_view_and_cost_and_the_recommendation() {
        let s = sweep(Budget { ms: Some(5.0), ..Budget::default() });
        let h = html(&s).unwrap();
        // the only address is the SVG namespace, which is a name, not a download
        let loaded = h.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
        assert!(!loaded.contains("http://") && !loaded.contains("https://"), "offline");
        for id in ["plot-mean-wrong-ms", "plot-worst-wrong-bytes", "plot-setup-0-wrong-ms", "plot-setup-1-wrong-counter-fetches_per_pixel"]
        {
            assert!(h.contains(&format!("id=\"{id}\"")), "{id}");
        }
        // the quality selector: FLIP as well as wrong %, for every view and cost
        for id in ["plot-mean-flip-ms", "plot-worst-flip-bytes", "plot-setup-1-flip-counter-fetches_per_pixel"] {
            assert!(h.contains(&format!("id=\"{id}\"")), "{id}");
        }
        assert!(h.contains("<option value=\"wrong\">wrong pixels (%)</option><option value=\"flip\">mean FLIP</option>"), "wrong % first");
        assert!(h.contains("mean FLIP against total ms"));
        // rays_traced: on one row only, so no view can plot it and it is not offered
        assert!(!h.contains("counter-rays_traced"));
        // not a cost: a split distance is not offered even where every row has it
        let mut with_split = s.clone();
        for r in &mut with_split.rows {
            r.counters.insert("split_0".into(), 3.0);
        }
        assert!(!html(&with_split).unwrap().contains("counter-split_0"));
        assert_eq!(h.matches("<svg").count(), 4 * 2 * 3, "4 views x (wrong, FLIP) x (ms, bytes, fetches)");
        assert!(h.contains("recommended for worst-case total &lt;= 5 ms: sm"), "lt takes 9 ms on b");
        assert!(h.contains("time on lavapipe is not your GPU"));
        let lines = recommendation_lines(&s);
        assert!(lines[0].starts_with("recommended for worst-case total <= 5 ms: sm"), "{lines:?}");
        assert!(lines.iter().any(|l| l.contains("time on lavapipe")));
        assert!(html(&sweep(Budget::default())).unwrap().contains("no budget"));
        assert!(recommendation_lines(&sweep(Budget::default())).is_empty());
    }
}
