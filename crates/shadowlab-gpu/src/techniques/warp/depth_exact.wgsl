// Fragment stage of the warped depth pass with `exact_depth` (see depth.wgsl): the fragment's
// warped map coordinate t is pulled back through the warp by Newton steps on warp(u) = t
// (forward-difference Jacobian over half a texel, the same lookups as the evaluation), and the
// depth of the piece's plane at u is written (paraboloid: the distance along the direction of u
// to the triangle's plane). Clamped to the piece corners' depth range, so a
// bad inversion is never worse than the interpolated depth's worst case.

@fragment
fn fs_main(in: VsOut) -> @builtin(frag_depth) f32 {
    if cut_out(materials[in.material], in.uv) || behind_hemisphere(in) {
        discard;
    }
    if in.plane.w == 0.0 {
        return in.clip.z;
    }
    let res = wp.texel.z;
    let t = in.clip.xy / res;
    let h = 0.5 / res;
    var u = in.u;
    // the best iterate so far (Newton on a warp with a kink per texel can bounce)
    var best = u;
    var best_e = 1e30;
    for (var i = 0; i <= NEWTON_STEPS; i++) {
        let w = warp(u);
        let f = w - t;
        let e = dot(f, f);
        if e < best_e {
            best_e = e;
            best = u;
        }
        if i == NEWTON_STEPS || e < TOLERANCE * TOLERANCE / (res * res) {
            break;
        }
        let jx = (warp(u + vec2<f32>(h, 0.0)) - w) / h;
        let jy = (warp(u + vec2<f32>(0.0, h)) - w) / h;
        let det = jx.x * jy.y - jy.x * jx.y;
        if abs(det) < 1e-6 {
            break;
        }
        var s = vec2<f32>(jy.y * f.x - jy.x * f.y, jx.x * f.y - jx.y * f.x) / det;
        // at most MAX_STEP texels per step (a kink can throw the linearisation far off)
        let len = length(s);
        if len > MAX_STEP / res {
            s *= MAX_STEP / res / len;
        }
        u -= s;
    }
    // not converged: the rasterised depth
    if best_e > FALLBACK * FALLBACK / (res * res) {
        return in.clip.z;
    }
    u = best;
    if is_paraboloid(wp) {
        // the direction of the unwarped map point, then the distance to the plane along it
        let r = dv_rect();
        let m = r.xy + u * (r.zw - r.xy);
        let x = vec2<f32>(2.0 * m.x - 1.0, 1.0 - 2.0 * m.y);
        let r2 = dot(x, x);
        let n = vec3<f32>(2.0 * x, 1.0 - r2) / (1.0 + r2);
        let d = in.plane.w / dot(in.plane.xyz, n);
        if !(d > 0.0) {
            return in.clip.z;
        }
        return clamp(d, in.zrange.x, in.zrange.y);
    }
    let d = dot(in.plane.xy, u) + in.plane.z;
    return clamp(d, in.zrange.x, in.zrange.y);
}

// Newton steps: the screen-linear guess is within the bend threshold (1-2 texels) of the answer.
const NEWTON_STEPS: i32 = 3;
// Converged when the warped point is this close to the fragment (warped texels).
const TOLERANCE: f32 = 0.01;
// Above this residual (warped texels) the inversion failed and the interpolated depth is kept.
const FALLBACK: f32 = 0.25;
// Largest Newton step (cropped texels).
const MAX_STEP: f32 = 4.0;
