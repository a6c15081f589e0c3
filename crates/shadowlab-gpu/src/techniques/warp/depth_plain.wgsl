// Fragment stage of the warped depth pass with the rasterised (interpolated) depth.

@fragment
fn fs_main(in: VsOut) {
    if discarded(in) {
        discard;
    }
}
