//! Technique specs with value lists: `sm:res=512|1024,pcf=1|3` expands to the product of its
//! lists, `sm:res=512,pcf=1`, `sm:res=512,pcf=3`, `sm:res=1024,pcf=1`, `sm:res=1024,pcf=3`:
//! the first key varies slowest, values in the order written. Every expanded spec is resolved
//! against the registry here, before any scene is loaded or GPU work starts, so a bad name,
//! key or value is one error naming the `-t` argument and the key.

use anyhow::{anyhow, bail, Result};
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::registry;

/// The separator of a value list.
pub const LIST: char = '|';

/// Most points one `-t` argument may expand to (a typo such as a long list pasted twice is
/// caught before hours of work).
pub const MAX_POINTS_PER_SPEC: usize = 4096;

/// Expands one `-t` argument into plain spec texts (each a point's label unless it has
/// `label=`), in a fixed order.
pub fn expand_one(text: &str) -> Result<Vec<String>> {
    let text = text.trim();
    let (name, rest) = match text.split_once(':') {
        Some((n, r)) => (n.trim(), r),
        None => (text, ""),
    };
    if name.contains(LIST) {
        bail!("-t '{text}': a value list (`{LIST}`) goes after a key (`name:key=a{LIST}b`), not in the technique name; give one -t per technique");
    }
    // (key, values) in the order written
    let mut axes: Vec<(String, Vec<String>)> = Vec::new();
    for kv in rest.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (k, v) = kv.split_once('=').ok_or_else(|| anyhow!("-t '{text}': expected key=value, got '{kv}'"))?;
        let (k, v) = (k.trim(), v.trim());
        let values: Vec<String> = v.split(LIST).map(|s| s.trim().to_string()).collect();
        if values.iter().any(String::is_empty) {
            bail!("-t '{text}': key '{k}' has an empty value in '{v}'");
        }
        for (i, a) in values.iter().enumerate() {
            if values[..i].contains(a) {
                bail!("-t '{text}': key '{k}' lists '{a}' twice");
            }
        }
        if k == "label" && values.len() > 1 {
            bail!("-t '{text}': 'label' cannot take a list; the points of a list are labelled by their values");
        }
        axes.push((k.to_string(), values));
    }
    let count = axes.iter().try_fold(1usize, |n, (_, v)| n.checked_mul(v.len()).filter(|n| *n <= MAX_POINTS_PER_SPEC));
    let Some(count) = count else {
        bail!("-t '{text}': expands to more than {MAX_POINTS_PER_SPEC} points; split it");
    };
    if count > 1 && axes.iter().any(|(k, _)| k == "label") {
        bail!("-t '{text}': 'label' names one run, but the lists make {count}; leave it out (each point is labelled by its values)");
    }
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        // mixed-radix digits of i, the last axis fastest
        let mut rem = i;
        let mut picks = vec![0usize; axes.len()];
        for (a, (_, values)) in axes.iter().enumerate().rev() {
            picks[a] = rem % values.len();
            rem /= values.len();
        }
        let args: Vec<String> = axes.iter().zip(&picks).map(|((k, v), p)| format!("{k}={}", v[*p])).collect();
        out.push(if args.is_empty() { name.to_string() } else { format!("{name}:{}", args.join(",")) });
    }
    Ok(out)
}

/// Expands every `-t` argument and checks each point against the registry (name, keys, kinds,
/// ranges; the light is checked per setup later). Labels must be unique over all arguments.
pub fn expand(texts: &[String]) -> Result<Vec<String>> {
    let mut out: Vec<String> = Vec::new();
    let mut labels = std::collections::HashSet::new();
    for text in texts {
        for point in expand_one(text)? {
            let spec = TechniqueSpec::parse(&point).map_err(|e| anyhow!("-t '{}': {e}", text.trim()))?;
            let resolved = registry::resolve(&spec, None).map_err(|e| anyhow!("-t '{}': {e}", text.trim()))?;
            if !labels.insert(resolved.label.clone()) {
                bail!("-t '{}': the point '{}' is given twice (labels must be unique; give one `label=...`)", text.trim(), resolved.label);
            }
            out.push(point);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(v: &[&str]) -> Vec<String> {
        v.iter().map(|x| x.to_string()).collect()
    }

    #[test]
    fn lists_expand_to_their_product_first_key_slowest() {
        assert_eq!(
            expand_one("sm:res=512|1024,pcf=1|3").unwrap(),
            s(&["sm:res=512,pcf=1", "sm:res=512,pcf=3", "sm:res=1024,pcf=1", "sm:res=1024,pcf=3"])
        );
        assert_eq!(expand_one("lt").unwrap(), s(&["lt"]));
        assert_eq!(expand_one(" notw : window = 8 | 16 ").unwrap(), s(&["notw:window=8", "notw:window=16"]));
        assert_eq!(expand_one("sm:pcf=3,label=soft").unwrap(), s(&["sm:pcf=3,label=soft"]));
        assert_eq!(expand_one("a:x=1|2,y=3,z=4|5|6").unwrap().len(), 6);
        assert_eq!(expand_one("a:x=1|2,y=3,z=4|5|6").unwrap()[5], "a:x=2,y=3,z=6");
    }

    #[test]
    fn expansion_checks_every_point_against_the_registry() {
        let v = expand(&s(&["sm:res=512|1024,pcf=1|3", "csm:res=1024|2048", "lt", "notw:window=8|16|32"])).unwrap();
        assert_eq!(v.len(), 4 + 2 + 1 + 3);
        assert_eq!(v[0], "sm:res=512,pcf=1");
        assert_eq!(v[6], "lt");
        assert_eq!(v, expand(&s(&["sm:res=512|1024,pcf=1|3", "csm:res=1024|2048", "lt", "notw:window=8|16|32"])).unwrap());
        let labels: std::collections::HashSet<_> = v.iter().collect();
        assert_eq!(labels.len(), v.len(), "labels are unique");
    }

    #[test]
    fn bad_lists_name_the_spec_and_the_key() {
        let err = |t: &str| expand(&s(&[t])).unwrap_err().to_string();
        let e = err("sm:res=512|7");
        assert!(e.contains("sm:res=512|7") && e.contains("res=7") && e.contains("out of range"), "{e}");
        let e = err("sm:res=512|,pcf=1");
        assert!(e.contains("key 'res'") && e.contains("empty value"), "{e}");
        let e = err("sm:bais=1|2");
        assert!(e.contains("sm:bais=1|2") && e.contains("'bais'"), "{e}");
        let e = err("nope:res=1|2");
        assert!(e.contains("nope"), "{e}");
        let e = err("sm|csm");
        assert!(e.contains("technique name"), "{e}");
        let e = err("sm:res=512|512");
        assert!(e.contains("twice"), "{e}");
        let e = err("sm:res=512|1024,label=x");
        assert!(e.contains("label"), "{e}");
        let e = err("sm:res");
        assert!(e.contains("key=value"), "{e}");
        let e = expand(&s(&["sm:res=512|1024", "sm:res=1024"])).unwrap_err().to_string();
        assert!(e.contains("sm:res=1024") && e.contains("twice"), "{e}");
        let e = err("sm:res=16|17|18|19|20|21|22|23,pcf=1|3|5|7|9|11|13|15,bias=0|1|2|3|4|5|6|7,x=1|2|3|4|5|6|7|8|9");
        assert!(e.contains("more than"), "{e}");
    }
}
