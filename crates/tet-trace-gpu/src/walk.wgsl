// Projected walk (Aman et al. 2022, Algorithms 1-7) as a WGSL compute
// kernel, one invocation per ray. A port of tet-trace-cpu's `walk::step`
// with the `DuffF32` projection; see the Rust crate docs (`src/lib.rs`) for
// the decisions, the tie rule and where the arithmetic may differ from the
// CPU. The layout-specific part (`layout_vx`, `layout_exit`: Algorithms 3, 5,
// 7) is appended by the host (`GpuLayout::snippet` in `layout.rs`).

// DuffF32::project: q = P - o; (u.q, v.q), sums left to right like glam.
fn project(p: vec3<f32>) -> vec2<f32> {
    let q = p - r_o;
    return vec2<f32>(r_u.x * q.x + r_u.y * q.y + r_u.z * q.z,
                     r_v.x * q.x + r_v.y * q.y + r_v.z * q.z);
}

// x rounded to its upper 12 significant bits (half an ulp of those added to
// the magnitude's bits, then masked): x - hi(x) is exact with at most 11
// significant bits, the split of Dekker's product (Veltkamp's, without its
// multiply, which a driver could fuse into a different split). Finite x of
// the walk's magnitudes only (see `walk_scale` on the CPU).
fn split_hi(x: f32) -> f32 {
    return bitcast<f32>((bitcast<u32>(x) + 0x800u) & 0xFFFFF000u);
}

// The rounding error of p = fl(a * b), exactly: a * b = p + err (Dekker's
// two-product). Every product of halves is exact, so a driver's fused
// multiply-adds cannot change it.
fn product_error(a: f32, b: f32, p: f32) -> f32 {
    let ah = split_hi(a);
    let al = a - ah;
    let bh = split_hi(b);
    let bl = b - bh;
    return al * bl - (((p - ah * bh) - al * bh) - ah * bl);
}

// True when the ray passes left of the directed edge a -> b:
// det(a, b) = a.x*b.y - a.y*b.x > 0, decided by comparing the two rounded
// products (never subtracted, so no fused multiply-add can break the exact
// antisymmetry; rounding is monotonic, so unequal rounded products order
// the exact ones). Equal rounded products are decided by the exact
// determinant, the difference of their rounding errors, as the CPU's
// `ExactDet`; an exact zero by the symbolic perturbation of the CPU walk.
fn left(a: vec2<f32>, ia: u32, b: vec2<f32>, ib: u32) -> bool {
    let l = a.x * b.y;
    let r = a.y * b.x;
    if (l != r) {
        return l > r;
    }
    let exact = product_error(a.x, b.y, l) - product_error(a.y, b.x, r);
    if (exact != 0.0) {
        return exact > 0.0;
    }
    if (a.y != b.y) {
        return a.y > b.y;
    }
    if (a.x != b.x) {
        return b.x > a.x;
    }
    return ia < ib;
}

// Algorithm 1 as the CPU's EXIT_SLOT table, packed 4 bits per entry by the
// host into EXIT_SLOT_PACKED (from `tet_trace_cpu::walk::EXIT_SLOT`).
fn exit_slot(sa: bool, sb: bool, sc: bool) -> u32 {
    let i = select(0u, 1u, sa) | select(0u, 2u, sb) | select(0u, 4u, sc);
    return (EXIT_SLOT_PACKED >> (4u * i)) & 0xFu;
}

fn rank_of(v: u32, a: u32, b: u32, c: u32, d: u32) -> u32 {
    return select(0u, 1u, a < v) + select(0u, 1u, b < v) + select(0u, 1u, c < v)
        + select(0u, 1u, d < v);
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

// walk::resolve_face for a non-tet link: sets s_next (crossing) or s_done.
fn resolve(link: u32) {
    if ((link & 0x80000000u) == 0u) {
        s_out = finish(ST_MISS, s_visited);
        s_done = true;
        return;
    }
    let c = link & 0x7FFFFFFFu;
    let wt = face_hit(s_ids[0], s_ids[1], s_ids[2]);
    let w = wt.xyz;
    let t = wt.w;
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
    // Constant indices only (like the CPU's branch-free replacement), so the
    // state can live in registers instead of indexed local memory.
    let e0 = slot == 0u;
    let e1 = slot == 1u;
    let e2 = slot == 2u;
    let exiting = select(select(s_ids[2], s_ids[1], e1), s_ids[0], e0);
    let raw = layout_exit(next, d, exiting);
    s_ids[0] = select(s_ids[0], d, e0);
    s_ids[1] = select(s_ids[1], d, e1);
    s_ids[2] = select(s_ids[2], d, e2);
    s_p[0] = select(s_p[0], pd, e0);
    s_p[1] = select(s_p[1], pd, e1);
    s_p[2] = select(s_p[2], pd, e2);
    s_tet = next;
    s_link = raw;
    s_visited += 1u;
    follow();
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

fn trace_ray(idx: u32) -> HitRec {
    s_done = false;
    load_ray(idx);
    if (params.camera_mode != 0u) {
        if (!start_in_tet()) {
            return finish(ST_LOST, 0u);
        }
        follow();
    } else {
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
