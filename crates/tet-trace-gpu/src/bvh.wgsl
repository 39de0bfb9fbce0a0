// Closest-hit traversal of a binary BVH (built on the CPU by obvhs, see
// `bvh.rs`), one invocation per ray: a stack of postponed subtrees, both
// children of a node tested together, the nearer visited first and the
// farther pushed with its entry distance, popped entries skipped once the
// closest hit so far is nearer (Aila & Laine 2009, the "while-while"
// traversal without its leaf postponing). Triangles: Möller & Trumbore
// (1997) in f32. Follows `camera.wgsl` (the camera rays of the tet walks);
// the host prepends `STACK_SIZE`, the deepest path's count of inner nodes.
//
// Positions are in the BVH's frame: the scene times `params.scale`, a power
// of two that brings very large or very small scenes near 1 (exact, so a
// ray's origin and its t range are scaled the same way and its direction
// kept; t is scaled back at the end).

struct BvhParams {
    ray_count: u32,
    first_ray: u32,
    camera_mode: u32,
    width: u32,
    height: u32,
    scale: f32,
    inv_scale: f32,
    pad: u32,
    camera: Camera,
};

// Inner node: `count` 0, children at `index` and `index + 1`. Leaf: `count`
// triangles from `index` in `tris`.
struct Node {
    lo: vec3<f32>,
    index: u32,
    hi: vec3<f32>,
    count: u32,
};

// Leaf triangle (leaf order): a vertex, the two edges from it, the scene
// triangle id reported and the constrained face it came from.
struct Tri {
    v0: vec3<f32>,
    triangle: u32,
    e1: vec3<f32>,
    face: u32,
    e2: vec3<f32>,
    pad: u32,
};

struct BatchRay {
    o: vec4<f32>,  // origin, t_min
    d: vec4<f32>,  // direction, t_max
};

struct BvhResult {
    hit: u32,
    triangle: u32,
    t: f32,
    nodes: u32,  // boxes tested, the root's included
};

@group(0) @binding(0) var<storage, read> nodes: array<Node>;
@group(0) @binding(1) var<storage, read> tris: array<Tri>;
@group(0) @binding(2) var<uniform> params: BvhParams;
@group(0) @binding(3) var<storage, read> rays: array<BatchRay>;
@group(0) @binding(4) var<storage, read_write> results: array<BvhResult>;

const NONE: u32 = 0xFFFFFFFFu;
// 1 + 2γ₃ rounded up: the far distance of a slab test, three roundings
// ((lo - o), 1/d, the product), scaled by it can no longer fall below the
// exact one (Ize 2013, "Robust BVH ray traversal"); the host pads the boxes
// for the rounding of obvhs's clipped (split) boxes.
const ROBUST: f32 = 1.0000004;

// 1/d per axis, components below the smallest normal f32 (2^-126, zero
// included) taken as ±2^-126: a finite inverse, so no 0 × ∞ in the slab
// test, at any scale of the direction.
fn safe_inverse(d: vec3<f32>) -> vec3<f32> {
    let big = select(vec3<f32>(8.507059e37), vec3<f32>(-8.507059e37), d < vec3<f32>(0.0));
    return select(1.0 / d, big, abs(d) < vec3<f32>(1.1754944e-38));
}

// The ray's interval inside node `n`'s box, clipped to [t0, t1]: a hit
// when x <= y.
fn slab(n: Node, o: vec3<f32>, inv: vec3<f32>, t0: f32, t1: f32) -> vec2<f32> {
    let a = (n.lo - o) * inv;
    let b = (n.hi - o) * inv;
    let near = min(a, b);
    let far = max(a, b);
    let enter = max(max(near.x, near.y), max(near.z, t0));
    let leave = min(min(far.x, far.y), far.z) * ROBUST;
    return vec2<f32>(enter, min(leave, t1));
}

fn trace(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32) -> BvhResult {
    var r: BvhResult;
    r.hit = 0u;
    r.triangle = NONE;
    r.t = 0.0;
    r.nodes = 0u;
    // Invalid rays come with an empty interval.
    if (!(t0 <= t1)) {
        return r;
    }
    let inv = safe_inverse(d);
    var best = t1;
    var found = NONE;
    var stack_node: array<u32, STACK_SIZE>;
    var stack_t: array<f32, STACK_SIZE>;
    var sp = 0u;
    var node = nodes[0];
    r.nodes = 1u;
    let root = slab(node, o, inv, t0, best);
    if (root.x > root.y) {
        return r;
    }
    loop {
        var pop = false;
        if (node.count != 0u) {
            // Leaf: Möller-Trumbore on each triangle, keeping the nearest
            // t in [t0, best].
            for (var k = node.index; k < node.index + node.count; k++) {
                let tri = tris[k];
                let p = cross(d, tri.e2);
                let det = dot(tri.e1, p);
                let inv_det = 1.0 / det;
                let s = o - tri.v0;
                let u = dot(s, p) * inv_det;
                let q = cross(s, tri.e1);
                let v = dot(d, q) * inv_det;
                let t = dot(tri.e2, q) * inv_det;
                if (det != 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= t0 && t <= best) {
                    best = t;
                    found = k;
                }
            }
            pop = true;
        } else {
            let ia = node.index;
            let a = nodes[ia];
            let b = nodes[ia + 1u];
            r.nodes += 2u;
            let ha = slab(a, o, inv, t0, best);
            let hb = slab(b, o, inv, t0, best);
            let hit_a = ha.x <= ha.y;
            let hit_b = hb.x <= hb.y;
            if (hit_a && hit_b) {
                // Both: the nearer now, the farther later.
                if (ha.x <= hb.x) {
                    stack_node[sp] = ia + 1u;
                    stack_t[sp] = hb.x;
                    node = a;
                } else {
                    stack_node[sp] = ia;
                    stack_t[sp] = ha.x;
                    node = b;
                }
                sp += 1u;
            } else if (hit_a) {
                node = a;
            } else if (hit_b) {
                node = b;
            } else {
                pop = true;
            }
        }
        if (pop) {
            // The last postponed subtree the closest hit has not passed.
            var next = NONE;
            loop {
                if (sp == 0u) {
                    break;
                }
                sp -= 1u;
                if (stack_t[sp] <= best) {
                    next = stack_node[sp];
                    break;
                }
            }
            if (next == NONE) {
                break;
            }
            node = nodes[next];
        }
    }
    if (found != NONE) {
        r.hit = 1u;
        r.triangle = tris[found].triangle;
        r.t = best * params.inv_scale;
    }
    return r;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>,
        @builtin(num_workgroups) nwg: vec3<u32>) {
    let idx = gid.x + gid.y * nwg.x * 64u;
    if (idx >= params.ray_count) {
        return;
    }
    var o: vec3<f32>;
    var d: vec3<f32>;
    var t0 = 0.0;
    var t1 = 3.4028235e38;
    if (params.camera_mode != 0u) {
        // The tet walks' camera ray (`load_ray` in `common.wgsl`).
        d = camera_direction(params.camera, params.first_ray + idx, params.width, params.height);
        o = params.camera.eye.xyz;
    } else {
        let ray = rays[idx];
        o = ray.o.xyz;
        t0 = ray.o.w;
        d = ray.d.xyz;
        t1 = ray.d.w;
    }
    let s = params.scale;
    results[idx] = trace(o * s, d, t0 * s, t1 * s);
}
