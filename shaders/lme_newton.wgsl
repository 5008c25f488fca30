// Stage `lme_newton` (LME only): per particle, damped Newton on λ minimising
// log Z, warm-started from the last step's λ, then (λ, log Z, J⁻¹) stored
// for the other passes. Converged when |r| ≤ lme_tol (f32: ~30 ulp of the
// sums). CPU twin: src/model/shape/lme.rs (Lme::eval), via
// src/cpu/shape_eval.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read_write
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;

// log Z, r = ∂ log Z/∂λ, J = ∂r/∂λ ([00, 01, 11]) and the support size.
struct Objective {
    log_z: f32,
    // Sum of the shifted exponentials (objective_shifted).
    z: f32,
    r: vec2<f32>,
    j: vec3<f32>,
    count: u32,
}

// The largest exponent −β|d|² + λ·d over the support.
fn largest_exponent(x: vec2<f32>, b: vec2<u32>, lam: vec2<f32>) -> f32 {
    var fmax = -3.0e38;
    for (var k = 0u; k < STENCIL; k++) {
        let a = lme_node(x, b.x, b.y, k);
        if a.ok {
            fmax = max(fmax, -params.lme_beta * dot(a.d, a.d) + dot(lam, a.d));
        }
    }
    return fmax;
}

// One pass over the box's slots that may lie in the support (`lme_span`)
// with every exponent shifted by `shift`; `z` is the shifted sum, kept to
// tell an underflow.
fn objective_shifted(x: vec2<f32>, b: vec2<u32>, lam: vec2<f32>, shift: f32) -> Objective {
    var z = 0.0;
    var r = vec2<f32>(0.0);
    var m = vec3<f32>(0.0);
    var count = 0u;
    for (var row = 0u; row < SHAPE_WIDTH; row++) {
        let span = lme_span(x, b.x, b.y, row);
        for (var k = span.x; k < span.y; k++) {
            let a = lme_node(x, b.x, b.y, k);
            if a.ok {
                let e = exp(-params.lme_beta * dot(a.d, a.d) + dot(lam, a.d) - shift);
                z += e;
                r += e * a.d;
                m += e * vec3<f32>(a.d.x * a.d.x, a.d.x * a.d.y, a.d.y * a.d.y);
                count += 1u;
            }
        }
    }
    var o: Objective;
    o.count = count;
    o.z = z;
    o.r = r / z;
    o.j = m / z - vec3<f32>(o.r.x * o.r.x, o.r.x * o.r.y, o.r.y * o.r.y);
    o.log_z = shift + log(z);
    return o;
}

// One pass, shifted by |λ|²/(4β): the largest value −β|d|² + λ·d takes
// over all d, so no term overflows and the largest is within the box's
// reach of 1. Every term underflows only if |λ| is tens of times 1/h (a
// particle pinned to the grid's edge); then a first pass finds the largest
// exponent to shift by, as this solve always did before (two passes).
fn objective(x: vec2<f32>, b: vec2<u32>, lam: vec2<f32>) -> Objective {
    var o = objective_shifted(x, b, lam, dot(lam, lam) / (4.0 * params.lme_beta));
    if !(o.z >= 1e-30) {
        o = objective_shifted(x, b, lam, largest_exponent(x, b, lam));
    }
    return o;
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
    if !inside_grid(x, 0.0) {
        report_fault(FAULT_LEFT_GRID, p);
        return;
    }
    let b = lme_box(x);
    var lam = lambda[p];
    var cur = objective(x, b, lam);
    if cur.count < 3u {
        report_fault(FAULT_LME_FEW_NODES, p);
        return;
    }
    for (var it = 0u; it <= params.lme_max_iter; it++) {
        let jm = cur.j;
        let det = jm.x * jm.z - jm.y * jm.y;
        let tr = jm.x + jm.z;
        let rn = length(cur.r);
        // Comparisons with NaN are false, so NaN lands here too.
        if !(det > 1e-10 * tr * tr) || !is_finite(rn) {
            report_fault(FAULT_LME_SINGULAR, p);
            return;
        }
        let inv = vec3<f32>(jm.z, -jm.y, jm.x) / det;
        if rn <= params.lme_tol {
            lambda[p] = lam;
#if LME_STORED
            for (var k = 0u; k < STENCIL; k++) {
                let s = p * STENCIL + k;
                let a = lme_node(x, b.x, b.y, k);
                if a.ok {
                    let n = exp(-params.lme_beta * dot(a.d, a.d) + dot(lam, a.d) - cur.log_z);
                    lme_nodes[s] = a.node;
                    lme_w[3u * s] = n;
                    lme_w[3u * s + 1u] = -n * (inv.x * a.d.x + inv.y * a.d.y);
                    lme_w[3u * s + 2u] = -n * (inv.y * a.d.x + inv.z * a.d.y);
                } else {
                    lme_nodes[s] = LME_EMPTY;
                }
            }
#else
            lme_cache[p] = vec4<f32>(cur.log_z, inv);
#endif
            return;
        }
        if it == params.lme_max_iter {
            break;
        }
        let step = -vec2<f32>(inv.x * cur.r.x + inv.y * cur.r.y, inv.y * cur.r.x + inv.z * cur.r.y);
        let slope = dot(cur.r, step);
        // Backtracking with an allowance for f32 round-off in log Z.
        let roundoff = 8.0 * 1.1920929e-7 * max(abs(cur.log_z), 1.0);
        var alpha = 1.0;
        var accepted = false;
        for (var ls = 0; ls < 20; ls++) {
            let trial = lam + alpha * step;
            let t = objective(x, b, trial);
            if t.log_z <= cur.log_z + 1e-4 * alpha * slope + roundoff {
                lam = trial;
                cur = t;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    report_fault(FAULT_LME_NOT_CONVERGED, p);
}
