// The view inputs every visibility pass reads, bind group 0 bindings 0-5 (techniques/mod.rs
// `view_bindings`); a technique's own bindings follow from 6.

// Lab-only instrumentation (view samples counted per shadow texel): false in the timed
// evaluation, true in the analysis pipeline of the same shader (`Technique::analyze`), which the
// lab runs after the timed frame.
override COUNT_SAMPLES: bool = false;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> light: LightU;
@group(0) @binding(2) var g_position: texture_2d<f32>;
@group(0) @binding(3) var g_normal: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> mask: array<u32>;
@group(0) @binding(5) var<storage, read_write> visibility: array<f32>;

// One evaluated view sample: world position, normal (facing the camera), pixel index.
struct Sample {
    p: vec3<f32>,
    n: vec3<f32>,
    i: u32,
}

// Loads the sample of thread `id`. Returns false (having written visibility 0 where the pixel
// exists but is not evaluated) when there is nothing to evaluate.
fn load_sample(id: vec3<u32>, s: ptr<function, Sample>) -> bool {
    if id.x >= frame.size.x || id.y >= frame.size.y {
        return false;
    }
    let i = id.y * frame.size.x + id.x;
    if mask[i] == 0u {
        visibility[i] = 0.0;
        return false;
    }
    (*s).p = textureLoad(g_position, id.xy, 0).xyz;
    (*s).n = textureLoad(g_normal, id.xy, 0).xyz;
    (*s).i = i;
    return true;
}
