// Bilinear Q4 (isoparametric on perturbed grids).
// CPU twin: src/model/shape/linear.rs.

const STENCIL: u32 = 4u;
const SHAPE_WIDTH: u32 = 2u;

struct ShapeCtx {
    cp: CellPoint,
#if CONTACT
    // The first node of the particle's field (`field_base`).
    field_base: u32,
#endif
}

fn shape_ctx(p: u32, x: vec2<f32>) -> ShapeCtx {
#if CONTACT
    return ShapeCtx(locate(x), field_base(p));
#else
    return ShapeCtx(locate(x));
#endif
}

fn shape_valid(c: ShapeCtx) -> bool {
    return c.cp.ok;
}

fn shape_node(c: ShapeCtx, k: u32) -> NodeW {
    // Corners counter-clockwise from (0, 0), as on the CPU.
    let di = select(0u, 1u, k == 1u || k == 2u);
    let dj = select(0u, 1u, k >= 2u);
    let s = c.cp.st.x;
    let t = c.cp.st.y;
    let ns = select(1.0 - s, s, di == 1u);
    let nt = select(1.0 - t, t, dj == 1u);
    let ds = select(-1.0, 1.0, di == 1u);
    let dt = select(-1.0, 1.0, dj == 1u);
    var w: NodeW;
    w.node = (c.cp.j + dj) * params.nx + c.cp.i + di;
    w.n = ns * nt;
    w.dn = to_physical(c.cp.map, vec2<f32>(ds * nt, ns * dt));
    w.ok = c.cp.ok;
#if CONTACT
    w.node += c.field_base;
#endif
    return w;
}

// Lowest node of the stencil: the cell's (0, 0) corner.
fn shape_anchor(c: ShapeCtx) -> vec2<i32> {
    return vec2<i32>(i32(c.cp.i), i32(c.cp.j));
}

// Slot of the node at offset a from the anchor (corners counter-clockwise).
fn shape_slot(a: vec2<u32>) -> u32 {
    return select(a.x, 3u - a.x, a.y == 1u);
}

// One row: every slot (shape_lme.wgsl narrows its rows to the support).
const SHAPE_ROWS: u32 = 1u;

fn shape_span(c: ShapeCtx, r: u32) -> vec2<u32> {
    return vec2<u32>(0u, STENCIL);
}
