//! Typed parameter sets: one declaration gives a technique both its struct of settings and the
//! [`ParamDef`] table the CLI, the viewer and the reports list.
//!
//! ```
//! use shadowlab_core::params::{family, Block, ParamDef, ParamSet};
//! shadowlab_core::param_choice! {
//!     /// How the map is filtered.
//!     pub enum Filter { Nearest = "nearest", Linear = "linear" }
//! }
//! shadowlab_core::param_set! {
//!     /// A technique's settings.
//!     pub struct MySettings {
//!         pub res: u32 = family::RES,
//!         pub filter: Filter = ParamDef::choice("filter", Filter::NAMES, 0, "map filter", "example"),
//!         pub bias: family::Bias = Block::as_declared(),
//!     }
//! }
//! let s = MySettings::defaults();
//! assert_eq!((s.res, s.filter, s.bias.bias), (512, Filter::Nearest, 0.5));
//! assert_eq!(MySettings::defs().len(), 6);
//! ```
//!
//! A field's name is its key; its type decides which kind of parameter it may be declared as
//! (`u32`: whole number, `f32`/`f64`: number, `bool`: flag, a [`param_choice!`] enum: choice of
//! its names, a [`param_set!`] struct: that block's rows, with a [`Block`] of overrides).
//! A declaration that breaks these rules panics when the table is first built, which every
//! registry test does.
//!
//! A set may add `rules { ... }`: [`ParamSet::validate`] (rules across parameters, e.g. a
//! window below the map size) and [`ParamSet::ineffective`] (keys that do nothing with the
//! other values: an explicitly given one is an error naming why).

use super::{Kind, ParamDef, ParamValues, Value};

/// A declared set of parameters (made by [`param_set!`]).
pub trait ParamSet: Sized {
    /// The table, in listing order (blocks in place).
    fn defs() -> &'static [ParamDef];
    /// The typed settings of values resolved against [`ParamSet::defs`].
    fn from_values(v: &ParamValues) -> Self;
    /// The settings at their defaults.
    fn defaults() -> Self {
        Self::from_values(&ParamValues::defaults(Self::defs()))
    }
    /// Rules across parameters; the error says which values conflict.
    fn validate(&self) -> Result<(), String> {
        Ok(())
    }
    /// `(key, why)` for each parameter that has no effect with these values.
    fn ineffective(&self) -> Vec<(&'static str, String)> {
        Vec::new()
    }
}

/// A type a declared field can have: how it is declared and how it is read.
pub trait Field: Sized {
    /// What the declaration gives: a [`ParamDef`] for a single parameter, a [`Block`] for a set.
    type Decl;
    /// Appends the field's rows to `out`, checking them against the field's name and type.
    fn declare(decl: Self::Decl, field: &'static str, out: &mut Vec<ParamDef>);
    /// Reads the field from resolved values.
    fn read(v: &ParamValues, field: &'static str) -> Self;
}

fn single(def: ParamDef, field: &str, fits: bool, ty: &str, out: &mut Vec<ParamDef>) {
    assert_eq!(def.key, field, "field '{field}' is declared with the parameter '{}'", def.key);
    assert!(fits, "field '{field}' ({ty}) is declared as {:?}", def.kind);
    out.push(def);
}

fn value<'a>(v: &'a ParamValues, key: &str) -> &'a Value {
    v.0.get(key).unwrap_or_else(|| panic!("parameter '{key}' missing from resolved values"))
}

impl Field for u32 {
    type Decl = ParamDef;
    fn declare(d: ParamDef, field: &'static str, out: &mut Vec<ParamDef>) {
        single(d, field, d.kind == Kind::Integer && d.min >= 0.0 && d.max <= u32::MAX as f64, "u32", out)
    }
    fn read(v: &ParamValues, field: &'static str) -> u32 {
        match value(v, field) {
            Value::Integer(i) => *i as u32,
            x => panic!("parameter '{field}' is {x:?}, not a whole number"),
        }
    }
}

impl Field for f64 {
    type Decl = ParamDef;
    fn declare(d: ParamDef, field: &'static str, out: &mut Vec<ParamDef>) {
        single(d, field, d.kind == Kind::Number, "f64", out)
    }
    fn read(v: &ParamValues, field: &'static str) -> f64 {
        match value(v, field) {
            Value::Number(x) => *x,
            x => panic!("parameter '{field}' is {x:?}, not a number"),
        }
    }
}

impl Field for f32 {
    type Decl = ParamDef;
    fn declare(d: ParamDef, field: &'static str, out: &mut Vec<ParamDef>) {
        single(d, field, d.kind == Kind::Number, "f32", out)
    }
    fn read(v: &ParamValues, field: &'static str) -> f32 {
        f64::read(v, field) as f32
    }
}

impl Field for bool {
    type Decl = ParamDef;
    fn declare(d: ParamDef, field: &'static str, out: &mut Vec<ParamDef>) {
        single(d, field, d.kind == Kind::Flag, "bool", out)
    }
    fn read(v: &ParamValues, field: &'static str) -> bool {
        match value(v, field) {
            Value::Flag(b) => *b,
            x => panic!("parameter '{field}' is {x:?}, not a flag"),
        }
    }
}

/// An [`Kind::AutoNumber`] value: the technique chooses (`auto`), or the number given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Auto {
    Auto,
    Fixed(f64),
}

impl Field for Auto {
    type Decl = ParamDef;
    fn declare(d: ParamDef, field: &'static str, out: &mut Vec<ParamDef>) {
        single(d, field, d.kind == Kind::AutoNumber, "Auto", out)
    }
    fn read(v: &ParamValues, field: &'static str) -> Auto {
        match value(v, field) {
            Value::Choice(s) if s == super::AUTO => Auto::Auto,
            Value::Number(x) => Auto::Fixed(*x),
            x => panic!("parameter '{field}' is {x:?}, not auto or a number"),
        }
    }
}

/// For [`param_choice!`]: declares a choice field whose names must be the enum's.
pub fn declare_choice(d: ParamDef, names: &'static [&'static str], field: &'static str, out: &mut Vec<ParamDef>) {
    let fits = matches!(d.kind, Kind::Choice(n) if n == names);
    single(d, field, fits, "choice enum", out)
}

/// For [`param_choice!`]: the index of the chosen name.
pub fn read_choice(v: &ParamValues, names: &[&str], field: &'static str) -> usize {
    match value(v, field) {
        Value::Choice(s) => {
            names.iter().position(|n| n == s).unwrap_or_else(|| panic!("parameter '{field}': '{s}' is not one of {names:?}"))
        }
        x => panic!("parameter '{field}' is {x:?}, not a choice"),
    }
}

/// How a block (a nested [`param_set!`]) is declared inside another set: as the block
/// declares it, or with some rows replaced by rows of the same key (another default, doc or
/// range).
#[derive(Clone, Debug, Default)]
pub struct Block {
    replace: Vec<ParamDef>,
}

impl Block {
    /// The block's rows as it declares them.
    pub fn as_declared() -> Block {
        Block::default()
    }
    /// Replaces the block's row of `def.key` with `def` (its kind must stay the same).
    pub fn with(mut self, def: ParamDef) -> Block {
        self.replace.push(def);
        self
    }
    /// For [`param_set!`]: the block's rows with the replacements applied.
    pub fn apply(self, rows: &[ParamDef], out: &mut Vec<ParamDef>) {
        for r in &self.replace {
            let own = rows.iter().find(|d| d.key == r.key).unwrap_or_else(|| panic!("block has no parameter '{}' to replace", r.key));
            assert_eq!(own.kind, r.kind, "replacement of '{}' changes its kind", r.key);
        }
        out.extend(rows.iter().map(|d| *self.replace.iter().find(|r| r.key == d.key).unwrap_or(d)));
    }
}

/// Checks a finished table: keys unique, defaults in range, every row documented.
pub fn check_table(set: &str, rows: &[ParamDef]) {
    for (i, d) in rows.iter().enumerate() {
        assert!(rows[..i].iter().all(|o| o.key != d.key), "{set}: '{}' declared twice", d.key);
        let auto = d.kind == Kind::AutoNumber && d.default.is_nan();
        assert!(
            auto || (d.min <= d.default && d.default <= d.max),
            "{set}: {} default {} outside [{}, {}]",
            d.key,
            d.default,
            d.min,
            d.max
        );
        assert!(!d.doc.is_empty() && !d.source.is_empty(), "{set}: {} needs a doc and a source", d.key);
    }
}

/// A set's table and checks as plain functions, for a registry entry.
#[derive(Clone, Copy)]
pub struct ParamTable {
    /// The rows ([`ParamSet::defs`]).
    pub defs: fn() -> &'static [ParamDef],
    /// Builds the typed settings of resolved values and applies the set's rules: a conflict,
    /// or an explicitly `given` key that has no effect, is an error.
    pub check: fn(&ParamValues, given: &[&str]) -> Result<(), String>,
}

impl ParamTable {
    /// The table of `P`.
    pub const fn of<P: ParamSet>() -> ParamTable {
        ParamTable { defs: P::defs, check: check::<P> }
    }
    /// The table of a technique that takes no parameters.
    pub const NONE: ParamTable = ParamTable { defs: no_defs, check: no_check };
}

fn no_defs() -> &'static [ParamDef] {
    &[]
}

fn no_check(_: &ParamValues, _: &[&str]) -> Result<(), String> {
    Ok(())
}

fn check<P: ParamSet>(values: &ParamValues, given: &[&str]) -> Result<(), String> {
    let p = P::from_values(values);
    p.validate()?;
    let unused: Vec<String> =
        p.ineffective().into_iter().filter(|(k, _)| given.contains(k)).map(|(k, why)| format!("{k} has no effect: {why}")).collect();
    if unused.is_empty() {
        Ok(())
    } else {
        Err(unused.join("; "))
    }
}

/// Declares a parameter set: the struct, its table and its reading. See the [module](self).
#[macro_export]
macro_rules! param_set {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$fmeta:meta])* $fvis:vis $field:ident : $fty:ty = $decl:expr ),* $(,)?
        }
        $( rules { $($rules:tt)* } )?
    ) => {
        $(#[$meta])*
        #[derive(Clone, Debug, PartialEq)]
        $vis struct $name {
            $( $(#[$fmeta])* $fvis $field: $fty, )*
        }

        impl $crate::params::ParamSet for $name {
            fn defs() -> &'static [$crate::params::ParamDef] {
                static DEFS: ::std::sync::OnceLock<::std::vec::Vec<$crate::params::ParamDef>> = ::std::sync::OnceLock::new();
                DEFS.get_or_init(|| {
                    let mut out = ::std::vec::Vec::new();
                    $( <$fty as $crate::params::Field>::declare($decl, stringify!($field), &mut out); )*
                    $crate::params::check_table(stringify!($name), &out);
                    out
                })
            }
            fn from_values(v: &$crate::params::ParamValues) -> Self {
                $name { $( $field: <$fty as $crate::params::Field>::read(v, stringify!($field)), )* }
            }
            $( $($rules)* )?
        }

        impl $crate::params::Field for $name {
            type Decl = $crate::params::Block;
            fn declare(decl: $crate::params::Block, _field: &'static str, out: &mut ::std::vec::Vec<$crate::params::ParamDef>) {
                decl.apply(<$name as $crate::params::ParamSet>::defs(), out)
            }
            fn read(v: &$crate::params::ParamValues, _field: &'static str) -> Self {
                <$name as $crate::params::ParamSet>::from_values(v)
            }
        }
    };
}

/// Declares the enum of a choice parameter: variants and the names users write.
#[macro_export]
macro_rules! param_choice {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident { $( $(#[$vmeta:meta])* $var:ident = $text:literal ),+ $(,)? }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        $vis enum $name { $( $(#[$vmeta])* $var ),+ }

        #[allow(dead_code)]
        impl $name {
            /// The names, in declaration order (a choice's index is its position here).
            pub const NAMES: &'static [&'static str] = &[$($text),+];
            const ALL: &'static [$name] = &[$($name::$var),+];
            /// The name users write.
            pub fn name(self) -> &'static str {
                Self::NAMES[self as usize]
            }
            /// The position among [`Self::NAMES`] (a shader's mode number, say).
            pub fn index(self) -> usize {
                self as usize
            }
        }

        impl $crate::params::Field for $name {
            type Decl = $crate::params::ParamDef;
            fn declare(d: $crate::params::ParamDef, field: &'static str, out: &mut ::std::vec::Vec<$crate::params::ParamDef>) {
                $crate::params::declare_choice(d, Self::NAMES, field, out)
            }
            fn read(v: &$crate::params::ParamValues, field: &'static str) -> Self {
                Self::ALL[$crate::params::read_choice(v, Self::NAMES, field)]
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::super::{family, TechniqueSpec};
    use super::*;

    crate::param_choice! {
        /// test choice
        pub enum Mode { Fast = "fast", Exact = "exact" }
    }
    crate::param_set! {
        /// test set
        pub struct Demo {
            pub res: u32 = family::RES,
            pub mode: Mode = ParamDef::choice("mode", Mode::NAMES, 1, "mode", "test"),
            pub window: u32 = ParamDef::integer("window", 16.0, 0.0, 1024.0, "window", "test"),
            pub bias: family::Bias = Block::as_declared().with(family::BIAS.with_default(1.5, "test")),
        }
        rules {
            fn validate(&self) -> Result<(), String> {
                if self.window >= self.res { Err(format!("window {} must be below res {}", self.window, self.res)) } else { Ok(()) }
            }
            fn ineffective(&self) -> Vec<(&'static str, String)> {
                if self.mode == Mode::Fast { vec![("window", "mode=fast has no window".into())] } else { vec![] }
            }
        }
    }

    fn resolve(spec: &str) -> Result<Demo, String> {
        let s = TechniqueSpec::parse(spec).unwrap();
        let v = s.resolve(Demo::defs())?;
        let given: Vec<&str> = s.args.iter().map(|(k, _)| k.as_str()).collect();
        (ParamTable::of::<Demo>().check)(&v, &given)?;
        Ok(Demo::from_values(&v))
    }

    #[test]
    fn a_set_reads_its_fields_and_blocks() {
        let keys: Vec<_> = Demo::defs().iter().map(|d| d.key).collect();
        assert_eq!(keys, ["res", "mode", "window", "bias", "slope_bias", "max_slope", "normal_offset"]);
        let d = Demo::defaults();
        assert_eq!((d.res, d.mode, d.window, d.bias.bias, d.bias.normal_offset), (512, Mode::Exact, 16, 1.5, 0.5));
        let d = resolve("x:mode=fast,res=1024,slope_bias=2").unwrap();
        assert_eq!((d.res, d.mode, d.bias.slope_bias), (1024, Mode::Fast, 2.0));
        assert_eq!(Mode::Fast.name(), "fast");
    }

    #[test]
    fn rules_reject_conflicts_and_ineffective_keys() {
        assert!(resolve("x:window=512").unwrap_err().contains("window 512 must be below res 512"));
        let e = resolve("x:mode=fast,window=8").unwrap_err();
        assert!(e.contains("window has no effect: mode=fast"), "{e}");
        // not given, so not reported
        assert!(resolve("x:mode=fast").is_ok());
    }

    crate::param_set! {
        /// a number the technique may choose
        pub struct WithAuto { pub lod: Auto = ParamDef::auto_number("lod", -2.0, 2.0, "lod bias", "test") }
    }

    #[test]
    fn an_auto_number_is_auto_or_a_number_in_range() {
        let read = |spec: &str| TechniqueSpec::parse(spec).unwrap().resolve(WithAuto::defs()).map(|v| WithAuto::from_values(&v).lod);
        assert_eq!(read("x"), Ok(Auto::Auto));
        assert_eq!(read("x:lod=auto"), Ok(Auto::Auto));
        assert_eq!(read("x:lod=-1.5"), Ok(Auto::Fixed(-1.5)));
        assert!(read("x:lod=3").unwrap_err().contains("out of range"));
        assert!(read("x:lod=fine").unwrap_err().contains("is not a number (or auto)"));
        assert_eq!((WithAuto::defs()[0].default_text(), WithAuto::defs()[0].range_text()), ("auto".into(), "auto or -2..2".into()));
    }

    crate::param_set! {
        /// a field declared with another key
        pub struct Misnamed { pub res: u32 = family::PCF }
    }
    crate::param_set! {
        /// a field of the wrong type
        pub struct Mistyped { pub pcf: f32 = family::PCF }
    }

    #[test]
    #[should_panic(expected = "declared with the parameter 'pcf'")]
    fn a_field_must_carry_its_own_key() {
        Misnamed::defs();
    }
    #[test]
    #[should_panic(expected = "(f32) is declared as Integer")]
    fn a_field_must_fit_its_kind() {
        Mistyped::defs();
    }
}
