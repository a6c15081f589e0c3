// Cube-map faces (shadowlab_core::cube, whose tests are the hand cases of these rules): face f
// looks along n with a 90 degree square frustum; a direction d hits its plane at n + s u + t v;
// map coordinates x = (s + 1) / 2, y = (1 - t) / 2. Faces: +x, -x, +y, -y, +z, -z.

// Columns n, u, v of face f (a switch: a per-invocation array indexed at run time is slow on
// lavapipe).
fn cube_basis(f: u32) -> mat3x3<f32> {
    let x = vec3<f32>(1.0, 0.0, 0.0);
    let y = vec3<f32>(0.0, 1.0, 0.0);
    let z = vec3<f32>(0.0, 0.0, 1.0);
    switch f {
        case 0u: {
            return mat3x3<f32>(x, z, y);
        }
        case 1u: {
            return mat3x3<f32>(-x, -z, y);
        }
        case 2u: {
            return mat3x3<f32>(y, x, z);
        }
        case 3u: {
            return mat3x3<f32>(-y, x, -z);
        }
        case 4u: {
            return mat3x3<f32>(z, -x, y);
        }
        default: {
            return mat3x3<f32>(-z, x, y);
        }
    }
}

// The face of direction d: largest |component|, ties x before y before z.
fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

// Map coordinates of d on face f (outside [0, 1] beyond the face's edges).
fn cube_project(f: u32, d: vec3<f32>) -> vec2<f32> {
    let b = cube_basis(f);
    let z = dot(d, b[0]);
    return vec2<f32>((dot(d, b[1]) / z + 1.0) * 0.5, (1.0 - dot(d, b[2]) / z) * 0.5);
}

// The direction through map position m of face f (unnormalised; beyond the edges for m
// outside [0, 1]).
fn cube_direction(f: u32, m: vec2<f32>) -> vec3<f32> {
    let b = cube_basis(f);
    return b[0] + b[1] * (2.0 * m.x - 1.0) + b[2] * (1.0 - 2.0 * m.y);
}
