//! The reproduction's report: markdown (reproduce.md, also what BENCHMARKS.md quotes), a
//! self-contained HTML page linking each run's sweep page, and the terminal table.

use super::data::Data;
use super::verdict::{Status, Verdict};
use super::Reproduction;

fn counts(v: &[Verdict]) -> String {
    let n = |s: Status| v.iter().filter(|x| x.status == s).count();
    format!(
        "{} claims: {} reproduced, {} not reproduced, {} not comparable",
        v.len(),
        n(Status::Reproduced),
        n(Status::NotReproduced),
        n(Status::NotComparable)
    )
}

fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// One row per claim: (seed, claim id, source, paper, ours, verdict, why).
fn rows<'a>(r: &'a Reproduction) -> impl Iterator<Item = (&'a str, &'a str, &'a str, String, &'a str, &'static str, String)> + 'a {
    r.claims.iter().zip(&r.verdicts).map(|(c, v)| {
        let why = match &c.tolerance {
            Some(t) => format!("{}; range: {t}", v.why),
            None => v.why.clone(),
        };
        (c.seed(), c.id.as_str(), c.source.as_str(), c.paper.clone(), v.ours.as_str(), v.status.text(), why)
    })
}

fn timers(r: &Reproduction) -> String {
    let mut t: Vec<&str> = r.runs.iter().filter(|x| !x.timer.is_empty()).map(|x| x.timer.as_str()).collect();
    t.dedup();
    let mut a: Vec<&str> = r.runs.iter().filter(|x| !x.adapter.is_empty()).map(|x| x.adapter.as_str()).collect();
    a.dedup();
    format!("timer: {} (adapter: {})", t.join("; "), a.join("; "))
}

pub fn markdown(r: &Reproduction, d: &Data) -> String {
    let mut s = format!(
        "# shadowlab reproduce {}\n\n{}\n\nbase size {}x{}{}, {} timed repetitions; {}; {} points computed, {} cached; {:.1} s\n",
        r.seeds.join(" "),
        counts(&r.verdicts),
        r.width,
        r.height,
        if r.quick { " (--quick)" } else { "" },
        r.repeat,
        timers(r),
        r.points_computed,
        r.points_cached,
        r.seconds
    );
    s += "\n| run | stands for | input | size | frames | points (computed/cached) | s |\n|---|---|---|---|---|---|---|\n";
    for x in &r.runs {
        let pts = match &x.skipped {
            Some(why) => format!("skipped: {}", cell(why)),
            None => format!("{}/{}", x.points_computed, x.points_cached),
        };
        s += &format!(
            "| {} | {} | {} (light {}) | {}x{} | {} | {pts} | {:.1} |\n",
            x.id,
            cell(&x.closest),
            x.input,
            x.light,
            x.width,
            x.height,
            x.frames,
            x.seconds
        );
    }
    for seed in d.seed.iter().filter(|sd| r.seeds.contains(&sd.id)) {
        s += &format!(
            "\n## {} {} (shared/seeds/{})\n\n| claim | source | paper | ours | verdict | why |\n|---|---|---|---|---|---|\n",
            seed.id, seed.title, seed.file
        );
        for (sd, id, src, paper, ours, verdict, why) in rows(r) {
            if sd == seed.id {
                s += &format!("| {id} | {} | {} | {} | **{verdict}** | {} |\n", cell(src), cell(&paper), cell(ours), cell(&why));
            }
        }
    }
    s
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

pub fn html(r: &Reproduction, d: &Data) -> String {
    let mut s = String::from(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>shadowlab reproduce</title><style>\
body{font:14px sans-serif;margin:2em;max-width:1400px}table{border-collapse:collapse;margin:1em 0}\
td,th{border:1px solid #ccc;padding:3px 6px;vertical-align:top}th{background:#eee}\
.reproduced{background:#d7f5d7}.not_reproduced{background:#f8d0d0}.not_comparable{background:#eee}</style></head><body>",
    );
    s += &format!("<h1>shadowlab reproduce {}</h1><p>{}</p>", esc(&r.seeds.join(" ")), esc(&counts(&r.verdicts)));
    s += &format!(
        "<p>base size {}x{}{}, {} timed repetitions; {}; {} points computed, {} cached; {:.1} s</p>",
        r.width,
        r.height,
        if r.quick { " (--quick)" } else { "" },
        r.repeat,
        esc(&timers(r)),
        r.points_computed,
        r.points_cached,
        r.seconds
    );
    s += "<table><tr><th>run</th><th>stands for</th><th>input</th><th>size</th><th>frames</th><th>points</th><th>s</th></tr>";
    for x in &r.runs {
        let (id, pts) = match &x.skipped {
            Some(why) => (esc(&x.id), format!("skipped: {}", esc(why))),
            None => (
                format!("<a href=\"{0}/index.html\">{0}</a>", esc(&x.id)),
                format!("{} computed, {} cached", x.points_computed, x.points_cached),
            ),
        };
        s += &format!(
            "<tr><td>{id}</td><td>{}</td><td>{} (light {})</td><td>{}x{}</td><td>{}</td><td>{pts}</td><td>{:.1}</td></tr>",
            esc(&x.closest),
            esc(&x.input),
            x.light,
            x.width,
            x.height,
            x.frames,
            x.seconds
        );
    }
    s += "</table>";
    for seed in d.seed.iter().filter(|sd| r.seeds.contains(&sd.id)) {
        s += &format!(
            "<h2>{} {}</h2><table><tr><th>claim</th><th>source</th><th>paper</th><th>ours</th><th>verdict</th><th>why</th></tr>",
            esc(&seed.id),
            esc(&seed.title)
        );
        for (sd, id, src, paper, ours, verdict, why) in rows(r) {
            if sd == seed.id {
                let class = verdict.replace(' ', "_");
                s += &format!(
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{class}\">{verdict}</td><td>{}</td></tr>",
                    esc(id),
                    esc(src),
                    esc(&paper),
                    esc(ours),
                    esc(&why)
                );
            }
        }
        s += "</table>";
    }
    s + "</body></html>\n"
}

/// The terminal table: the paper's figure beside ours, per claim.
pub fn terminal(r: &Reproduction) -> String {
    let mut s = String::new();
    for (_, id, _, paper, ours, verdict, _) in rows(r) {
        s += &format!("{id:<26} {verdict:<15} ours: {ours}\n{:<42} paper: {paper}\n", "");
    }
    s + &format!("{}\n{}\n", counts(&r.verdicts), timers(r))
}
