// Tensor-product B-splines of degree BSPLINE_P (2 or 3) by Cox-de Boor, with
// open knot vectors at the grid's edge, one basis function per node:
// t_k = 0 for k ≤ p, n − 1 for k ≥ n, k − (p + 1)/2 between (lattice units).
// CPU twin: src/shape/bspline.rs.

const BSPLINE_P: i32 = {{BSPLINE_DEGREE}};
const STENCIL: u32 = u32((BSPLINE_P + 1) * (BSPLINE_P + 1));
const SHAPE_WIDTH: u32 = u32(BSPLINE_P + 1);

fn bs_knot(k: i32, n: u32) -> f32 {
    if k <= BSPLINE_P {
        return 0.0;
    }
    if k >= i32(n) {
        return f32(n - 1u);
    }
    return f32(k) - 0.5 * f32(BSPLINE_P + 1);
}

// The p + 1 nonzero basis functions at u and their derivatives d/du.
struct Basis1 {
    first: u32,
    n: vec4<f32>,
    dn: vec4<f32>,
}

// Away from the edge (every knot t_{s−p}..t_{s+p+1} uniform) the closed
// form of the cardinal B-splines; near it the open-knot recursion.
fn bs_basis(u: f32, n: u32) -> Basis1 {
    let s = clamp(i32(floor(u + 0.5 * f32(BSPLINE_P + 1))), BSPLINE_P, i32(n) - 1);
    if s > 2 * BSPLINE_P && s + BSPLINE_P + 2 <= i32(n) {
        return bs_uniform_basis(u, s);
    }
    return bs_open_basis(u, s, n);
}

// Uniform knots: quadratic with f = u − first in [0.5, 1.5), cubic with
// t = u − (first + 1) in [0, 1).
fn bs_uniform_basis(u: f32, s: i32) -> Basis1 {
    let first = s - BSPLINE_P;
    if BSPLINE_P == 2 {
        let f = u - f32(first);
        let a = 1.5 - f;
        let b = f - 1.0;
        let c = f - 0.5;
        return Basis1(u32(first), vec4<f32>(0.5 * a * a, 0.75 - b * b, 0.5 * c * c, 0.0), vec4<f32>(-a, -2.0 * b, c, 0.0));
    }
    let t = u - f32(first + 1);
    let t2 = t * t;
    let t3 = t2 * t;
    let r = 1.0 - t;
    return Basis1(
        u32(first),
        vec4<f32>(r * r * r / 6.0, 0.5 * t3 - t2 + 2.0 / 3.0, -0.5 * t3 + 0.5 * t2 + 0.5 * t + 1.0 / 6.0, t3 / 6.0),
        vec4<f32>(-0.5 * r * r, 1.5 * t2 - 2.0 * t, -1.5 * t2 + t + 0.5, 0.5 * t2),
    );
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
}

fn shape_ctx(p: u32, x: vec2<f32>) -> ShapeCtx {
    let q = x * params.inv_h;
    return ShapeCtx(bs_basis(q.x, params.nx), bs_basis(q.y, params.ny), inside_grid(x, 0.0));
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
    return w;
}

// Lowest node of the stencil.
fn shape_anchor(c: ShapeCtx) -> vec2<i32> {
    return vec2<i32>(i32(c.bx.first), i32(c.by.first));
}

fn shape_slot(a: vec2<u32>) -> u32 {
    return a.y * SHAPE_WIDTH + a.x;
}

