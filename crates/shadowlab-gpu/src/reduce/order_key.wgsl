// Keys that order like the floats they encode, for min/max reductions with integer atomics
// (reduce.wgsl, csm/sdsm_bounds.wgsl). Prepended to the shaders that use them.

// Monotonic map f32 -> u32: negative floats flipped entirely, positive ones get the sign bit.
fn order_key(x: f32) -> u32 {
    let b = bitcast<u32>(x);
    if (b & 0x80000000u) != 0u {
        return ~b;
    }
    return b | 0x80000000u;
}

// The float of a key (inverse of order_key).
fn from_order_key(k: u32) -> f32 {
    if (k & 0x80000000u) != 0u {
        return bitcast<f32>(k & 0x7fffffffu);
    }
    return bitcast<f32>(~k);
}
