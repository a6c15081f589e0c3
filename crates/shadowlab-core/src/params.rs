//! Technique specs (`name` or `name:key=value,key=value`) and parameter tables.
//!
//! Each technique declares its parameters once, as a `&'static [ParamDef]` with defaults and
//! sources; parsing, validation, the CLI listing and the report all read that one table.

use std::collections::BTreeMap;

use serde::Serialize;

/// One documented parameter of a technique.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ParamDef {
    pub key: &'static str,
    pub default: f64,
    pub min: f64,
    pub max: f64,
    /// Whole numbers only (resolutions, kernel sizes).
    pub integer: bool,
    /// What it does, and what goes wrong when too low or too high.
    pub doc: &'static str,
    /// Where the default comes from.
    pub source: &'static str,
    /// Named values (`select=sort`, `sd=true`): the parameter holds the index of the name,
    /// `default`/`min`/`max` are indices and `integer` is true. Empty for numeric parameters.
    pub choices: &'static [&'static str],
}

/// `choices` for on/off parameters: `false` = 0, `true` = 1 (`0`/`1` are accepted too).
pub const BOOL: &[&str] = &["false", "true"];

impl ParamDef {
    /// The default as the user writes it (`512`, `0.5`, `sort`).
    pub fn default_text(&self) -> String {
        match self.choices.get(self.default as usize) {
            Some(name) if !self.choices.is_empty() => name.to_string(),
            _ => format!("{}", self.default),
        }
    }
}

/// A parsed spec: technique name, explicit key/value pairs (strings), optional label.
#[derive(Clone, Debug, PartialEq)]
pub struct TechniqueSpec {
    pub name: String,
    pub args: Vec<(String, String)>,
    pub label: Option<String>,
    /// The spec string as given.
    pub text: String,
}

impl TechniqueSpec {
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        let (name, rest) = match text.split_once(':') {
            Some((n, r)) => (n.trim(), Some(r)),
            None => (text, None),
        };
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
            return Err(format!("technique spec '{text}': bad technique name '{name}'"));
        }
        let mut args = Vec::new();
        let mut label = None;
        if let Some(rest) = rest {
            for kv in rest.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                let (k, v) = kv.split_once('=').ok_or_else(|| format!("technique spec '{text}': expected key=value, got '{kv}'"))?;
                let (k, v) = (k.trim(), v.trim());
                if k == "label" {
                    label = Some(v.to_string());
                } else {
                    if args.iter().any(|(a, _): &(String, String)| a == k) {
                        return Err(format!("technique spec '{text}': '{k}' given twice"));
                    }
                    args.push((k.to_string(), v.to_string()));
                }
            }
        }
        Ok(TechniqueSpec { name: name.to_string(), args, label, text: text.to_string() })
    }

    /// The run's label: `label=` if given, else the spec text.
    pub fn label(&self) -> String {
        self.label.clone().unwrap_or_else(|| self.text.clone())
    }

    /// Resolves the arguments against a parameter table: unknown keys, non-numbers, fractions
    /// for integer parameters and out-of-range values are errors naming the valid choices.
    pub fn resolve(&self, defs: &[ParamDef]) -> Result<ParamValues, String> {
        let mut values: BTreeMap<String, f64> = defs.iter().map(|d| (d.key.to_string(), d.default)).collect();
        for (k, v) in &self.args {
            let def = defs.iter().find(|d| d.key == k).ok_or_else(|| {
                let keys: Vec<_> = defs.iter().map(|d| d.key).collect();
                if keys.is_empty() {
                    format!("technique '{}' takes no parameters (got '{k}')", self.name)
                } else {
                    format!("technique '{}' has no parameter '{k}' (valid: {}, label)", self.name, keys.join(", "))
                }
            })?;
            if !def.choices.is_empty() {
                let idx = def.choices.iter().position(|c| c == v).or_else(|| v.parse::<usize>().ok().filter(|i| *i < def.choices.len()));
                let idx = idx.ok_or_else(|| format!("technique '{}': {k}={v} is not one of {}", self.name, def.choices.join(", ")))?;
                values.insert(k.clone(), idx as f64);
                continue;
            }
            let x: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| format!("technique '{}': {k}={v} is not a number", self.name))?;
            if def.integer && x.fract() != 0.0 {
                return Err(format!("technique '{}': {k}={v} must be a whole number", self.name));
            }
            if x < def.min || x > def.max {
                return Err(format!("technique '{}': {k}={v} out of range [{}, {}]", self.name, def.min, def.max));
            }
            values.insert(k.clone(), x);
        }
        Ok(ParamValues(values))
    }
}

/// Resolved parameter values (every declared key present).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ParamValues(pub BTreeMap<String, f64>);

impl ParamValues {
    /// Panics only on a key the technique did not declare (a programming error).
    pub fn get(&self, key: &str) -> f64 {
        *self.0.get(key).unwrap_or_else(|| panic!("parameter '{key}' not declared"))
    }
    pub fn get_u32(&self, key: &str) -> u32 {
        self.get(key) as u32
    }
    /// An on/off parameter declared with `choices: BOOL`.
    pub fn get_bool(&self, key: &str) -> bool {
        self.get(key) != 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    const DEFS: &[ParamDef] = &[
        ParamDef { key: "select", default: 0.0, min: 0.0, max: 1.0, integer: true, doc: "", source: "", choices: &["minmax", "sort"] },
        ParamDef { key: "sd", default: 1.0, min: 0.0, max: 1.0, integer: true, doc: "", source: "", choices: BOOL },
        ParamDef { key: "res", default: 512.0, min: 16.0, max: 16384.0, integer: true, doc: "", source: "", choices: &[] },
        ParamDef { key: "bias", default: 0.5, min: 0.0, max: 100.0, integer: false, doc: "", source: "", choices: &[] },
    ];
    #[test]
    fn named_choices_resolve_to_indices() {
        let v = TechniqueSpec::parse("x:select=sort,sd=false").unwrap().resolve(DEFS).unwrap();
        assert_eq!((v.get_u32("select"), v.get_bool("sd")), (1, false));
        let v = TechniqueSpec::parse("x:sd=1").unwrap().resolve(DEFS).unwrap();
        assert!(v.get_bool("sd") && v.get_u32("select") == 0);
        let e = TechniqueSpec::parse("x:select=median").unwrap().resolve(DEFS).unwrap_err();
        assert!(e.contains("minmax, sort"), "{e}");
        assert!(TechniqueSpec::parse("x:sd=2").unwrap().resolve(DEFS).is_err());
        assert_eq!(DEFS[0].default_text(), "minmax");
        assert_eq!(DEFS[2].default_text(), "512");
    }
    #[test]
    fn parse_and_resolve() {
        let s = TechniqueSpec::parse("sm:res=2048, bias=1.5,label=big").unwrap();
        assert_eq!(s.name, "sm");
        assert_eq!(s.label(), "big");
        let v = s.resolve(DEFS).unwrap();
        assert_eq!(v.get("res"), 2048.0);
        assert_eq!(v.get("bias"), 1.5);
        let d = TechniqueSpec::parse("sm").unwrap();
        assert_eq!(d.label(), "sm");
        assert_eq!(d.resolve(DEFS).unwrap().get("res"), 512.0);
    }
    #[test]
    fn errors_are_specific() {
        let e = TechniqueSpec::parse("sm:rez=2").unwrap().resolve(DEFS).unwrap_err();
        assert!(e.contains("no parameter 'rez'") && e.contains("res, bias"), "{e}");
        assert!(TechniqueSpec::parse("sm:res=1.5").unwrap().resolve(DEFS).unwrap_err().contains("whole"));
        assert!(TechniqueSpec::parse("sm:res=8").unwrap().resolve(DEFS).unwrap_err().contains("range"));
        assert!(TechniqueSpec::parse("sm:res=abc").unwrap().resolve(DEFS).unwrap_err().contains("not a number"));
        assert!(TechniqueSpec::parse("sm:res").is_err());
        assert!(TechniqueSpec::parse("sm:res=1,res=2").is_err());
        assert!(TechniqueSpec::parse("").is_err());
        assert!(TechniqueSpec::parse("s m").is_err());
    }
}
