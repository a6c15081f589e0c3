//! One widget per parameter, generated from the technique's declared table: numbers get range
//! sliders (logarithmic over wide ranges), whole numbers steppers (doubling for map sizes),
//! flags checkboxes, choices drop-downs. Edits produce a spec text that resolves through the
//! same parser as `-t`, so what the viewer runs is what a saved setup reproduces.

use eframe::egui;
use shadowlab_core::params::{Kind, ParamDef, ParamValues, TechniqueSpec, Value, AUTO};
use shadowlab_gpu::registry::{self, Resolved};
use shadowlab_gpu::GpuError;

/// The widget a parameter gets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Widget {
    /// A range slider; logarithmic when the range spans more than two decades (from 0 or above).
    Slider {
        min: f64,
        max: f64,
        log: bool,
    },
    /// An integer stepper; `doubling` steps by powers of two (map sizes).
    Stepper {
        min: i64,
        max: i64,
        doubling: bool,
    },
    Checkbox,
    Dropdown(&'static [&'static str]),
    /// An `auto` checkbox, and a slider for the number when it is off.
    AutoSlider {
        min: f64,
        max: f64,
    },
}

/// The widget for `def`.
pub fn widget(def: &ParamDef) -> Widget {
    match def.kind {
        Kind::Number => Widget::Slider { min: def.min, max: def.max, log: def.min >= 0.0 && def.max / def.min.max(1e-3) > 100.0 },
        Kind::Integer => {
            let d = def.default as i64;
            Widget::Stepper { min: def.min as i64, max: def.max as i64, doubling: d >= 64 && (d as u64).is_power_of_two() }
        }
        Kind::Flag => Widget::Checkbox,
        Kind::Choice(names) => Widget::Dropdown(names),
        Kind::AutoNumber => Widget::AutoSlider { min: def.min, max: def.max },
    }
}

/// Draws `def`'s widget for `value`; true when the user changed it.
pub fn edit(ui: &mut egui::Ui, def: &ParamDef, value: &mut Value) -> egui::Response {
    let hover = format!("{}\ndefault {} ({})", def.doc, def.default_text(), def.source);
    let r = match (widget(def), value.clone()) {
        (Widget::Slider { min, max, log }, v) => {
            let mut x = match v {
                Value::Number(x) => x,
                Value::Integer(i) => i as f64,
                _ => def.default,
            };
            let r = ui.add(egui::Slider::new(&mut x, min..=max).logarithmic(log).text(def.key));
            if r.changed() {
                *value = Value::Number(x);
            }
            r
        }
        (Widget::Stepper { min, max, doubling }, v) => {
            let mut i = match v {
                Value::Integer(i) => i,
                _ => def.default as i64,
            };
            let before = i;
            let mut r = ui
                .horizontal(|ui| {
                    let down = ui.small_button("-").clicked();
                    let up = ui.small_button("+").clicked();
                    if down {
                        i = if doubling { i / 2 } else { i - 1 };
                    }
                    if up {
                        i = if doubling { i * 2 } else { i + 1 };
                    }
                    ui.add(egui::DragValue::new(&mut i).range(min..=max));
                    ui.label(def.key);
                })
                .response;
            i = i.clamp(min, max);
            if i != before {
                *value = Value::Integer(i);
                r.mark_changed();
            }
            r
        }
        (Widget::Checkbox, v) => {
            let mut b = matches!(v, Value::Flag(true));
            let r = ui.checkbox(&mut b, def.key);
            if r.changed() {
                *value = Value::Flag(b);
            }
            r
        }
        (Widget::AutoSlider { min, max }, v) => {
            let (mut auto, mut x) = match v {
                Value::Number(x) => (false, x),
                _ => (true, (min.max(0.0_f64.min(max))).clamp(min, max)),
            };
            let before = (auto, x);
            let mut r = ui
                .horizontal(|ui| {
                    ui.checkbox(&mut auto, AUTO);
                    ui.add_enabled(!auto, egui::Slider::new(&mut x, min..=max).text(def.key));
                })
                .response;
            if (auto, x) != before {
                *value = if auto { Value::Choice(AUTO.to_string()) } else { Value::Number(x) };
                r.mark_changed();
            }
            r
        }
        (Widget::Dropdown(names), v) => {
            let mut name = match v {
                Value::Choice(s) => s,
                _ => names[def.default as usize].to_string(),
            };
            let before = name.clone();
            let mut r = egui::ComboBox::from_label(def.key)
                .selected_text(name.clone())
                .show_ui(ui, |ui| {
                    for n in names {
                        ui.selectable_value(&mut name, n.to_string(), *n);
                    }
                })
                .response;
            if name != before {
                *value = Value::Choice(name);
                r.mark_changed();
            }
            r
        }
    };
    r.on_hover_text(hover)
}

/// The spec text of `values` for `name`: the keys that differ from the defaults, in key order,
/// then `label=` when one is given. `TechniqueSpec::parse` of it resolves to `values`.
pub fn spec_text(name: &str, defs: &[ParamDef], values: &ParamValues, label: Option<&str>) -> String {
    let mut args: Vec<String> = Vec::new();
    for d in defs {
        if let Some(v) = values.0.get(d.key) {
            if *v != d.default_value() {
                args.push(format!("{}={v}", d.key));
            }
        }
    }
    if let Some(l) = label {
        args.push(format!("label={l}"));
    }
    if args.is_empty() {
        name.to_string()
    } else {
        format!("{name}:{}", args.join(","))
    }
}

/// Resolves a spec text as `-t` does.
pub fn resolve_text(text: &str) -> Result<Resolved, GpuError> {
    let spec = TechniqueSpec::parse(text).map_err(GpuError::Invalid)?;
    registry::resolve(&spec, None)
}

/// The label a spec gave explicitly (`label=`), kept when its parameters are edited.
pub fn explicit_label(r: &Resolved) -> Option<String> {
    TechniqueSpec::parse(&r.text).ok().and_then(|s| s.label)
}

/// `r` with parameter `key` set to `text` (parsed as `-t` would), keeping its explicit label.
pub fn with_value(r: &Resolved, key: &str, text: &str) -> Result<Resolved, GpuError> {
    let def = r.info.params().iter().find(|d| d.key == key).ok_or_else(|| {
        let keys: Vec<_> = r.info.params().iter().map(|d| d.key).collect();
        GpuError::Invalid(format!("technique '{}' has no parameter '{key}' (valid: {})", r.info.name, keys.join(", ")))
    })?;
    let one = TechniqueSpec::parse(&format!("{}:{key}={text}", r.info.name)).map_err(GpuError::Invalid)?;
    let parsed = one.resolve(std::slice::from_ref(def)).map_err(GpuError::Invalid)?;
    let mut values = r.values.clone();
    values.0.insert(key.to_string(), parsed.0[key].clone());
    resolve_text(&spec_text(r.info.name, r.info.params(), &values, explicit_label(r).as_deref()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadowlab_gpu::registry::REGISTRY;

    #[test]
    fn every_registry_parameter_gets_a_fitting_widget() {
        let mut n = 0;
        for t in REGISTRY {
            for d in t.params() {
                n += 1;
                let default = d.default_value();
                match (widget(d), &default) {
                    (Widget::Slider { min, max, log }, Value::Number(x)) => {
                        assert!(min.is_finite() && max.is_finite() && min < max, "{}.{}: slider range {min}..{max}", t.name, d.key);
                        assert!((min..=max).contains(x), "{}.{}: default {x} outside {min}..{max}", t.name, d.key);
                        assert!(!log || min >= 0.0);
                    }
                    (Widget::Stepper { min, max, .. }, Value::Integer(i)) => {
                        assert!(min <= *i && *i <= max, "{}.{}: default {i} outside {min}..{max}", t.name, d.key)
                    }
                    (Widget::Checkbox, Value::Flag(_)) => {}
                    (Widget::Dropdown(names), Value::Choice(c)) => assert!(names.contains(&c.as_str()), "{}.{}", t.name, d.key),
                    (Widget::AutoSlider { min, max }, Value::Choice(c)) => assert!(c == AUTO && min < max, "{}.{}", t.name, d.key),
                    (w, v) => panic!("{}.{}: widget {w:?} does not edit {v:?}", t.name, d.key),
                }
            }
        }
        assert!(n > 50, "the registry declares {n} parameters");
    }

    #[test]
    fn every_registry_parameter_is_drawn_and_edits_round_trip() {
        let ctx = egui::Context::default();
        let mut drawn = 0;
        let mut total = 0;
        let mut out = ctx.run_ui(egui::RawInput::default(), |ui| {
            for t in REGISTRY {
                let r = resolve_text(t.name).expect("bare name resolves");
                for d in t.params() {
                    total += 1;
                    let mut v = r.values.0[d.key].clone();
                    let resp = edit(ui, d, &mut v);
                    drawn += resp.rect.is_positive() as usize;
                    assert_eq!(v, r.values.0[d.key], "drawing alone changes nothing");
                }
            }
        });
        // the font atlas upload a renderer would apply
        out.textures_delta.clear();
        assert_eq!(drawn, total, "every parameter has a visible widget");
        // an edit resolves through the spec parser, keeps the label, and writes only changes
        let r = resolve_text("sm:label=mine").unwrap();
        let e = with_value(&r, "res", "1024").unwrap();
        assert_eq!(e.text, "sm:res=1024,label=mine");
        assert_eq!((e.label.as_str(), e.values.value("res").cloned()), ("mine", Some(Value::Integer(1024))));
        assert_eq!(with_value(&e, "res", &r.values.0["res"].to_string()).unwrap().text, "sm:label=mine");
        assert!(with_value(&r, "nope", "1").unwrap_err().to_string().contains("valid:"));
        assert!(with_value(&r, "res", "-3").is_err());
    }
}
