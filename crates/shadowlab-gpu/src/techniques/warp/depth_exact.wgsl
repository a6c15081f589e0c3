// Fragment stage of the warped depth pass with `exact_depth` (see depth.wgsl): the fragment's
// warped map coordinate t is pulled back through the warp by Newton steps on warp(u) = t
// (lookup.wgsl `unwarp`: 3 steps, forward-difference Jacobian over half a texel; or exactly,
// `unwarp_exact`, with `exact_inverse`), and the
// depth of the piece's plane at u is written (paraboloid: the distance along the direction of u
// to the triangle's plane). Clamped to the piece corners' depth range, so a
// bad inversion is never worse than the interpolated depth's worst case.

// The report's count of the fragments that invert the warp (depth.rs `counting_pipeline`):
// the others are discarded.
override COUNT_INVERSIONS: bool = false;

@fragment
fn fs_main(in: VsOut) -> @builtin(frag_depth) f32 {
    if discarded(in) {
        discard;
    }
    // no plane (seen edge-on), or a piece whose interpolated depth is close enough (`exact_tol`)
    if in.plane.w == 0.0 {
        if COUNT_INVERSIONS {
            discard;
        }
        return in.clip.z;
    }
    let res = wp.res;
    var inv = vec3<f32>(0.0);
    if EXACT_INVERSE {
        // searched from the screen-linear unwarped coordinate (within about `subdiv` texels)
        inv = vec3<f32>(unwarp_exact(in.clip.xy / res, clamp(in.u, vec2<f32>(0.0), vec2<f32>(1.0))), 0.0);
    } else {
        inv = unwarp(in.clip.xy / res, in.u);
    }
    // not converged: the rasterised depth
    if inv.z > FALLBACK {
        return in.clip.z;
    }
    let u = inv.xy;
    if PARABOLOID {
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

// Above this residual (warped texels) the inversion failed and the interpolated depth is kept.
const FALLBACK: f32 = 0.25;
