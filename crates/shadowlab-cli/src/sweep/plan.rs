//! The plan of a sweep: its setups (each resolved like a `compare` run, so every name, value,
//! light and file is checked before any GPU work), their points and cache keys in a fixed
//! order, and the share of that order a `--shard` runs.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use shadowlab_core::builtin::DEFAULT_SCENE;

use super::key::{file_sha256, resolved_spec_text, KeyInput};
use super::record::{PlanEntry, SetupInfo, Shard};
use crate::config::{resolve, RunConfig};
use crate::RunArgs;

/// Where a setup comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum SetupInput {
    File(PathBuf),
    /// A built-in scene name or a scene file, with the scene's own camera and lights.
    Scene(String),
}

/// What every setup of a sweep shares (the overrides of `compare`).
pub struct Common<'a> {
    /// Expanded `-t` points; empty: each setup's own list, else the default compare set.
    pub specs: &'a [String],
    pub size: Option<String>,
    pub frames: usize,
    pub repeat: usize,
    pub light: usize,
    pub time: Option<f32>,
    pub binary: &'a str,
}

/// One resolved setup and the cache key of each of its points (in `cfg.specs` order).
pub struct SetupPlan {
    pub info: SetupInfo,
    pub cfg: RunConfig,
    /// (key, key text) per spec.
    pub keys: Vec<(String, String)>,
}

fn stem(p: &Path) -> String {
    p.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| p.display().to_string())
}

/// The name rows carry: the setup file's stem, or the scene's name.
fn setup_name(input: &SetupInput) -> String {
    match input {
        SetupInput::File(p) => stem(p),
        SetupInput::Scene(s) if s.contains('/') || s.contains('.') => stem(Path::new(s)),
        SetupInput::Scene(s) => s.clone(),
    }
}

/// The setup's part of the cache key: the setup file's content and the scene file's content
/// (the main file: an OBJ's MTL and textures are not hashed), or the built-in scene's name.
fn setup_identity(input: &SetupInput, cfg: &RunConfig) -> Result<String> {
    let scene = match cfg.source.strip_prefix("builtin:") {
        Some(name) => format!("builtin:{name}"),
        None => format!("scene-file sha256:{}", file_sha256(Path::new(&cfg.source))?),
    };
    Ok(match input {
        SetupInput::File(p) => format!("setup-file sha256:{} {scene}", file_sha256(p)?),
        SetupInput::Scene(_) => scene,
    })
}

/// Resolves every setup (the default built-in scene when none is given) and the keys of
/// their points. Errors name the setup.
pub fn plan(inputs: &[SetupInput], common: &Common) -> Result<Vec<SetupPlan>> {
    let default = [SetupInput::Scene(DEFAULT_SCENE.into())];
    let inputs = if inputs.is_empty() { &default[..] } else { inputs };
    let mut out: Vec<SetupPlan> = Vec::new();
    for input in inputs {
        let name = setup_name(input);
        if out.iter().any(|s| s.info.name == name) {
            bail!("two setups are named '{name}' (a setup is named by its file's stem or its scene); rename one");
        }
        let (setup, scene) = match input {
            SetupInput::File(p) => (Some(p.clone()), None),
            SetupInput::Scene(s) => (None, Some(s.clone())),
        };
        let args = RunArgs {
            setup,
            scene,
            techniques: common.specs.to_vec(),
            size: common.size.clone(),
            light: common.light,
            repeat: common.repeat,
            frames: common.frames,
            time: common.time,
            quiet: true,
        };
        let cfg = resolve(&args, &shadowlab_gpu::registry::default_compare()).map_err(|e| anyhow!("setup '{name}': {e:#}"))?;
        let identity = setup_identity(input, &cfg).map_err(|e| anyhow!("setup '{name}': {e:#}"))?;
        let keys = cfg
            .specs
            .iter()
            .map(|r| {
                let spec = resolved_spec_text(r);
                let k = KeyInput {
                    binary: common.binary,
                    setup: &identity,
                    width: cfg.width,
                    height: cfg.height,
                    frames: common.frames,
                    repeat: common.repeat,
                    light: common.light,
                    time: cfg.time,
                    spec: &spec,
                };
                (k.key(), k.text())
            })
            .collect();
        let info = SetupInfo {
            name,
            source: match input {
                SetupInput::File(p) => p.display().to_string(),
                SetupInput::Scene(_) => cfg.source.clone(),
            },
            scene_source: cfg.source.clone(),
            width: cfg.width,
            height: cfg.height,
            labels: cfg.specs.iter().map(|s| s.label.clone()).collect(),
        };
        out.push(SetupPlan { info, cfg, keys });
    }
    Ok(out)
}

/// Every point in order: setups as given, each setup's specs in order.
pub fn entries(setups: &[SetupPlan]) -> Vec<PlanEntry> {
    setups
        .iter()
        .flat_map(|s| {
            s.info.labels.iter().zip(&s.keys).map(|(l, (k, _))| PlanEntry { key: k.clone(), setup: s.info.name.clone(), label: l.clone() })
        })
        .collect()
}

/// Parses `--shard i/n`: 1 <= i <= n.
pub fn parse_shard(s: &str) -> Result<Shard> {
    let bad = || anyhow!("--shard '{s}': expected i/n with 1 <= i <= n (1-based, e.g. 1/4 .. 4/4)");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (index, count): (usize, usize) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if count == 0 || index == 0 || index > count {
        return Err(bad());
    }
    Ok(Shard { index, count })
}

impl Shard {
    /// Whether the point at `position` of the plan belongs to this shard: every n-th point,
    /// starting at the i-th (round robin, so shards get similar mixes of cheap and costly specs).
    pub fn selects(&self, position: usize) -> bool {
        position % self.count == self.index - 1
    }
}

/// Which plan positions a run covers (all without a shard).
pub fn selected(len: usize, shard: Option<Shard>) -> Vec<usize> {
    (0..len).filter(|&p| shard.is_none_or(|s| s.selects(p))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_1_based_and_rejected_when_out_of_range() {
        assert_eq!(parse_shard("1/4").unwrap(), Shard { index: 1, count: 4 });
        assert_eq!(parse_shard(" 4 / 4 ").unwrap(), Shard { index: 4, count: 4 });
        for bad in ["0/4", "5/4", "1/0", "x/2", "1", "1/2/3", ""] {
            let e = parse_shard(bad).unwrap_err().to_string();
            assert!(e.contains("--shard") && e.contains("1-based"), "{bad}: {e}");
        }
    }

    #[test]
    fn shards_partition_the_plan_deterministically() {
        for n in 1..6 {
            let mut all: Vec<usize> = Vec::new();
            for i in 1..=n {
                let s = selected(11, Some(Shard { index: i, count: n }));
                assert_eq!(s, selected(11, Some(Shard { index: i, count: n })), "deterministic");
                assert!(s.len() == 11 / n || s.len() == 11 / n + 1, "balanced");
                all.extend(s);
            }
            all.sort();
            assert_eq!(all, (0..11).collect::<Vec<_>>(), "{n} shards cover every point once");
        }
        assert_eq!(selected(5, Some(Shard { index: 2, count: 2 })), vec![1, 3]);
        assert_eq!(selected(3, None), vec![0, 1, 2]);
    }

    fn common<'a>(specs: &'a [String]) -> Common<'a> {
        Common { specs, size: Some("32x32".into()), frames: 1, repeat: 1, light: 0, time: None, binary: "b" }
    }

    #[test]
    fn setups_resolve_with_keys_per_point_and_unique_names() {
        let specs = vec!["sm:res=256".to_string(), "sm:res=512".to_string()];
        // room's light 0 is a spot light: csm (directional only) is refused, naming the setup
        let csm = vec!["csm".to_string()];
        let e = plan(&[SetupInput::Scene("planebox".into()), SetupInput::Scene("room".into())], &common(&csm))
            .err()
            .expect("csm on a spot light");
        assert!(e.to_string().contains("setup 'room'"), "{e}");
        let p = plan(&[SetupInput::Scene("planebox".into()), SetupInput::Scene("city".into())], &common(&specs)).unwrap();
        let e = entries(&p);
        assert_eq!(e.len(), 4);
        assert_eq!((e[0].setup.as_str(), e[0].label.as_str()), ("planebox", "sm:res=256"));
        assert_eq!((e[3].setup.as_str(), e[3].label.as_str()), ("city", "sm:res=512"));
        let keys: std::collections::HashSet<_> = e.iter().map(|x| &x.key).collect();
        assert_eq!(keys.len(), 4, "keys differ per setup and spec");
        assert!(p[0].keys[0].1.contains("setup builtin:planebox") && p[0].keys[0].1.contains("size 32x32"));
        let again = plan(&[SetupInput::Scene("planebox".into())], &common(&specs)).unwrap();
        assert_eq!(again[0].keys, p[0].keys, "the same setup gives the same keys");
        let e = plan(&[SetupInput::Scene("planebox".into()), SetupInput::Scene("planebox".into())], &common(&specs)).err().unwrap();
        assert!(e.to_string().contains("two setups are named 'planebox'"), "{e}");
        // no setup: the default scene, with its own list (the default compare set) without -t
        let d = plan(&[], &common(&[])).unwrap();
        assert_eq!(d[0].info.name, DEFAULT_SCENE);
        assert!(d[0].info.labels.len() > 5 && d[0].info.labels.contains(&"sm".to_string()));
    }
}
