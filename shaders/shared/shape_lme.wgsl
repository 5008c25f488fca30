// Local max-ent weights. Default: from a particle's solved state (λ, log Z,
// J⁻¹), which `lme_newton` writes each step: N_a = exp(−β|d|² + λ·d − log Z),
// ∇N_a = −N_a J⁻¹ d, d = x − x_a, over nodes within the support radius, one
// pass over the search box per use (24 bytes per particle). LME_STORED:
// `lme_newton` stores N and ∇N per search-box slot (16 bytes per slot) and
// the passes read them. docs/performance.md compares the two.
// CPU twin: src/model/shape/lme.rs.

const SHAPE_WIDTH: u32 = {{LME_SIDE}}u;
const STENCIL: u32 = SHAPE_WIDTH * SHAPE_WIDTH;
const LME_EMPTY: u32 = 0xffffffffu;

// First node of the search box around x.
fn lme_box(x: vec2<f32>) -> vec2<u32> {
    let q = x * params.inv_h;
    return vec2<u32>(max(ceil(q - vec2<f32>(params.lme_reach)), vec2<f32>(0.0)));
}

// The k-th node of the search box and its offset d = x − x_a, if inside the support.
struct LmeNode {
    node: u32,
    d: vec2<f32>,
    ok: bool,
}

fn lme_node(x: vec2<f32>, i0: u32, j0: u32, k: u32) -> LmeNode {
    var r: LmeNode;
    // The side as a constant (= params.lme_side): no integer division.
    let i = i0 + k % SHAPE_WIDTH;
    let j = j0 + k / SHAPE_WIDTH;
    r.ok = i < params.nx && j < params.ny;
    if r.ok {
        r.d = x - node_xy(i, j);
        r.ok = dot(r.d, r.d) <= params.lme_r2;
        r.node = j * params.nx + i;
    }
    return r;
}

// The slots [x, y) of row r of the box from (i0, j0) around x whose node
// may lie in the support (`lme_node` still checks |d|² ≤ r²): ~14 of the
// 25 at γ = 3. Loops over these spans visit only them, which a masked
// branch would not save on a SIMD CPU adapter. On a perturbed grid, the
// whole row.
fn lme_span(x: vec2<f32>, i0: u32, j0: u32, r: u32) -> vec2<u32> {
    let row = r * SHAPE_WIDTH;
#if PERTURBED
    return vec2<u32>(row, row + SHAPE_WIDTH);
#else
    // Widened by 1e-4 h against rounding: a node just outside is rejected
    // by `lme_node` anyway.
    let dy = x.y - f32(j0 + r) * params.h;
    let h2 = params.lme_r2 - dy * dy;
    let half = sqrt(max(h2, 0.0)) * params.inv_h + 1e-4;
    let q = x.x * params.inv_h - f32(i0);
    let lo = u32(clamp(ceil(q - half), 0.0, f32(SHAPE_WIDTH)));
    let hi = u32(clamp(floor(q + half) + 1.0, 0.0, f32(SHAPE_WIDTH)));
    let empty = h2 < -1e-4 * params.h * params.h;
    return select(vec2<u32>(row + lo, row + max(lo, hi)), vec2<u32>(row), empty);
#endif
}

#if LME_STORED
struct ShapeCtx {
    base: u32,
    // First node of the search box (gather passes).
    i0: u32,
    j0: u32,
    ok: bool,
#if CONTACT
    // The first node of the particle's field (`field_base`).
    field_base: u32,
#endif
}

fn shape_ctx(p: u32, x: vec2<f32>) -> ShapeCtx {
    let b = lme_box(x);
#if CONTACT
    return ShapeCtx(p * STENCIL, b.x, b.y, inside_grid(x, 0.0), field_base(p));
#else
    return ShapeCtx(p * STENCIL, b.x, b.y, inside_grid(x, 0.0));
#endif
}

fn shape_valid(c: ShapeCtx) -> bool {
    return c.ok;
}

fn shape_node(c: ShapeCtx, k: u32) -> NodeW {
    let s = c.base + k;
    var w: NodeW;
    w.node = lme_nodes[s];
    w.ok = c.ok && w.node != LME_EMPTY;
    w.n = lme_w[3u * s];
    w.dn = vec2<f32>(lme_w[3u * s + 1u], lme_w[3u * s + 2u]);
#if CONTACT
    w.node += c.field_base;
#endif
    return w;
}
#else
struct ShapeCtx {
    x: vec2<f32>,
    i0: u32,
    j0: u32,
    lam: vec2<f32>,
    // log Z, then J⁻¹ as [00, 01, 11].
    cache: vec4<f32>,
    ok: bool,
#if CONTACT
    // The first node of the particle's field (`field_base`).
    field_base: u32,
#endif
}

fn shape_ctx(p: u32, x: vec2<f32>) -> ShapeCtx {
    var c: ShapeCtx;
    c.x = x;
    let b = lme_box(x);
    c.i0 = b.x;
    c.j0 = b.y;
    c.lam = lambda[p];
    c.cache = lme_cache[p];
    c.ok = inside_grid(x, 0.0);
#if CONTACT
    c.field_base = field_base(p);
#endif
    return c;
}

fn shape_valid(c: ShapeCtx) -> bool {
    return c.ok;
}

fn shape_node(c: ShapeCtx, k: u32) -> NodeW {
    let a = lme_node(c.x, c.i0, c.j0, k);
    var w: NodeW;
    w.ok = a.ok && c.ok;
    w.node = a.node;
    let f = -params.lme_beta * dot(a.d, a.d) + dot(c.lam, a.d);
    w.n = exp(f - c.cache.x);
    let jd = vec2<f32>(c.cache.y * a.d.x + c.cache.z * a.d.y, c.cache.z * a.d.x + c.cache.w * a.d.y);
    w.dn = -w.n * jd;
#if CONTACT
    w.node += c.field_base;
#endif
    return w;
}
#endif

// Rows of the search box and their slots that may lie in the support
// (`lme_span`; with stored weights, the whole row).
const SHAPE_ROWS: u32 = SHAPE_WIDTH;

fn shape_span(c: ShapeCtx, r: u32) -> vec2<u32> {
#if LME_STORED
    let row = r * SHAPE_WIDTH;
    return vec2<u32>(row, row + SHAPE_WIDTH);
#else
    return lme_span(c.x, c.i0, c.j0, r);
#endif
}

// Lowest node of the search box.
fn shape_anchor(c: ShapeCtx) -> vec2<i32> {
    return vec2<i32>(i32(c.i0), i32(c.j0));
}

fn shape_slot(a: vec2<u32>) -> u32 {
    return a.y * SHAPE_WIDTH + a.x;
}
