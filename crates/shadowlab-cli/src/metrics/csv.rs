//! metrics.csv: one row per technique, the headline figures (columns in docs/metrics.md).

use serde::Serialize;

use super::{Metrics, Technique};

/// A column: its name and how a technique's cell is read.
type Column = (&'static str, fn(&Technique) -> String);

/// Columns after `label,technique`, each read from the technique's summary or its counters.
pub const COLUMNS: &[Column] = &[
    ("wrong_pct", |t| cell(t.quality.wrong_pct)),
    ("false_lit_pct", |t| cell(t.quality.false_lit_pct)),
    ("false_shadow_pct", |t| cell(t.quality.false_shadow_pct)),
    ("mae", |t| cell(t.quality.mae)),
    ("flip_mean", |t| cell(t.flip_mean)),
    ("flicker_pct", |t| cell(t.flicker_pct)),
    ("evaluated_pixels", |t| cell(t.quality.evaluated_pixels)),
    ("shadow_data_bytes", |t| cell(t.shadow_data_bytes)),
    ("total_ms", |t| cell(t.total_ms)),
    ("fetches_per_pixel", |t| cell(t.counters.get("fetches_per_pixel"))),
    ("rays_traced", |t| cell(t.counters.get("rays_traced"))),
];

/// A value as JSON writes it (`1.0`, `512`); empty for null, a missing counter or NaN.
fn cell(v: impl Serialize) -> String {
    match serde_json::to_value(v) {
        Ok(serde_json::Value::Null) | Err(_) => String::new(),
        Ok(v) => v.to_string(),
    }
}

pub fn csv(m: &Metrics) -> String {
    let names: Vec<&str> = COLUMNS.iter().map(|c| c.0).collect();
    let mut s = format!("label,technique,{}\n", names.join(","));
    for t in &m.techniques {
        let cols: Vec<String> = COLUMNS.iter().map(|c| (c.1)(t)).collect();
        s += &format!("\"{}\",{},{}\n", t.label.replace('"', "\"\""), t.technique, cols.join(","));
    }
    s
}

#[cfg(test)]
mod tests {
    #[test]
    fn one_row_per_technique_with_blank_nulls() {
        let mut m = super::super::sample::metrics(1);
        m.techniques[1].label = "say \"hi\"".into();
        let s = super::csv(&m);
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(
            lines[0],
            "label,technique,wrong_pct,false_lit_pct,false_shadow_pct,mae,flip_mean,flicker_pct,evaluated_pixels,shadow_data_bytes,total_ms,fetches_per_pixel,rays_traced"
        );
        assert_eq!(lines[1], "\"sm:pcf=3\",sm,1.25,0.5,0.75,0.01,0.0625,,10,1048576,3.0,9.0,");
        assert!(lines[2].starts_with("\"say \"\"hi\"\"\",sm,"), "{}", lines[2]);
        assert_eq!(lines.len(), 3);
    }
}
