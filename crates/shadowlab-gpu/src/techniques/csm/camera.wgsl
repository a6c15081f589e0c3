// Copies the view's camera (view-projection and position) out of the frame uniform into a
// storage buffer the CPU can read: the cascade fit needs the camera, which FrameInputs only
// hands over as this uniform (not copyable).

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read_write> camera: array<vec4<f32>, 5>;

@compute @workgroup_size(1)
fn main() {
    camera[0] = frame.view_proj[0];
    camera[1] = frame.view_proj[1];
    camera[2] = frame.view_proj[2];
    camera[3] = frame.view_proj[3];
    camera[4] = frame.camera_pos;
}
