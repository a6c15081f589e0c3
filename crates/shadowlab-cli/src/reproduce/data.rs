//! The seeds' figures and the experiments behind them (claims.toml, compiled in): the data
//! model, its parse and the checks that every claim names a run, labels the run has and a
//! metric we measure.

use std::collections::BTreeSet;

use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};

pub const CLAIMS_TOML: &str = include_str!("claims.toml");

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Data {
    pub seed: Vec<Seed>,
    pub run: Vec<Run>,
    pub claim: Vec<Claim>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Seed {
    pub id: String,
    pub title: String,
    /// The seed document under ../shared/seeds/.
    pub file: String,
}

/// One experiment: a sweep of `techniques` over one setup.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Run {
    pub id: String,
    pub seed: String,
    /// A shipped setup file (relative to `--setups`).
    pub setup: Option<String>,
    /// A built-in scene.
    pub scene: Option<String>,
    #[serde(default)]
    pub light: usize,
    /// Output size = base size x scale (each side).
    #[serde(default = "one")]
    pub scale: f64,
    #[serde(default = "one_frame")]
    pub frames: usize,
    /// What the run stands in for in the seed.
    pub closest: String,
    pub techniques: Vec<String>,
}

fn one() -> f64 {
    1.0
}

fn one_frame() -> usize {
    1
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Order,
    Ratio,
    Value,
    Trend,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    Increasing,
    Decreasing,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Claim {
    pub id: String,
    pub kind: Kind,
    /// The run (order, ratio, value).
    pub run: Option<String>,
    /// The runs in order (trend).
    #[serde(default)]
    pub runs: Vec<String>,
    pub metric: String,
    /// order: best first.
    #[serde(default)]
    pub labels: Vec<String>,
    /// value, trend of one label.
    pub label: Option<String>,
    /// ratio, trend of a ratio.
    pub num: Option<String>,
    pub den: Option<String>,
    /// ratio, value: inclusive bounds.
    pub range: Option<[f64; 2]>,
    pub direction: Option<Direction>,
    /// Seed, section, table or figure.
    pub source: String,
    /// The paper's figure or words.
    pub paper: String,
    /// Where the range is ours, why it is what it is.
    pub tolerance: Option<String>,
}

impl Claim {
    /// The seed a claim belongs to: its id's prefix (`000-...`).
    pub fn seed(&self) -> &str {
        self.id.split('-').next().unwrap_or_default()
    }

    /// The runs the claim reads.
    pub fn run_ids(&self) -> Vec<&str> {
        match self.kind {
            Kind::Trend => self.runs.iter().map(String::as_str).collect(),
            _ => self.run.iter().map(String::as_str).collect(),
        }
    }

    /// The labels the claim reads.
    pub fn labels(&self) -> Vec<&str> {
        let mut v: Vec<&str> = self.labels.iter().map(String::as_str).collect();
        v.extend(self.label.as_deref());
        v.extend(self.num.as_deref());
        v.extend(self.den.as_deref());
        v
    }
}

/// Metrics whose figure is a time (ms): timer dependent.
pub fn is_time(metric: &str) -> bool {
    metric == "total_ms" || metric.starts_with("stage:")
}

/// Whether `metric` is one the rows give.
pub fn known_metric(metric: &str) -> bool {
    const PLAIN: &[&str] = &[
        "wrong_pct",
        "false_lit_pct",
        "false_shadow_pct",
        "mae",
        "flip_mean",
        "total_ms",
        "shadow_data_bytes",
        "stalls",
        "rays_per_pixel",
    ];
    PLAIN.contains(&metric)
        || metric.strip_prefix("stage:").is_some_and(|s| !s.is_empty())
        || metric.strip_prefix("counter:").is_some_and(|s| !s.is_empty())
}

pub fn load() -> Result<Data> {
    parse(CLAIMS_TOML)
}

/// Parses and checks a claims file: unique ids, every run known with a setup or a scene, every
/// claim's runs, labels, metric and kind-specific fields present.
pub fn parse(text: &str) -> Result<Data> {
    let d: Data = toml::from_str(text).context("claims.toml")?;
    let seeds: BTreeSet<&str> = d.seed.iter().map(|s| s.id.as_str()).collect();
    let mut ids = BTreeSet::new();
    for r in &d.run {
        if !ids.insert(r.id.as_str()) {
            bail!("run '{}' is declared twice", r.id);
        }
        if !seeds.contains(r.seed.as_str()) {
            bail!("run '{}': unknown seed '{}'", r.id, r.seed);
        }
        if r.setup.is_some() == r.scene.is_some() {
            bail!("run '{}': give exactly one of setup and scene", r.id);
        }
        if r.techniques.is_empty() || !(r.scale > 0.0 && r.scale <= 4.0) || r.frames == 0 {
            bail!("run '{}': needs techniques, a scale in (0, 4] and at least one frame", r.id);
        }
    }
    let mut claim_ids = BTreeSet::new();
    for c in &d.claim {
        let at = || format!("claim '{}'", c.id);
        if !claim_ids.insert(c.id.as_str()) {
            bail!("{} is declared twice", at());
        }
        if !seeds.contains(c.seed()) {
            bail!("{}: its id does not start with a seed id", at());
        }
        if !known_metric(&c.metric) {
            bail!("{}: unknown metric '{}'", at(), c.metric);
        }
        let runs = c.run_ids();
        let ok = match c.kind {
            Kind::Order => c.labels.len() >= 2,
            Kind::Ratio => c.num.is_some() && c.den.is_some() && c.range.is_some(),
            Kind::Value => c.label.is_some() && c.range.is_some(),
            Kind::Trend => runs.len() >= 2 && c.direction.is_some() && (c.label.is_some() != (c.num.is_some() && c.den.is_some())),
        };
        if !ok || runs.is_empty() || (c.kind != Kind::Trend && c.run.is_none()) {
            bail!("{}: missing or extra fields for a {:?} claim", at(), c.kind);
        }
        if let Some([lo, hi]) = c.range {
            if !(lo <= hi) {
                bail!("{}: range [{lo}, {hi}] is empty", at());
            }
        }
        for id in runs {
            let run = d.run.iter().find(|r| r.id == id).ok_or_else(|| anyhow!("{}: unknown run '{id}'", at()))?;
            if run.seed != c.seed() {
                bail!("{}: run '{id}' belongs to seed {}", at(), run.seed);
            }
            for l in c.labels() {
                if !run.techniques.iter().any(|t| t == l) {
                    bail!("{}: run '{id}' has no technique '{l}'", at());
                }
            }
        }
    }
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_data_parses_and_checks() {
        let d = load().unwrap();
        assert_eq!(d.seed.len(), 5);
        for s in &d.seed {
            assert!(d.claim.iter().any(|c| c.seed() == s.id), "seed {} has no claim", s.id);
        }
    }

    #[test]
    fn mistakes_in_the_data_are_refused() {
        let base = "[[seed]]\nid='000'\ntitle='t'\nfile='f'\n[[run]]\nid='000-a'\nseed='000'\nscene='planebox'\nclosest='c'\ntechniques=['sm','rtw']\n";
        let claim = |body: &str| format!("{base}[[claim]]\nid='000-x'\nsource='s'\npaper='p'\n{body}");
        assert!(parse(&claim("kind='order'\nrun='000-a'\nmetric='wrong_pct'\nlabels=['sm','rtw']")).is_ok());
        for (body, needle) in [
            ("kind='order'\nrun='000-a'\nmetric='wrong_pct'\nlabels=['sm','notw']", "no technique 'notw'"),
            ("kind='order'\nrun='000-b'\nmetric='wrong_pct'\nlabels=['sm','rtw']", "unknown run"),
            ("kind='order'\nrun='000-a'\nmetric='speed'\nlabels=['sm','rtw']", "unknown metric"),
            ("kind='ratio'\nrun='000-a'\nmetric='mae'\nnum='sm'\nden='rtw'", "missing or extra"),
            ("kind='value'\nrun='000-a'\nmetric='mae'\nlabel='sm'\nrange=[2.0, 1.0]", "is empty"),
            ("kind='order'\nrun='000-a'\nmetric='mae'\nlabels=['sm','rtw']\ncolour='red'", "unknown field"),
        ] {
            let e = format!("{:#}", parse(&claim(body)).unwrap_err());
            assert!(e.contains(needle), "{body}: {e}");
        }
    }
}
