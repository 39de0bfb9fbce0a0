// Tet80: the Plücker walk of Maria, Horna & Aveneau (2017, §3-4) as a
// WGSL compute kernel, a port of `tet_trace_cpu::tet80::Tet80Tracer`.
// Record (20 words): four vertex positions (f32 bits, slot order of the
// mesh) then four faces (occlusion = constrained-face index or 0xFFFFFFFF,
// neighbor = tet << 2 | face or 0xFFFFFFFF). The host prepends
// `common.wgsl` and the packed tables:
//   EXIT80   2 bits per entry, index 4 e + 2 s1 + s2 (tet80::EXIT)
//   SECOND80 2 bits per entry, index 2 e + s1 (B after a left turn, C else)
//   FIRST80  2 bits per entry, index e (FACE_VERTICES[e][0])

const NONE80: u32 = 0xFFFFFFFFu;

fn vtx(t: u32, k: u32) -> vec3<f32> {
    let b = 20u * t + 3u * k;
    return vec3<f32>(bitcast<f32>(tet_word(b)), bitcast<f32>(tet_word(b + 1u)), bitcast<f32>(tet_word(b + 2u)));
}

// glam's scalar Vec3 cross and dot, in its operation order.
fn gcross(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}

fn gdot(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

fn table2(table: u32, i: u32) -> u32 {
    return (table >> (2u * i)) & 3u;
}

var<private> s_tet: u32;
var<private> s_face: u32;
var<private> s_visited: u32;
var<private> s_done: bool;
var<private> s_out: HitRec;

// Tet80Tracer::leave: cross face k of s_tet (hit, miss, or the next tet and
// its entry face).
fn leave(k: u32) {
    let b = 20u * s_tet + 12u + 2u * k;
    let occl = tet_word(b);
    let nb = tet_word(b + 1u);
    if (occl != NONE80) {
        let wt = face_hit(faces[6u * occl + 3u], faces[6u * occl + 4u], faces[6u * occl + 5u]);
        if (wt.w >= r_tmin) {
            if (wt.w > r_tmax) {
                s_out = finish(ST_MISS, s_visited);
                s_done = true;
                return;
            }
            var h: HitRec;
            h.status = ST_HIT;
            h.triangle = faces[6u * occl];
            h.face = occl;
            h.t = wt.w;
            h.b0 = wt.x;
            h.b1 = wt.y;
            h.b2 = wt.z;
            h.tet = s_tet;
            h.far_tet = select(nb >> 2u, NO_TET, nb == NONE80);
            h.visited = s_visited;
            s_out = h;
            s_done = true;
            return;
        }
    }
    if (nb == NONE80) {
        s_out = finish(ST_MISS, s_visited);
        s_done = true;
        return;
    }
    s_tet = nb >> 2u;
    s_face = nb & 3u;
}

// One tet of Tet80Tracer::walk: two Plücker side products in the frame of
// the entry face's complement vertex (the apex).
fn step() {
    if (s_visited >= params.step_cap) {
        s_out = finish(ST_STEP_CAP, s_visited);
        s_done = true;
        return;
    }
    s_visited += 1u;
    let e = s_face;
    let apex = vtx(s_tet, e);
    let m = gcross(r_d, apex - r_o);
    let s1 = gdot(vtx(s_tet, table2(FIRST80, e)) - apex, m) > 0.0;
    let second = table2(SECOND80, 2u * e + select(0u, 1u, s1));
    let s2 = gdot(vtx(s_tet, second) - apex, m) > 0.0;
    let exit = table2(EXIT80, 4u * e + select(0u, 2u, s1) + select(0u, 1u, s2));
    leave(exit);
}

// TripleF32::left: d.(a x b) with the CPU's tie rule (a, b relative to o).
fn left3(a: vec3<f32>, ia: u32, b: vec3<f32>, ib: u32) -> bool {
    let s = gdot(r_d, gcross(a, b));
    if (s != 0.0) {
        return s > 0.0;
    }
    let e = a - b;
    let y = gdot(e, r_v);
    if (y != 0.0) {
        return y > 0.0;
    }
    let x = gdot(e, r_u);
    if (x != 0.0) {
        return x < 0.0;
    }
    return ia < ib;
}

// walk::start_in_tet with the triple-product test, for the camera's tet.
fn start_in_tet() -> bool {
    let ids = array<u32, 4>(params.cam_ids.x, params.cam_ids.y, params.cam_ids.z, params.cam_ids.w);
    var p: array<vec3<f32>, 4>;
    for (var i = 0u; i < 4u; i++) {
        p[i] = point(ids[i]) - r_o;
    }
    for (var k = 0u; k < 4u; k++) {
        let s = face_slots(k);
        if (left3(p[s.x], ids[s.x], p[s.y], ids[s.y]) && left3(p[s.y], ids[s.y], p[s.z], ids[s.z])
            && left3(p[s.z], ids[s.z], p[s.x], ids[s.x])) {
            s_tet = params.cam_tet;
            s_visited = 1u;
            leave(k);
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
    } else {
        let st = starts[idx];
        if (st.mode == START_DONE) {
            return finish(st.link, st.visited);
        }
        s_tet = st.tet;
        s_visited = st.visited;
        if (st.mode == START_ENTER) {
            s_face = st.i0;
        } else {
            leave(st.i0);
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
