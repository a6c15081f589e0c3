//! `shadowlab scenes` and `shadowlab techniques`, both read from the registries.

use anyhow::Result;
use shadowlab_core::builtin::{BUILTIN_SCENES, DEFAULT_SCENE};
use shadowlab_gpu::registry::REGISTRY;

pub fn scenes() -> Result<()> {
    println!("Built-in scenes (no files needed):");
    for s in BUILTIN_SCENES {
        let scene = (s.build)();
        let default = if s.name == DEFAULT_SCENE { " [default]" } else { "" };
        let lights: Vec<_> = scene.lights.iter().map(|l| l.kind()).collect();
        println!("  {:<10} {:>6} tris, lights: {:<18} {}{default}", s.name, scene.triangle_count(), lights.join(", "), s.summary);
    }
    println!("\nSetups (use with --setup): see setups/*.toml; scene files load from .gltf, .glb and .obj (--scene PATH).");
    if let Ok(rd) = std::fs::read_dir("setups") {
        let mut names: Vec<_> =
            rd.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "toml")).collect();
        names.sort();
        for p in names {
            println!("  {}", p.display());
        }
    }
    Ok(())
}

pub fn techniques() -> Result<()> {
    for t in REGISTRY {
        println!("{}  —  {}", t.name, t.summary);
        println!("  lights:  {}", t.lights.join(", "));
        println!("  cost:    {}", t.cost);
        println!("  quality: {}", t.quality);
        println!("  source:  {}", t.source);
        println!("  stalls:  {}", if t.stalls.is_empty() { "none: a frame records into one submit" } else { t.stalls });
        println!("  needs:   {}", if t.needs.is_empty() { "WebGPU's default features and limits" } else { t.needs });
        let runs: Vec<String> =
            t.compare.iter().map(|a| if a.is_empty() { t.name.to_string() } else { format!("{}:{a}", t.name) }).collect();
        println!("  compare: {}", if runs.is_empty() { "not in the default set".to_string() } else { runs.join(", ") });
        if t.params().is_empty() {
            println!("  parameters: none");
        }
        for p in t.params() {
            println!("  {:<14} default {:<8} [{}]  {}  (source: {})", p.key, p.default_text(), p.range_text(), p.doc, p.source);
        }
        println!();
    }
    println!("Spec syntax: name or name:key=value,key=value (label=... names the run).");
    println!("Without -t, compare runs the `compare:` specs above: {}.", shadowlab_gpu::registry::default_compare().join(" "));
    Ok(())
}
