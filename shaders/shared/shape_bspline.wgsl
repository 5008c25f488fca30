// Tensor-product B-splines of degree BSPLINE_P (2 or 3) by Cox-de Boor, with
// open knot vectors at the grid's edge, one basis function per node:
// t_k = e for k ≤ p, n − 1 − e for k ≥ n, k − (p + 1)/2 between (lattice
// units), e = BSPLINE_END: 0, or (p − 1)/2 for the `cells` layout (knots on
// the scene's grid lines, on a node lattice shifted out by e).
// CPU twin: src/model/shape/bspline.rs.

const BSPLINE_P: i32 = {{BSPLINE_DEGREE}};
#if BSPLINE_CELLS
const BSPLINE_END: f32 = 0.5 * f32(BSPLINE_P - 1);
#else
const BSPLINE_END: f32 = 0.0;
#endif
const STENCIL: u32 = u32((BSPLINE_P + 1) * (BSPLINE_P + 1));
const SHAPE_WIDTH: u32 = u32(BSPLINE_P + 1);

fn bs_knot(k: i32, n: u32) -> f32 {
    if k <= BSPLINE_P {
        return BSPLINE_END;
    }
    if k >= i32(n) {
        return f32(n - 1u) - BSPLINE_END;
    }
    return f32(k) - 0.5 * f32(BSPLINE_P + 1);
}

// The p + 1 nonzero basis functions at u and their derivatives d/du.
struct Basis1 {
    first: u32,
    n: vec4<f32>,
    dn: vec4<f32>,
}

// One code path for every lane (no branch on the particle's position: on
// a SIMD software adapter like llvmpipe both sides of a divergent branch
// run, so the recursion would run beside the closed form for every
// particle): each span's p + 1 bases are fixed polynomials in
// c = u − s + p/2, one row of coefficients per left-edge span s = p..2p − 1
// and one for the interior, picked with selects; the right edge is the left
// one mirrored (N_i(u) = N_{n−1−i}(n − 1 − u)). On grids too small for the
// edges to stay apart (BSPLINE_SMALL_GRID: fewer than 3p + 1 nodes in a
// direction) the open-knot recursion runs. CPU twin: `table_basis`.
fn bs_basis(u: f32, n: u32) -> Basis1 {
    let s = clamp(i32(floor(u + 0.5 * f32(BSPLINE_P + 1))), BSPLINE_P, i32(n) - 1);
#if BSPLINE_SMALL_GRID
    return bs_open_basis(u, s, n);
#else
    let right = s + BSPLINE_P >= i32(n);
    let sm = select(s, i32(n) + BSPLINE_P - 1 - s, right);
    let c = select(u, f32(n - 1u) - u, right) - f32(sm) + 0.5 * f32(BSPLINE_P);
    let row = sm - BSPLINE_P;
    var nb: vec4<f32>;
    var dn: vec4<f32>;
    if BSPLINE_P == 2 {
#if BSPLINE_CELLS
        // The cells layout: only the first span differs from the interior.
        let k0 = bs_pick2(row, vec4<f32>(1.0 / 4.0, 5.0 / 8.0, 1.0 / 8.0, 0.0), vec4<f32>(1.0 / 8.0, 3.0 / 4.0, 1.0 / 8.0, 0.0), vec4<f32>(1.0 / 8.0, 3.0 / 4.0, 1.0 / 8.0, 0.0));
        let k1 = bs_pick2(row, vec4<f32>(-1.0, 1.0 / 2.0, 1.0 / 2.0, 0.0), vec4<f32>(-1.0 / 2.0, 0.0, 1.0 / 2.0, 0.0), vec4<f32>(-1.0 / 2.0, 0.0, 1.0 / 2.0, 0.0));
        let k2 = bs_pick2(row, vec4<f32>(1.0, -3.0 / 2.0, 1.0 / 2.0, 0.0), vec4<f32>(1.0 / 2.0, -1.0, 1.0 / 2.0, 0.0), vec4<f32>(1.0 / 2.0, -1.0, 1.0 / 2.0, 0.0));
#else
        let k0 = bs_pick2(row, vec4<f32>(1.0 / 9.0, 28.0 / 45.0, 4.0 / 15.0, 0.0), vec4<f32>(1.0 / 10.0, 31.0 / 40.0, 1.0 / 8.0, 0.0), vec4<f32>(1.0 / 8.0, 3.0 / 4.0, 1.0 / 8.0, 0.0));
        let k1 = bs_pick2(row, vec4<f32>(-4.0 / 9.0, -4.0 / 45.0, 8.0 / 15.0, 0.0), vec4<f32>(-2.0 / 5.0, -1.0 / 10.0, 1.0 / 2.0, 0.0), vec4<f32>(-1.0 / 2.0, 0.0, 1.0 / 2.0, 0.0));
        let k2 = bs_pick2(row, vec4<f32>(4.0 / 9.0, -32.0 / 45.0, 4.0 / 15.0, 0.0), vec4<f32>(2.0 / 5.0, -9.0 / 10.0, 1.0 / 2.0, 0.0), vec4<f32>(1.0 / 2.0, -1.0, 1.0 / 2.0, 0.0));
#endif
        nb = k0 + c * (k1 + c * k2);
        dn = k1 + 2.0 * c * k2;
        nb = select(nb, nb.zyxw, right);
        dn = select(dn, -dn.zyxw, right);
    } else {
#if BSPLINE_CELLS
        // The cells layout: the first two spans differ from the interior.
        let k0 = bs_pick3(row, vec4<f32>(1.0 / 8.0, 19.0 / 32.0, 25.0 / 96.0, 1.0 / 48.0), vec4<f32>(1.0 / 32.0, 15.0 / 32.0, 23.0 / 48.0, 1.0 / 48.0), vec4<f32>(1.0 / 48.0, 23.0 / 48.0, 23.0 / 48.0, 1.0 / 48.0), vec4<f32>(1.0 / 48.0, 23.0 / 48.0, 23.0 / 48.0, 1.0 / 48.0));
        let k1 = bs_pick3(row, vec4<f32>(-3.0 / 4.0, -3.0 / 16.0, 13.0 / 16.0, 1.0 / 8.0), vec4<f32>(-3.0 / 16.0, -9.0 / 16.0, 5.0 / 8.0, 1.0 / 8.0), vec4<f32>(-1.0 / 8.0, -5.0 / 8.0, 5.0 / 8.0, 1.0 / 8.0), vec4<f32>(-1.0 / 8.0, -5.0 / 8.0, 5.0 / 8.0, 1.0 / 8.0));
        let k2 = bs_pick3(row, vec4<f32>(3.0 / 2.0, -15.0 / 8.0, 1.0 / 8.0, 1.0 / 4.0), vec4<f32>(3.0 / 8.0, -3.0 / 8.0, -1.0 / 4.0, 1.0 / 4.0), vec4<f32>(1.0 / 4.0, -1.0 / 4.0, -1.0 / 4.0, 1.0 / 4.0), vec4<f32>(1.0 / 4.0, -1.0 / 4.0, -1.0 / 4.0, 1.0 / 4.0));
        let k3 = bs_pick3(row, vec4<f32>(-1.0, 7.0 / 4.0, -11.0 / 12.0, 1.0 / 6.0), vec4<f32>(-1.0 / 4.0, 7.0 / 12.0, -1.0 / 2.0, 1.0 / 6.0), vec4<f32>(-1.0 / 6.0, 1.0 / 2.0, -1.0 / 2.0, 1.0 / 6.0), vec4<f32>(-1.0 / 6.0, 1.0 / 2.0, -1.0 / 2.0, 1.0 / 6.0));
#else
        let k0 = bs_pick3(row, vec4<f32>(1.0 / 64.0, 21.0 / 64.0, 33.0 / 64.0, 9.0 / 64.0), vec4<f32>(1.0 / 72.0, 211.0 / 576.0, 115.0 / 192.0, 1.0 / 48.0), vec4<f32>(1.0 / 64.0, 31.0 / 64.0, 23.0 / 48.0, 1.0 / 48.0), vec4<f32>(1.0 / 48.0, 23.0 / 48.0, 23.0 / 48.0, 1.0 / 48.0));
        let k1 = bs_pick3(row, vec4<f32>(-3.0 / 32.0, -15.0 / 32.0, 9.0 / 32.0, 9.0 / 32.0), vec4<f32>(-1.0 / 12.0, -49.0 / 96.0, 15.0 / 32.0, 1.0 / 8.0), vec4<f32>(-3.0 / 32.0, -21.0 / 32.0, 5.0 / 8.0, 1.0 / 8.0), vec4<f32>(-1.0 / 8.0, -5.0 / 8.0, 5.0 / 8.0, 1.0 / 8.0));
        let k2 = bs_pick3(row, vec4<f32>(3.0 / 16.0, -1.0 / 16.0, -5.0 / 16.0, 3.0 / 16.0), vec4<f32>(1.0 / 6.0, -5.0 / 48.0, -5.0 / 16.0, 1.0 / 4.0), vec4<f32>(3.0 / 16.0, -3.0 / 16.0, -1.0 / 4.0, 1.0 / 4.0), vec4<f32>(1.0 / 4.0, -1.0 / 4.0, -1.0 / 4.0, 1.0 / 4.0));
        let k3 = bs_pick3(row, vec4<f32>(-1.0 / 8.0, 19.0 / 72.0, -13.0 / 72.0, 1.0 / 24.0), vec4<f32>(-1.0 / 9.0, 23.0 / 72.0, -3.0 / 8.0, 1.0 / 6.0), vec4<f32>(-1.0 / 8.0, 11.0 / 24.0, -1.0 / 2.0, 1.0 / 6.0), vec4<f32>(-1.0 / 6.0, 1.0 / 2.0, -1.0 / 2.0, 1.0 / 6.0));
#endif
        nb = k0 + c * (k1 + c * (k2 + c * k3));
        dn = k1 + c * (2.0 * k2 + 3.0 * c * k3);
        nb = select(nb, nb.wzyx, right);
        dn = select(dn, -dn.wzyx, right);
    }
    return Basis1(u32(s - BSPLINE_P), nb, dn);
#endif
}

// Coefficient rows (`table_basis` in src/model/shape/bspline.rs): the
// left edge's spans, then the interior for row ≥ p.
fn bs_pick2(row: i32, e0: vec4<f32>, e1: vec4<f32>, interior: vec4<f32>) -> vec4<f32> {
    return select(select(interior, e1, row == 1), e0, row == 0);
}

fn bs_pick3(row: i32, e0: vec4<f32>, e1: vec4<f32>, e2: vec4<f32>, interior: vec4<f32>) -> vec4<f32> {
    return select(select(select(interior, e2, row == 2), e1, row == 1), e0, row == 0);
}

// The general open-knot evaluation on span s (Cox-de Boor).
fn bs_open_basis(u: f32, s: i32, n: u32) -> Basis1 {
    let p = BSPLINE_P;
    var nb = array<f32, 4>(1.0, 0.0, 0.0, 0.0);
    var lower = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    var left = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    var right = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    for (var j = 1; j <= p; j++) {
        left[j] = u - bs_knot(s + 1 - j, n);
        right[j] = bs_knot(s + j, n) - u;
        if j == p {
            lower = nb;
        }
        var saved = 0.0;
        for (var r = 0; r < j; r++) {
            let den = right[r + 1] + left[j - r];
            var temp = 0.0;
            if den != 0.0 {
                temp = nb[r] / den;
            }
            nb[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        nb[j] = saved;
    }
    let first = s - p;
    var dn = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    for (var r = 0; r <= p; r++) {
        let i = first + r;
        var a = 0.0;
        if r >= 1 {
            a = lower[r - 1];
        }
        var b = 0.0;
        if r < p {
            b = lower[r];
        }
        let da = bs_knot(i + p, n) - bs_knot(i, n);
        let db = bs_knot(i + p + 1, n) - bs_knot(i + 1, n);
        var d = 0.0;
        if da != 0.0 {
            d += a / da;
        }
        if db != 0.0 {
            d -= b / db;
        }
        dn[r] = f32(p) * d;
    }
    return Basis1(u32(first), vec4<f32>(nb[0], nb[1], nb[2], nb[3]), vec4<f32>(dn[0], dn[1], dn[2], dn[3]));
}

struct ShapeCtx {
    bx: Basis1,
    by: Basis1,
    ok: bool,
#if CONTACT
    // The first node of the particle's field (`field_base`).
    field_base: u32,
#endif
}

fn shape_ctx(p: u32, x: vec2<f32>) -> ShapeCtx {
    let q = x * params.inv_h;
#if CONTACT
    return ShapeCtx(bs_basis(q.x, params.nx), bs_basis(q.y, params.ny), inside_grid(x, params.edge_margin), field_base(p));
#else
    return ShapeCtx(bs_basis(q.x, params.nx), bs_basis(q.y, params.ny), inside_grid(x, params.edge_margin));
#endif
}

fn shape_valid(c: ShapeCtx) -> bool {
    return c.ok;
}

fn shape_node(c: ShapeCtx, k: u32) -> NodeW {
    let side = u32(BSPLINE_P + 1);
    let a = k % side;
    let b = k / side;
    var w: NodeW;
    w.ok = c.ok;
    w.node = (c.by.first + b) * params.nx + c.bx.first + a;
    w.n = c.bx.n[a] * c.by.n[b];
    w.dn = vec2<f32>(c.bx.dn[a] * c.by.n[b], c.bx.n[a] * c.by.dn[b]) * params.inv_h;
#if CONTACT
    w.node += c.field_base;
#endif
    return w;
}

// Lowest node of the stencil.
fn shape_anchor(c: ShapeCtx) -> vec2<i32> {
    return vec2<i32>(i32(c.bx.first), i32(c.by.first));
}

fn shape_slot(a: vec2<u32>) -> u32 {
    return a.y * SHAPE_WIDTH + a.x;
}


// One row: every slot (shape_lme.wgsl narrows its rows to the support).
const SHAPE_ROWS: u32 = 1u;

fn shape_span(c: ShapeCtx, r: u32) -> vec2<u32> {
    return vec2<u32>(0u, STENCIL);
}
