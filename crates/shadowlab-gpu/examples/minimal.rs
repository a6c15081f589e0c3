//! The library without the CLI: build a scene, render a G-buffer, run `sm` and the reference,
//! and compare them. Run with `cargo run --release -p shadowlab-gpu --example minimal`.

use shadowlab_core::builtin::builtin;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::Gpu;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let gpu = Gpu::new()?;
    let scene = builtin("courtyard").ok_or("no such scene")?;
    // Uploads the scene and builds its BVH once; views and techniques reuse them.
    let lab = Lab::new(&gpu, &scene)?;
    let view = lab.view(&scene.camera, &scene.camera, &scene.lights[0], 512, 512)?;
    let reference = lab.reference(&view, 1)?;
    let sm = lab.run(&view, &TechniqueSpec::parse("sm:res=1024,pcf=3")?, 3)?;
    let m = compare(&sm.visibility, &reference.visibility, &view.mask);
    println!(
        "{}: {:.2} % wrong ({:.2} % false lit) over {} pixels, {:.2} ms ({} bytes of shadow data)",
        sm.label, m.wrong_pct, m.false_lit_pct, m.evaluated_pixels, sm.total_ms, sm.report.shadow_data_bytes
    );
    Ok(())
}
