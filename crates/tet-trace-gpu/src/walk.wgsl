// Projected walk (Aman et al., seed 000 Algorithms 1-7) as a WGSL compute
// kernel, one invocation per ray. A port of tet-trace-cpu's `walk::step`
// with the `DuffF32` projection; see the Rust crate docs (`src/lib.rs`) for
// the decisions, the tie rule and where the arithmetic may differ from the
// CPU. The layout-specific part (`layout_vx`, `layout_exit`: Algorithms 3, 5,
// 7) is appended by the host (`GpuLayout::snippet` in `tracer.rs`).

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
    eye: vec4<f32>,
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // half_h, aspect, pixel offset (0 or 0.5), unused
    lens: vec4<f32>,
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
@group(0) @binding(1) var<storage, read> tets: array<u32>;
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

// DuffF32::project: q = P - o; (u.q, v.q), sums left to right like glam.
fn project(p: vec3<f32>) -> vec2<f32> {
    let q = p - r_o;
    return vec2<f32>(r_u.x * q.x + r_u.y * q.y + r_u.z * q.z,
                     r_v.x * q.x + r_v.y * q.y + r_v.z * q.z);
}

// True when the ray passes left of the directed edge a -> b:
// det(a, b) = a.x*b.y - a.y*b.x > 0, decided by comparing the two products
// (never subtracted, so no fused multiply-add can break the exact
// antisymmetry), ties by the symbolic perturbation of the CPU walk.
fn left(a: vec2<f32>, ia: u32, b: vec2<f32>, ib: u32) -> bool {
    let l = a.x * b.y;
    let r = a.y * b.x;
    if (l != r) {
        return l > r;
    }
    if (a.y != b.y) {
        return a.y > b.y;
    }
    if (a.x != b.x) {
        return b.x > a.x;
    }
    return ia < ib;
}

// Algorithm 1 as the CPU's EXIT_SLOT table [0, 2, 0, 0, 1, 2, 1, 0].
fn exit_slot(sa: bool, sb: bool, sc: bool) -> u32 {
    let i = select(0u, 1u, sa) | select(0u, 2u, sb) | select(0u, 4u, sc);
    return (0x01210020u >> (4u * i)) & 0xFu;
}

fn rank_of(v: u32, a: u32, b: u32, c: u32, d: u32) -> u32 {
    return select(0u, 1u, a < v) + select(0u, 1u, b < v) + select(0u, 1u, c < v)
        + select(0u, 1u, d < v);
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

// Walk state.
var<private> s_ids: array<u32, 3>;
var<private> s_p: array<vec2<f32>, 3>;
var<private> s_tet: u32;
var<private> s_link: u32;
var<private> s_visited: u32;
var<private> s_next: u32;
// Raw link of the tet being entered across its entry face (Tet16 needs it).
var<private> s_entry: u32;
var<private> s_done: bool;
var<private> s_out: HitRec;

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

// walk::resolve_face for a non-tet link: sets s_next (crossing) or s_done.
fn resolve(link: u32) {
    if ((link & 0x80000000u) == 0u) {
        s_out = finish(ST_MISS, s_visited);
        s_done = true;
        return;
    }
    let c = link & 0x7FFFFFFFu;
    // face_hit in f32 (the CPU uses f64): edge functions w_i = d.(q_j x q_k).
    let q0 = point(s_ids[0]) - r_o;
    let q1 = point(s_ids[1]) - r_o;
    let q2 = point(s_ids[2]) - r_o;
    var w = vec3<f32>(dot(r_d, cross(q1, q2)), dot(r_d, cross(q2, q0)), dot(r_d, cross(q0, q1)));
    let sum = w.x + w.y + w.z;
    if (sum != 0.0 && abs(sum) <= 3.4028235e38) {
        w = w / sum;
    } else {
        w = vec3<f32>(1.0 / 3.0);
    }
    let hp = q0 * w.x + q1 * w.y + q2 * w.z;
    let t = dot(hp, r_d) / dot(r_d, r_d);
    if (t < r_tmin) {
        let o = other_side(c, s_tet);
        if (o != NO_TET) {
            s_entry = link;
            s_next = o;
        } else {
            s_out = finish(ST_MISS, s_visited);
            s_done = true;
        }
        return;
    }
    if (t > r_tmax) {
        s_out = finish(ST_MISS, s_visited);
        s_done = true;
        return;
    }
    var h: HitRec;
    h.status = ST_HIT;
    h.triangle = faces[6u * c];
    h.face = c;
    h.t = t;
    var b = array<f32, 3>(0.0, 0.0, 0.0);
    let wa = array<f32, 3>(w.x, w.y, w.z);
    for (var k = 0u; k < 3u; k++) {
        let vk = faces[6u * c + 3u + k];
        var j = k;
        for (var m = 2i; m >= 0; m--) {
            if (s_ids[u32(m)] == vk) {
                j = u32(m);
            }
        }
        b[k] = wa[j];
    }
    h.b0 = b[0];
    h.b1 = b[1];
    h.b2 = b[2];
    h.tet = s_tet;
    h.far_tet = other_side(c, s_tet);
    h.visited = s_visited;
    s_out = h;
    s_done = true;
}

// Follows the current exit link: a tet becomes s_next, anything else is
// resolved.
fn follow() {
    if (s_link < BOUNDARY) {
        s_entry = s_tet;
        s_next = s_link;
    } else {
        resolve(s_link);
    }
}

// walk::step: enter s_next, choose the exit face, fetch its link.
fn step() {
    if (s_visited >= params.step_cap) {
        s_out = finish(ST_STEP_CAP, s_visited);
        s_done = true;
        return;
    }
    let next = s_next;
    let d = s_ids[0] ^ s_ids[1] ^ s_ids[2] ^ layout_vx(next);
    if (d >= params.point_count) {
        s_out = finish(ST_LOST, s_visited);
        s_done = true;
        return;
    }
    let pd = project(point(d));
    let sa = left(pd, d, s_p[0], s_ids[0]);
    let sb = left(pd, d, s_p[1], s_ids[1]);
    let sc = left(pd, d, s_p[2], s_ids[2]);
    let slot = exit_slot(sa, sb, sc);
    let exiting = s_ids[slot];
    let raw = layout_exit(next, d, exiting);
    s_ids[slot] = d;
    s_p[slot] = pd;
    s_tet = next;
    s_link = raw;
    s_visited += 1u;
    follow();
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

// walk::start_in_tet for the camera's start tet (ids and links in the
// canonical mesh's slot order). False when no face winds counter-clockwise
// around the origin (origin on the tet's boundary).
fn start_in_tet() -> bool {
    let ids = array<u32, 4>(params.cam_ids.x, params.cam_ids.y, params.cam_ids.z, params.cam_ids.w);
    let links = array<u32, 4>(params.cam_links.x, params.cam_links.y, params.cam_links.z,
                              params.cam_links.w);
    var p: array<vec2<f32>, 4>;
    for (var i = 0u; i < 4u; i++) {
        p[i] = project(point(ids[i]));
    }
    for (var k = 0u; k < 4u; k++) {
        let s = face_slots(k);
        if (left(p[s.x], ids[s.x], p[s.y], ids[s.y]) && left(p[s.y], ids[s.y], p[s.z], ids[s.z])
            && left(p[s.z], ids[s.z], p[s.x], ids[s.x])) {
            s_ids = array<u32, 3>(ids[s.x], ids[s.y], ids[s.z]);
            s_p = array<vec2<f32>, 3>(p[s.x], p[s.y], p[s.z]);
            s_tet = params.cam_tet;
            s_link = links[k];
            s_visited = 1u;
            return true;
        }
    }
    return false;
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

fn trace_ray(idx: u32) -> HitRec {
    s_done = false;
    if (params.camera_mode != 0u) {
        let pix = params.first_ray + idx;
        let i = pix % params.width;
        let j = pix / params.width;
        let x = 2.0 * (f32(i) + params.lens.z) / f32(params.width) - 1.0;
        let y = 1.0 - 2.0 * (f32(j) + params.lens.z) / f32(params.height);
        let half_h = params.lens.x;
        let dd = params.forward.xyz + params.right.xyz * (half_h * params.lens.y * x)
            + params.up.xyz * (half_h * y);
        let len = sqrt(dd.x * dd.x + dd.y * dd.y + dd.z * dd.z);
        r_d = dd * (1.0 / len);
        r_o = params.eye.xyz;
        r_tmin = 0.0;
        r_tmax = 3.4028235e38;
        let dl = sqrt(r_d.x * r_d.x + r_d.y * r_d.y + r_d.z * r_d.z);
        duff_basis(r_d / dl);
        if (!start_in_tet()) {
            return finish(ST_LOST, 0u);
        }
        follow();
    } else {
        let ray = rays[idx];
        r_o = ray.o.xyz;
        r_tmin = ray.o.w;
        r_d = ray.d.xyz;
        r_tmax = ray.d.w;
        r_u = ray.u.xyz;
        r_v = ray.v.xyz;
        let st = starts[idx];
        if (st.mode == START_DONE) {
            return finish(st.link, st.visited);
        }
        s_ids = array<u32, 3>(st.i0, st.i1, st.i2);
        for (var k = 0u; k < 3u; k++) {
            s_p[k] = project(point(s_ids[k]));
        }
        s_tet = st.tet;
        s_link = st.link;
        s_visited = st.visited;
        if (st.mode == START_ENTER) {
            s_entry = st.link;
            s_next = st.next;
        } else {
            follow();
        }
    }
    // The step cap bounds this loop (every iteration visits one tet).
    loop {
        if (s_done) {
            break;
        }
        step();
    }
    return s_out;
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
