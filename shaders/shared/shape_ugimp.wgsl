// Uniform GIMP: the tent averaged over a particle square of half-width
// lp = h/(2 ppc); tensor product of the 1D weight, 3 x 3 nodes. On a
// perturbed grid, in the lattice coordinates of the Q4 map (see
// src/model/shape/ugimp.rs, the CPU twin, for why that loses linear
// reproduction).

const STENCIL: u32 = 9u;
const SHAPE_WIDTH: u32 = 3u;

struct ShapeCtx {
    base: vec2<i32>,
    wx: vec3<f32>,
    dwx: vec3<f32>,
    wy: vec3<f32>,
    dwy: vec3<f32>,
    map: CellMap,
    ok: bool,
#if CONTACT
    // The first node of the particle's field (`field_base`).
    field_base: u32,
#endif
}

// 1D weight and derivative in lattice units: d = (particle − node)/h, l = lp/h.
fn gimp_1d(d: f32, l: f32) -> vec2<f32> {
    let a = abs(d);
    let sg = select(1.0, -1.0, d < 0.0);
    if a < l {
        return vec2<f32>(1.0 - (d * d + l * l) / (2.0 * l), -d / l);
    } else if a < 1.0 - l {
        return vec2<f32>(1.0 - a, -sg);
    } else if a < 1.0 + l {
        let u = 1.0 + l - a;
        return vec2<f32>(u * u / (4.0 * l), -sg * u / (2.0 * l));
    }
    return vec2<f32>(0.0, 0.0);
}

fn shape_ctx(p: u32, x: vec2<f32>) -> ShapeCtx {
    var c: ShapeCtx;
    let l = params.ugimp_lp;
    c.ok = inside_grid(x, l * params.h);
#if PERTURBED
    let cp = locate(x);
    let q = vec2<f32>(f32(cp.i), f32(cp.j)) + cp.st;
    c.map = cp.map;
    let hi = vec2<f32>(f32(params.nx - 1u), f32(params.ny - 1u)) - vec2<f32>(l);
    c.ok = c.ok && cp.ok && all(q >= vec2<f32>(l)) && all(q <= hi);
#else
    let q = x * params.inv_h;
    c.map = CellMap(vec2<f32>(params.h, 0.0), vec2<f32>(0.0, params.h), params.inv_h * params.inv_h);
#endif
    c.base = vec2<i32>(floor(q + vec2<f32>(0.5))) - vec2<i32>(1);
    for (var k = 0; k < 3; k++) {
        let a = gimp_1d(q.x - f32(c.base.x + k), l);
        let b = gimp_1d(q.y - f32(c.base.y + k), l);
        c.wx[k] = a.x;
        c.dwx[k] = a.y;
        c.wy[k] = b.x;
        c.dwy[k] = b.y;
    }
#if CONTACT
    c.field_base = field_base(p);
#endif
    return c;
}

fn shape_valid(c: ShapeCtx) -> bool {
    return c.ok;
}

fn shape_node(c: ShapeCtx, k: u32) -> NodeW {
    let kx = k % 3u;
    let ky = k / 3u;
    let i = c.base.x + i32(kx);
    let j = c.base.y + i32(ky);
    var w: NodeW;
    w.ok = c.ok && i >= 0 && j >= 0 && i < i32(params.nx) && j < i32(params.ny);
    w.node = u32(max(j, 0)) * params.nx + u32(max(i, 0));
    w.n = c.wx[kx] * c.wy[ky];
    w.dn = to_physical(c.map, vec2<f32>(c.dwx[kx] * c.wy[ky], c.wx[kx] * c.dwy[ky]));
#if CONTACT
    w.node += c.field_base;
#endif
    return w;
}

// Lowest node of the stencil (may lie outside the grid, by one).
fn shape_anchor(c: ShapeCtx) -> vec2<i32> {
    return c.base;
}

fn shape_slot(a: vec2<u32>) -> u32 {
    return a.y * 3u + a.x;
}

// One row: every slot (shape_lme.wgsl narrows its rows to the support).
const SHAPE_ROWS: u32 = 1u;

fn shape_span(c: ShapeCtx, r: u32) -> vec2<u32> {
    return vec2<u32>(0u, STENCIL);
}
