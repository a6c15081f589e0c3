//! The one list of techniques: their registry entries, their shaders (with the shared
//! passes', for the naga test) and spec resolution. Adding a technique means its folder under
//! `techniques/` and one entry here (docs/adding-a-technique.md).

use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamValues, TechniqueSpec};

use crate::technique::TechniqueInfo;
use crate::techniques::{csm, cube, dpsm, filtered, iasm, lt, mdsm, min_sm, sdsm, sm, sv, virtual_sm, warp};
use crate::GpuError;

/// Every technique, in listing order.
pub static REGISTRY: &[&TechniqueInfo] = &[
    &crate::reference::INFO,
    &sm::INFO,
    &sv::INFO,
    &warp::RTW_INFO,
    &warp::NOTW_INFO,
    &warp::DV_INFO,
    &min_sm::INFO,
    &mdsm::INFO,
    &filtered::VSM_INFO,
    &filtered::ESM_INFO,
    &filtered::EVSM_INFO,
    &filtered::MSM_INFO,
    &csm::INFO,
    &sdsm::INFO,
    &iasm::INFO,
    &cube::INFO,
    &cube::NOTW_INFO,
    &dpsm::INFO,
    &dpsm::NOTW_INFO,
    &lt::LT_INFO,
    &lt::LTT_INFO,
    &lt::HYBRID_INFO,
    &virtual_sm::INFO,
];

/// (file name, composed source) of every shader the crate uses: the shared passes' and every
/// technique's, for the naga validation test.
pub fn shaders() -> Vec<(&'static str, String)> {
    let mut v = vec![];
    v.extend(crate::gbuffer::shaders());
    v.extend(crate::host::shaders());
    v.extend(crate::shade::shaders());
    v.extend(crate::reduce::shaders());
    v.extend(crate::blur::shaders());
    v.extend(crate::prefix_sum::shaders());
    for t in REGISTRY {
        for (name, src) in (t.shaders)() {
            if !v.iter().any(|(n, _)| *n == name) {
                v.push((name, src));
            }
        }
    }
    v
}

pub fn find(name: &str) -> Result<&'static TechniqueInfo, GpuError> {
    REGISTRY.iter().copied().find(|t| t.name == name).ok_or_else(|| {
        let names: Vec<_> = REGISTRY.iter().map(|t| t.name).collect();
        GpuError::Invalid(format!("unknown technique '{name}' (known: {})", names.join(", ")))
    })
}

/// A spec checked against the registry once: the technique, every parameter's value, the label.
/// The CLI, the lab and the reports carry this; nothing resolves a spec twice.
#[derive(Clone)]
pub struct Resolved {
    pub info: &'static TechniqueInfo,
    pub values: ParamValues,
    pub label: String,
    /// The spec as the user wrote it.
    pub text: String,
}

impl std::fmt::Debug for Resolved {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Resolved").field("technique", &self.info.name).field("values", &self.values).field("label", &self.label).finish()
    }
}

impl Resolved {
    /// Values already resolved against `info.params()`, under `label`.
    pub fn new(info: &'static TechniqueInfo, values: ParamValues, label: impl Into<String>) -> Resolved {
        let label = label.into();
        Resolved { info, values, text: label.clone(), label }
    }

    /// Whether the technique supports `light`'s type; the error names the types it supports.
    pub fn check_light(&self, light: &Light) -> Result<(), GpuError> {
        let info = self.info;
        if info.lights.contains(&light.kind()) {
            return Ok(());
        }
        Err(GpuError::Invalid(format!(
            "technique '{}' does not support {} lights (it supports: {})",
            info.name,
            light.kind(),
            info.lights.join(", ")
        )))
    }
}

/// Checks a spec against the registry without a GPU: its name, its parameters, and with
/// `light` the light type.
pub fn resolve(spec: &TechniqueSpec, light: Option<&Light>) -> Result<Resolved, GpuError> {
    let info = find(&spec.name)?;
    let values = spec.resolve(info.params()).map_err(GpuError::Invalid)?;
    let given: Vec<&str> = spec.args.iter().map(|(k, _)| k.as_str()).collect();
    (info.params.check)(&values, &given).map_err(|e| GpuError::Invalid(format!("technique '{}': {e}", info.name)))?;
    let r = Resolved { info, values, label: spec.label(), text: spec.text.clone() };
    if let Some(l) = light {
        r.check_light(l)?;
    }
    Ok(r)
}

/// The reference `rt` as a resolved spec (it has no parameters).
pub fn reference() -> Resolved {
    Resolved { info: &crate::reference::INFO, values: ParamValues::default(), label: "rt".into(), text: "rt".into() }
}

/// The specs `compare` runs when given none: every registry entry's [`TechniqueInfo::compare`].
pub fn default_compare() -> Vec<String> {
    let mut v = Vec::new();
    for t in REGISTRY {
        for args in t.compare {
            v.push(if args.is_empty() { t.name.to_string() } else { format!("{}:{args}", t.name) });
        }
    }
    v
}

/// Spec checks for the techniques' unit tests (no GPU).
#[cfg(test)]
pub(crate) mod testing {
    use shadowlab_core::params::{ParamDef, ParamSet, TechniqueSpec};

    use super::{resolve, Resolved};
    use crate::GpuError;

    /// `spec`, which must resolve.
    pub fn ok(spec: &str) -> Resolved {
        resolve(&TechniqueSpec::parse(spec).unwrap(), None).unwrap_or_else(|e| panic!("{spec}: {e}"))
    }

    /// The error of `spec`, which must not resolve.
    pub fn err(spec: &str) -> String {
        match resolve(&TechniqueSpec::parse(spec).unwrap(), None) {
            Err(GpuError::Invalid(m)) => m,
            other => panic!("{spec}: {other:?}"),
        }
    }

    /// A table's keys, in listing order.
    pub fn keys(defs: &[ParamDef]) -> Vec<&'static str> {
        defs.iter().map(|d| d.key).collect()
    }

    /// The keys of `P`'s table, in listing order.
    pub fn set_keys<P: ParamSet>() -> Vec<&'static str> {
        keys(P::defs())
    }

    /// `spec` resolved (the rules applied), or its error text.
    pub fn check(spec: &str) -> Result<(), String> {
        match resolve(&TechniqueSpec::parse(spec).unwrap(), None) {
            Ok(_) => Ok(()),
            Err(GpuError::Invalid(m)) => Err(m),
            Err(e) => panic!("{spec}: {e:?}"),
        }
    }

    /// [`check`]'s error for `spec`, or "" when it resolves.
    pub fn error(spec: &str) -> String {
        check(spec).err().unwrap_or_default()
    }
}
