//! The terminal summary of a `compare` run.

use super::Metrics;

/// One line on stderr per degraded result (printed with `--quiet` too).
pub fn warnings(m: &Metrics) {
    for w in &m.warnings {
        eprintln!("warning: {w}");
    }
    for t in &m.techniques {
        for d in &t.degraded {
            eprintln!("warning: {} is degraded: {d}", t.label);
        }
    }
}

pub fn summary(m: &Metrics) {
    let light = m.light().map(|l| l.kind()).unwrap_or("?");
    println!("{} ({} triangles), {}x{}, light {} ({}), {}", m.scene, m.triangles, m.width, m.height, m.light_index, light, m.adapter);
    println!(
        "{:<28} {:>8} {:>9} {:>9} {:>8} {:>7} {:>10} {:>12}",
        "technique", "wrong%", "f-lit%", "f-shad%", "mae", "FLIP", "ms", "bytes"
    );
    println!(
        "{:<28} {:>8} {:>9} {:>9} {:>8} {:>7} {:>10.2} {:>12}",
        "rt (reference)", "-", "-", "-", "-", "-", m.reference.total_ms, m.bvh.bytes
    );
    for t in &m.techniques {
        println!(
            "{:<28} {:>8.3} {:>9.3} {:>9.3} {:>8.4} {:>7.4} {:>10.2} {:>12}",
            t.label,
            t.quality.wrong_pct,
            t.quality.false_lit_pct,
            t.quality.false_shadow_pct,
            t.quality.mae,
            t.flip_mean,
            t.total_ms,
            t.shadow_data_bytes
        );
    }
    println!("times: median of {} frames, {}", m.repeat, m.timer);
    for t in m.techniques.iter().filter(|t| !t.stalls.is_empty()) {
        println!("  {} stalls mid-frame: {}", t.label, t.stalls.join(", "));
    }
}
