// Declarations shared by the GPU kernels (`walk.wgsl`, `tet80.wgsl`):
// outcome codes, the records exchanged with the host (layouts mirrored by
// `records.rs`), the bindings, the ray of the current invocation and the
// hit computation. Follows `camera.wgsl` (the camera-ray generator).

const BOUNDARY: u32 = 0x7FFFFFFFu;
const NO_TET: u32 = 0xFFFFFFFFu;

// Outcome codes of `HitRec.status`.
const ST_HIT: u32 = 0u;
const ST_MISS: u32 = 1u;
const ST_STEP_CAP: u32 = 2u;
const ST_INVALID: u32 = 3u;
const ST_LOST: u32 = 4u;

// Start modes of `StartRec.mode`.
const START_EXIT: u32 = 0u;   // in `tet`, leaving through face `ids` via `link`
const START_ENTER: u32 = 1u;  // about to enter `next` through face `ids`
const START_DONE: u32 = 2u;   // finished on the host: `link` holds the status

struct Params {
    ray_count: u32,
    first_ray: u32,
    step_cap: u32,
    camera_mode: u32,
    width: u32,
    height: u32,
    point_count: u32,
    cam_tet: u32,
    cam_ids: vec4<u32>,
    cam_links: vec4<u32>,
    camera: Camera,
};

struct RayRec {
    o: vec4<f32>,  // origin, t_min
    d: vec4<f32>,  // direction, t_max
    u: vec4<f32>,  // projection basis u (host f64 -> f32)
    v: vec4<f32>,  // projection basis v
};

struct StartRec {
    mode: u32,
    i0: u32,
    i1: u32,
    i2: u32,
    tet: u32,
    link: u32,
    visited: u32,
    next: u32,
};

struct HitRec {
    status: u32,
    triangle: u32,
    face: u32,
    t: f32,
    b0: f32,
    b1: f32,
    b2: f32,
    tet: u32,
    far_tet: u32,
    visited: u32,
};

@group(0) @binding(0) var<storage, read> points: array<f32>;
// Binding 1 (and 7, 8, 9 when the tet records are split over several
// bindings) holds the tet records; the host declares it together with
// `tet_word(i)`, the accessor of record word `i`.
@group(0) @binding(2) var<storage, read> faces: array<u32>;
@group(0) @binding(3) var<uniform> params: Params;
@group(0) @binding(4) var<storage, read> rays: array<RayRec>;
@group(0) @binding(5) var<storage, read> starts: array<StartRec>;
@group(0) @binding(6) var<storage, read_write> hits: array<HitRec>;

// The ray being traced (private: one per invocation).
var<private> r_o: vec3<f32>;
var<private> r_d: vec3<f32>;
var<private> r_u: vec3<f32>;
var<private> r_v: vec3<f32>;
var<private> r_tmin: f32;
var<private> r_tmax: f32;

fn point(i: u32) -> vec3<f32> {
    let k = 3u * i;
    return vec3<f32>(points[k], points[k + 1u], points[k + 2u]);
}

fn finish(status: u32, visited: u32) -> HitRec {
    var h: HitRec;
    h.status = status;
    h.triangle = NO_TET;
    h.face = NO_TET;
    h.t = 0.0;
    h.b0 = 0.0;
    h.b1 = 0.0;
    h.b2 = 0.0;
    h.tet = NO_TET;
    h.far_tet = NO_TET;
    h.visited = visited;
    return h;
}

// Constrained-face table record: triangle, front tet, back tet, v0, v1, v2.
fn other_side(c: u32, tet: u32) -> u32 {
    let front = faces[6u * c + 1u];
    let back = faces[6u * c + 2u];
    if (front == tet) {
        return back;
    }
    if (back == tet) {
        return front;
    }
    return NO_TET;
}

// FACE_VERTICES of tet-core: outward-ordered slots of face k.
fn face_slots(k: u32) -> vec3<u32> {
    switch k {
        case 0u: { return vec3<u32>(1u, 2u, 3u); }
        case 1u: { return vec3<u32>(0u, 3u, 2u); }
        case 2u: { return vec3<u32>(0u, 1u, 3u); }
        default: { return vec3<u32>(0u, 2u, 1u); }
    }
}

// Duff et al.'s orthonormal basis in f32 (the CPU builds it in f64 and
// rounds; camera rays made on the GPU use this f32 version).
fn duff_basis(n: vec3<f32>) {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let u = vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let v = vec3<f32>(b, sign + n.y * n.y * a, -n.y);
    if (dot(cross(u, v), n) >= 0.0) {
        r_u = u;
        r_v = v;
    } else {
        r_u = v;
        r_v = u;
    }
}

// The ray of invocation `idx`: generated from the camera (camera mode, the
// conventions of `scenes.json`, as `tet_trace_cpu::render::PinholeCamera`) or
// read from the batch (basis made on the host in f64, like the CPU).
fn load_ray(idx: u32) {
    if (params.camera_mode != 0u) {
        r_d = camera_direction(params.camera, params.first_ray + idx, params.width,
                               params.height);
        r_o = params.camera.eye.xyz;
        r_tmin = 0.0;
        r_tmax = 3.4028235e38;
        let dl = sqrt(r_d.x * r_d.x + r_d.y * r_d.y + r_d.z * r_d.z);
        duff_basis(r_d / dl);
    } else {
        let ray = rays[idx];
        r_o = ray.o.xyz;
        r_tmin = ray.o.w;
        r_d = ray.d.xyz;
        r_tmax = ray.d.w;
        r_u = ray.u.xyz;
        r_v = ray.v.xyz;
    }
}

// walk::face_hit in f32 (the CPU uses f64): barycentrics w.r.t. (a, b, c)
// from the edge functions w_i = d.(q_j x q_k), and the ray parameter t.
fn face_hit(a: u32, b: u32, c: u32) -> vec4<f32> {
    let q0 = point(a) - r_o;
    let q1 = point(b) - r_o;
    let q2 = point(c) - r_o;
    var w = vec3<f32>(dot(r_d, cross(q1, q2)), dot(r_d, cross(q2, q0)), dot(r_d, cross(q0, q1)));
    let sum = w.x + w.y + w.z;
    if (sum != 0.0 && abs(sum) <= 3.4028235e38) {
        w = w / sum;
    } else {
        w = vec3<f32>(1.0 / 3.0);
    }
    let hp = q0 * w.x + q1 * w.y + q2 * w.z;
    return vec4<f32>(w, dot(hp, r_d) / dot(r_d, r_d));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>,
        @builtin(num_workgroups) nwg: vec3<u32>) {
    let idx = gid.x + gid.y * nwg.x * 64u;
    if (idx >= params.ray_count) {
        return;
    }
    hits[idx] = trace_ray(idx);
}

