//! Technique specs (`name` or `name:key=value,key=value`) and parameter tables.
//!
//! Each technique declares its parameters once, as a `&'static [ParamDef]` built with the
//! constructors here ([`ParamDef::number`], [`ParamDef::integer`], [`ParamDef::flag`],
//! [`ParamDef::choice`]); the parameters many techniques share (map size, PCF, the bias family)
//! are defined once in [`family`]. Parsing, validation, the CLI listing and the report all
//! read that one table, and a spec resolves once into typed [`ParamValues`].

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

pub mod family;
mod set;

pub use set::{check_table, declare_choice, read_choice, Auto, Block, Field, ParamSet, ParamTable};

/// What values a parameter takes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "type", content = "names", rename_all = "lowercase")]
pub enum Kind {
    /// Any number in `[min, max]`.
    Number,
    /// A whole number in `[min, max]` (resolutions, kernel sizes).
    Integer,
    /// `true`/`false` (`1`/`0` accepted too).
    Flag,
    /// One of the names (its index accepted too); `default` is the index of the default name.
    Choice(&'static [&'static str]),
    /// `auto` (the technique chooses, per frame) or a number in `[min, max]`; `default` is NaN
    /// for `auto`.
    AutoNumber,
}

/// The word an [`Kind::AutoNumber`] parameter takes for "the technique chooses".
pub const AUTO: &str = "auto";

/// One documented parameter of a technique.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ParamDef {
    pub key: &'static str,
    pub kind: Kind,
    /// The default value; for a flag 0 or 1, for a choice the index of the default name.
    pub default: f64,
    pub min: f64,
    pub max: f64,
    /// What it does, and what goes wrong when too low or too high.
    pub doc: &'static str,
    /// Where the default comes from.
    pub source: &'static str,
}

impl ParamDef {
    /// A number in `[min, max]`.
    pub const fn number(key: &'static str, default: f64, min: f64, max: f64, doc: &'static str, source: &'static str) -> ParamDef {
        ParamDef { key, kind: Kind::Number, default, min, max, doc, source }
    }
    /// A whole number in `[min, max]`.
    pub const fn integer(key: &'static str, default: f64, min: f64, max: f64, doc: &'static str, source: &'static str) -> ParamDef {
        ParamDef { key, kind: Kind::Integer, default, min, max, doc, source }
    }
    /// `auto` by default, or a number in `[min, max]` ([`Kind::AutoNumber`]).
    pub const fn auto_number(key: &'static str, min: f64, max: f64, doc: &'static str, source: &'static str) -> ParamDef {
        ParamDef { key, kind: Kind::AutoNumber, default: f64::NAN, min, max, doc, source }
    }
    /// An on/off switch.
    pub const fn flag(key: &'static str, default: bool, doc: &'static str, source: &'static str) -> ParamDef {
        ParamDef { key, kind: Kind::Flag, default: default as u32 as f64, min: 0.0, max: 1.0, doc, source }
    }
    /// One of `names`, `names[default]` by default.
    pub const fn choice(
        key: &'static str,
        names: &'static [&'static str],
        default: usize,
        doc: &'static str,
        source: &'static str,
    ) -> ParamDef {
        assert!(default < names.len());
        ParamDef { key, kind: Kind::Choice(names), default: default as f64, min: 0.0, max: (names.len() - 1) as f64, doc, source }
    }
    /// The same parameter with another default and the source of that default.
    pub const fn with_default(self, default: f64, source: &'static str) -> ParamDef {
        ParamDef { default, source, ..self }
    }
    /// The same parameter with another description.
    pub const fn with_doc(self, doc: &'static str) -> ParamDef {
        ParamDef { doc, ..self }
    }
    /// The same parameter with another range.
    pub const fn with_range(self, min: f64, max: f64) -> ParamDef {
        ParamDef { min, max, ..self }
    }

    /// The default as a typed value.
    pub fn default_value(&self) -> Value {
        match self.kind {
            Kind::Number => Value::Number(self.default),
            Kind::Integer => Value::Integer(self.default as i64),
            Kind::Flag => Value::Flag(self.default != 0.0),
            Kind::Choice(names) => Value::Choice(names[self.default as usize].to_string()),
            Kind::AutoNumber if self.default.is_nan() => Value::Choice(AUTO.to_string()),
            Kind::AutoNumber => Value::Number(self.default),
        }
    }

    /// The default as the user writes it (`512`, `0.5`, `true`, `sort`).
    pub fn default_text(&self) -> String {
        self.default_value().to_string()
    }

    /// The accepted values as the listing shows them (`16..16384, whole`, `true|false`).
    pub fn range_text(&self) -> String {
        match self.kind {
            Kind::Number => format!("{}..{}", self.min, self.max),
            Kind::Integer => format!("{}..{}, whole", self.min, self.max),
            Kind::Flag => "true|false".into(),
            Kind::Choice(names) => names.join("|"),
            Kind::AutoNumber => format!("{AUTO} or {}..{}", self.min, self.max),
        }
    }

    /// Parses `text` as this parameter's value, with an error naming what is accepted.
    fn parse(&self, technique: &str, text: &str) -> Result<Value, String> {
        let k = self.key;
        match self.kind {
            Kind::Flag => match text {
                "true" | "1" => Ok(Value::Flag(true)),
                "false" | "0" => Ok(Value::Flag(false)),
                _ => Err(format!("technique '{technique}': {k}={text} is not one of false, true")),
            },
            Kind::Choice(names) => {
                let idx = names.iter().position(|c| *c == text).or_else(|| text.parse::<usize>().ok().filter(|i| *i < names.len()));
                let idx = idx.ok_or_else(|| format!("technique '{technique}': {k}={text} is not one of {}", names.join(", ")))?;
                Ok(Value::Choice(names[idx].to_string()))
            }
            Kind::AutoNumber if text == AUTO => Ok(Value::Choice(AUTO.to_string())),
            Kind::Number | Kind::Integer | Kind::AutoNumber => {
                let x: f64 = text.parse().ok().filter(|x: &f64| x.is_finite()).ok_or_else(|| {
                    let auto = if self.kind == Kind::AutoNumber { " (or auto)" } else { "" };
                    format!("technique '{technique}': {k}={text} is not a number{auto}")
                })?;
                let integer = self.kind == Kind::Integer;
                if integer && x.fract() != 0.0 {
                    return Err(format!("technique '{technique}': {k}={text} must be a whole number"));
                }
                if x < self.min || x > self.max {
                    return Err(format!("technique '{technique}': {k}={text} out of range [{}, {}]", self.min, self.max));
                }
                Ok(if integer { Value::Integer(x as i64) } else { Value::Number(x) })
            }
        }
    }
}

/// One resolved parameter value, as the user wrote it: choices stay names, flags booleans.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    Flag(bool),
    Integer(i64),
    Number(f64),
    Choice(String),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Flag(b) => write!(f, "{b}"),
            Value::Integer(i) => write!(f, "{i}"),
            Value::Number(x) => write!(f, "{x}"),
            Value::Choice(s) => f.write_str(s),
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
        let mut values = ParamValues::defaults(defs).0;
        for (k, v) in &self.args {
            let def = defs.iter().find(|d| d.key == k).ok_or_else(|| {
                let keys: Vec<_> = defs.iter().map(|d| d.key).collect();
                if keys.is_empty() {
                    format!("technique '{}' takes no parameters (got '{k}')", self.name)
                } else {
                    format!("technique '{}' has no parameter '{k}' (valid: {}, label)", self.name, keys.join(", "))
                }
            })?;
            values.insert(k.clone(), def.parse(&self.name, v)?);
        }
        Ok(ParamValues(values))
    }
}

/// Resolved parameter values (every declared key present), as the user wrote them: what
/// `metrics.json` records and a spec is written back from. A technique reads them once into
/// its typed settings ([`ParamSet::from_values`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct ParamValues(pub BTreeMap<String, Value>);

impl ParamValues {
    /// Every parameter of `defs` at its default.
    pub fn defaults(defs: &[ParamDef]) -> ParamValues {
        ParamValues(defs.iter().map(|d| (d.key.to_string(), d.default_value())).collect())
    }
    /// The value of `key`, for code that works on tables (listings, widgets, spec text);
    /// techniques read their typed settings ([`ParamSet::from_values`]) instead.
    pub fn value(&self, key: &str) -> Option<&Value> {
        self.0.get(key)
    }
    /// `key=value,...` in key order, as a spec writes them.
    pub fn to_spec_args(&self) -> String {
        self.0.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(",")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    const DEFS: &[ParamDef] = &[
        ParamDef::choice("select", &["minmax", "sort"], 0, "", ""),
        ParamDef::flag("sd", true, "", ""),
        ParamDef::integer("res", 512.0, 16.0, 16384.0, "", ""),
        ParamDef::number("bias", 0.5, 0.0, 100.0, "", ""),
    ];
    #[test]
    fn choices_and_flags_stay_names() {
        let v = TechniqueSpec::parse("x:select=sort,sd=false").unwrap().resolve(DEFS).unwrap();
        assert_eq!((v.value("select"), v.value("sd")), (Some(&Value::Choice("sort".into())), Some(&Value::Flag(false))));
        let v = TechniqueSpec::parse("x:sd=1,select=1").unwrap().resolve(DEFS).unwrap();
        assert_eq!((v.value("select"), v.value("sd")), (Some(&Value::Choice("sort".into())), Some(&Value::Flag(true))));
        let e = TechniqueSpec::parse("x:select=median").unwrap().resolve(DEFS).unwrap_err();
        assert!(e.contains("minmax, sort"), "{e}");
        assert!(TechniqueSpec::parse("x:sd=2").unwrap().resolve(DEFS).is_err());
        assert_eq!(DEFS[0].default_text(), "minmax");
        assert_eq!(DEFS[1].default_text(), "true");
        assert_eq!(DEFS[2].default_text(), "512");
        let json = serde_json::to_string(&v).unwrap();
        assert_eq!(json, r#"{"bias":0.5,"res":512,"sd":true,"select":"sort"}"#);
        assert_eq!(serde_json::from_str::<ParamValues>(&json).unwrap(), v);
        assert_eq!(v.to_spec_args(), "bias=0.5,res=512,sd=true,select=sort");
    }
    #[test]
    fn parse_and_resolve() {
        let s = TechniqueSpec::parse("sm:res=2048, bias=1.5,label=big").unwrap();
        assert_eq!(s.name, "sm");
        assert_eq!(s.label(), "big");
        let v = s.resolve(DEFS).unwrap();
        assert_eq!((v.value("res"), v.value("bias")), (Some(&Value::Integer(2048)), Some(&Value::Number(1.5))));
        let d = TechniqueSpec::parse("sm").unwrap();
        assert_eq!(d.label(), "sm");
        assert_eq!(d.resolve(DEFS).unwrap(), ParamValues::defaults(DEFS));
    }
    #[test]
    fn errors_are_specific() {
        let e = TechniqueSpec::parse("sm:rez=2").unwrap().resolve(DEFS).unwrap_err();
        assert!(e.contains("no parameter 'rez'") && e.contains("select, sd, res, bias"), "{e}");
        assert!(TechniqueSpec::parse("sm:res=1.5").unwrap().resolve(DEFS).unwrap_err().contains("whole"));
        assert!(TechniqueSpec::parse("sm:res=8").unwrap().resolve(DEFS).unwrap_err().contains("range"));
        assert!(TechniqueSpec::parse("sm:res=abc").unwrap().resolve(DEFS).unwrap_err().contains("not a number"));
        assert!(TechniqueSpec::parse("sm:res").is_err());
        assert!(TechniqueSpec::parse("sm:res=1,res=2").is_err());
        assert!(TechniqueSpec::parse("").is_err());
        assert!(TechniqueSpec::parse("s m").is_err());
    }
}
