// MLS helpers shared by the mls_* passes (CPU twin: src/cpu/mls.rs).
// Integration cells ("spans") are the B-spline's knot spans, the grid's
// cells for linear shapes; each has 2 x 2 Gauss points, numbered
// g = 4 (sy * spans_x + sx) + k with k = (−,−), (+,−), (−,+), (+,+).

const MLS_SUPPORT: f32 = 3.0;
// A moment matrix with det A < this × A00³ is singular. Looser than the
// CPU's 1e-10: f32 round-off in det reaches ~1e-7 A00³.
const MLS_SINGULAR_REL: f32 = 1e-6;

// Quadratic-spline weight (B-spline paper eq. 17) of r ≥ 0.
fn mls_weight(r: f32) -> f32 {
    if r <= 0.5 {
        return 0.75 - r * r;
    }
    if r < 1.5 {
        return 0.5 * (1.5 - r) * (1.5 - r);
    }
    return 0.0;
}

// Break k of `spans` integration cells along an axis of n nodes (lattice
// units): the distinct knots (`model::gauss::breaks`). The cells layout's
// are e, e + 1, …, n − 1 − e, with e = mls_break_off.
fn mls_break(k: u32, spans: u32, n: u32) -> f32 {
#if BSPLINE_CELLS
    return f32(k) + params.mls_break_off;
#endif
    if k == 0u {
        return 0.0;
    }
    if k >= spans {
        return f32(n - 1u);
    }
    return f32(k) + params.mls_break_off;
}

// Integration cell holding lattice coordinate u along an axis.
fn mls_span_of(u: f32, spans: u32) -> u32 {
    return u32(clamp(floor(u - params.mls_break_off), 0.0, f32(spans - 1u)));
}

fn mls_n_gauss() -> u32 {
    return 4u * params.mls_spans_x * params.mls_spans_y;
}

struct GaussPoint {
    // Position (m, grid-relative) and weight ω (m²).
    x: vec2<f32>,
    w: f32,
    span: u32,
}

fn mls_gauss_point(g: u32) -> GaussPoint {
    let span = g / 4u;
    let k = g % 4u;
    let sx = span % params.mls_spans_x;
    let sy = span / params.mls_spans_x;
    let x0 = mls_break(sx, params.mls_spans_x, params.nx);
    let x1 = mls_break(sx + 1u, params.mls_spans_x, params.nx);
    let y0 = mls_break(sy, params.mls_spans_y, params.ny);
    let y1 = mls_break(sy + 1u, params.mls_spans_y, params.ny);
    let a = select(-1.0, 1.0, (k & 1u) == 1u);
    let b = select(-1.0, 1.0, k >= 2u);
    let g3 = 0.28867513459481287; // 1 / (2 √3)
    let u = 0.5 * (x0 + x1) + a * g3 * (x1 - x0);
    let v = 0.5 * (y0 + y1) + b * g3 * (y1 - y0);
    return GaussPoint(vec2<f32>(u, v) * params.h, 0.25 * (x1 - x0) * (y1 - y0) * params.h * params.h, span);
}

// Grid cells whose particles can lie within the support of a Gauss point at
// lattice point q: [lo.x, hi.x] x [lo.y, hi.y].
struct CellRange {
    lo: vec2<u32>,
    hi: vec2<u32>,
}

fn mls_cells_around(q: vec2<f32>) -> CellRange {
    let top = vec2<f32>(f32(params.nx - 2u), f32(params.ny - 2u));
    let lo = clamp(floor(q - MLS_SUPPORT), vec2<f32>(0.0), top);
    let hi = clamp(floor(q + MLS_SUPPORT), vec2<f32>(0.0), top);
    return CellRange(vec2<u32>(lo), vec2<u32>(hi));
}

// Offset of particle p from a Gauss point at lattice point qg, in units of h,
// and its weight: (Δx, Δy, w(|Δx|/2) w(|Δy|/2)). Needs the x0 and u bindings.
fn mls_sample(p: u32, qg: vec2<f32>) -> vec3<f32> {
    return mls_sample_at(x0[p] + u[p], qg);
}

// `mls_sample` of a particle at position xp (m, grid-relative).
fn mls_sample_at(xp: vec2<f32>, qg: vec2<f32>) -> vec3<f32> {
    let d = xp * params.inv_h - qg;
    let s = params.mls_weight_scale;
    return vec3<f32>(d, mls_weight(s * abs(d.x)) * mls_weight(s * abs(d.y)));
}
