// The camera-ray generator of every kernel that makes its primary rays on
// the GPU (the tet walks' `load_ray` in `common.wgsl`, the BVH kernel
// `bvh.wgsl`): one function in one place, so that the walks and the BVH
// trace bit-identical rays. Conventions of `scenes.json`, as
// `tet_trace_cpu::render::PinholeCamera`; the host fills `Camera` from
// `records::CameraRec` (in f32, see `CameraRec::new`).

struct Camera {
    eye: vec4<f32>,
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // half_h, aspect, pixel offset (0 or 0.5), unused
    lens: vec4<f32>,
};

// Unit direction of the ray through pixel `pix` (row-major from the top) of
// a `width x height` image.
fn camera_direction(c: Camera, pix: u32, width: u32, height: u32) -> vec3<f32> {
    let i = pix % width;
    let j = pix / width;
    let x = 2.0 * (f32(i) + c.lens.z) / f32(width) - 1.0;
    let y = 1.0 - 2.0 * (f32(j) + c.lens.z) / f32(height);
    let half_h = c.lens.x;
    let dd = c.forward.xyz + c.right.xyz * (half_h * c.lens.y * x) + c.up.xyz * (half_h * y);
    let len = sqrt(dd.x * dd.x + dd.y * dd.y + dd.z * dd.z);
    return dd * (1.0 / len);
}
