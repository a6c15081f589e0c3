// Fragment stage of the warped depth pass with the rasterised (interpolated) depth.

@fragment
fn fs_main(in: VsOut) {
    if cut_out(materials[in.material], in.uv) || behind_hemisphere(in) {
        discard;
    }
}
