// The shape-function interface every particle stage uses:
//   let c = shape_ctx(p, x);               // per-particle setup
//   for (var k = 0u; k < STENCIL; k++) {     // or per row r < SHAPE_ROWS over shape_span(c, r)
//       let w = shape_node(c, k);          // k-th candidate node
//       if !w.ok { continue; }
//       ... w.node, w.n, w.dn ...
//   }
// and, for node-centred passes, `shape_at(c, i, j)` (below).
// Exactly one of shape_linear / shape_ugimp / shape_lme / shape_bspline is compiled in.
// Positions are relative to the grid's lower-left node (m).

struct NodeW {
    node: u32,
    n: f32,
    dn: vec2<f32>,
    ok: bool,
}

// Position of node (i, j).
fn node_xy(i: u32, j: u32) -> vec2<f32> {
#if PERTURBED
    return node_pos[j * params.nx + i];
#else
    return vec2<f32>(f32(i), f32(j)) * params.h;
#endif
}

fn inside_grid(x: vec2<f32>, margin: f32) -> bool {
    return x.x >= margin && x.y >= margin && x.x <= params.grid_w - margin && x.y <= params.grid_hgt - margin;
}

// Q4 values and (s, t)-derivatives, corners counter-clockwise from (0, 0).
fn q4_n(st: vec2<f32>) -> vec4<f32> {
    let s = st.x;
    let t = st.y;
    return vec4<f32>((1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t);
}

// Gradient map of the cell holding a point: grad_x = J^{-T} grad_(s,t),
// with J = [dx/ds | dx/dt] (columns) and its inverse determinant.
struct CellMap {
    c0: vec2<f32>,
    c1: vec2<f32>,
    inv_det: f32,
}

fn to_physical(m: CellMap, g: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(m.c1.y * g.x - m.c0.y * g.y, -m.c1.x * g.x + m.c0.x * g.y) * m.inv_det;
}

// Cell (i, j), local (s, t) and map of a point. Regular grid: closed form.
// Perturbed: Newton on the bilinear map of the lattice guess, walking to a
// neighbour cell while (s, t) falls outside [0, 1]^2 (nodes move < h/4).
struct CellPoint {
    i: u32,
    j: u32,
    st: vec2<f32>,
    map: CellMap,
    ok: bool,
}

fn locate(x: vec2<f32>) -> CellPoint {
    var cp: CellPoint;
    let q = x * params.inv_h;
    var i = i32(clamp(floor(q.x), 0.0, f32(params.nx - 2u)));
    var j = i32(clamp(floor(q.y), 0.0, f32(params.ny - 2u)));
    cp.ok = inside_grid(x, 0.0);
#if !PERTURBED
    cp.i = u32(i);
    cp.j = u32(j);
    cp.st = q - vec2<f32>(f32(i), f32(j));
    cp.map = CellMap(vec2<f32>(params.h, 0.0), vec2<f32>(0.0, params.h), params.inv_h * params.inv_h);
    return cp;
#else
    if !cp.ok {
        return cp;
    }
    cp.ok = false;
    for (var attempt = 0; attempt < 4; attempt++) {
        let ui = u32(i);
        let uj = u32(j);
        let x00 = node_xy(ui, uj);
        let x10 = node_xy(ui + 1u, uj);
        let x11 = node_xy(ui + 1u, uj + 1u);
        let x01 = node_xy(ui, uj + 1u);
        var st = q - vec2<f32>(f32(i), f32(j));
        var c0 = vec2<f32>(params.h, 0.0);
        var c1 = vec2<f32>(0.0, params.h);
        for (var it = 0; it < 8; it++) {
            let n = q4_n(st);
            let r = x00 * n.x + x10 * n.y + x11 * n.z + x01 * n.w - x;
            c0 = (x10 - x00) * (1.0 - st.y) + (x11 - x01) * st.y;
            c1 = (x01 - x00) * (1.0 - st.x) + (x11 - x10) * st.x;
            let det = c0.x * c1.y - c1.x * c0.y;
            st -= vec2<f32>(c1.y * r.x - c1.x * r.y, -c0.y * r.x + c0.x * r.y) / det;
        }
        let tol = 1e-5;
        var di = 0;
        var dj = 0;
        if st.x < -tol { di = -1; } else if st.x > 1.0 + tol { di = 1; }
        if st.y < -tol { dj = -1; } else if st.y > 1.0 + tol { dj = 1; }
        if di == 0 && dj == 0 {
            cp.i = ui;
            cp.j = uj;
            cp.st = clamp(st, vec2<f32>(0.0), vec2<f32>(1.0));
            cp.map = CellMap(c0, c1, 1.0 / (c0.x * c1.y - c1.x * c0.y));
            cp.ok = true;
            return cp;
        }
        i += di;
        j += dj;
        if i < 0 || j < 0 || i > i32(params.nx) - 2 || j > i32(params.ny) - 2 {
            return cp;
        }
    }
    return cp;
#endif
}

#if SHAPE_LINEAR
#include "shared/shape_linear.wgsl"
#elif SHAPE_UGIMP
#include "shared/shape_ugimp.wgsl"
#elif SHAPE_LME
#include "shared/shape_lme.wgsl"
#elif SHAPE_BSPLINE
#include "shared/shape_bspline.wgsl"
#endif

// For node-centred (gather) passes: node (i, j) as seen from a particle.
// Every stencil is a SHAPE_WIDTH × SHAPE_WIDTH box of nodes from
// `shape_anchor(c)` (some of them outside the support: `ok` false), and
// `shape_slot` numbers the box as `shape_node` does.
fn shape_at(c: ShapeCtx, i: u32, j: u32) -> NodeW {
    let a = vec2<i32>(i32(i), i32(j)) - shape_anchor(c);
    if any(a < vec2<i32>(0)) || any(a >= vec2<i32>(i32(SHAPE_WIDTH))) {
        var w: NodeW;
        w.ok = false;
        return w;
    }
    return shape_node(c, shape_slot(vec2<u32>(a)));
}
