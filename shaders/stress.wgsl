// Stage `stress`: L = Σ v_I ⊗ ∇N_I, then the material's update over Δt
// (linear elastic: σ += D : Δt sym(L); Neo-Hookean: F ← (I + Δt L) F, σ(F);
// plastic models: Jaumann trial and return, with the `plastic` state),
// and ρ ← ρ / (V_new / V_old). CPU twin: src/cpu/stress.rs.
// Built with FORCES (pass `StressForces`, what a whole step runs) it goes on
// to stage `forces` for the same particle with the same weights (the stress
// is all `forces` needs from it), saving a pass over the particles and a
// shape evaluation; the stages stay separate passes for parity tests. Built
// with FORCES and PATCH, one invocation per bin of particles that share a
// stencil runs both for each of them and sums the forces in registers (the
// walks are shared/bins.wgsl's).
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#include "shared/material.wgsl"
#if DEF_GRAD
@group(0) @binding({{B_DEF_GRAD}}) var<storage, read_write> def_grad: array<vec4<f32>>;
#endif
#if PLASTIC
@group(0) @binding({{B_PLASTIC}}) var<storage, read_write> plastic: array<vec4<f32>>;
#endif

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
#if MUSL
@group(0) @binding({{B_X_START}}) var<storage, read> x_start: array<vec2<f32>>;
#endif
#if MLS_FORCE
// solver.mls_scope = "force": the strain-rate correction (mls_strain.wgsl).
@group(0) @binding({{B_MLS_DL}}) var<storage, read> mls_dl: array<vec4<f32>>;
#endif
#if CELL_AVERAGE
// solver.volumetric_strain = "cell_average": the (cell, body) sums of
// cell_average.wgsl.
@group(0) @binding({{B_BODY}}) var<storage, read> body: array<u32>;
@group(0) @binding({{B_CELL_AVG}}) var<storage, read> cell_avg: array<f32>;
#include "shared/cell_average.wgsl"
#endif
@group(0) @binding({{B_RHO}}) var<storage, read_write> rho: array<f32>;
@group(0) @binding({{B_STRESS}}) var<storage, read_write> stress: array<f32>;
#if FORCES
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

#include "shared/bins.wgsl"
#include "shared/body_force.wgsl"

fn node_value(i: u32) -> f32 {
#if FLOAT_ATOMICS
    return atomicLoad(&node_acc[i]);
#else
    return bitcast<f32>(atomicLoad(&node_acc[i]));
#endif
}
#else
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;

fn node_value(i: u32) -> f32 {
    return node_acc[i];
}
#endif

// The stress update of particle p with shape context c (velocity gradient,
// material, density; state written back). `ok` false: a fault was reported.
struct Updated {
    ok: bool,
    s: vec3<f32>,
    rho: f32,
}

fn update_particle(p: u32, c: ShapeCtx) -> Updated {
    var out: Updated;
    out.ok = false;
    // Velocity gradient L = Σ v ⊗ ∇N as (xx, xy, yx, yy).
    var l = vec4<f32>(0.0);
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if !w.ok {
                continue;
            }
            let b = w.node * NODE_STRIDE;
            let vn = vec2<f32>(node_value(b + 1u), node_value(b + 2u));
            l += vec4<f32>(vn.x * w.dn.x, vn.x * w.dn.y, vn.y * w.dn.x, vn.y * w.dn.y);
        }
    }
#if MLS_FORCE
    l += mls_dl[p];
#endif
#if CELL_AVERAGE
    // The volumetric part of L becomes its (cell, body) mean:
    // L + ½ (⟨tr L⟩ − tr L) I (CPU: `CellAverage::update`'s `dl`).
    let slot = cell_slot(x0[p] + u[p], body[p]);
    let half = 0.5 * (cell_avg[slot] / cell_avg[slot + 1u] - (l.x + l.w));
    l += vec4<f32>(half, 0.0, 0.0, half);
#endif
    let dt = sim.dt;
#if DEF_GRAD
    let f = def_grad[p];
#else
    let f = vec4<f32>(1.0, 0.0, 0.0, 1.0);
#endif
#if PLASTIC
    let q = plastic[p];
#else
    let q = vec4<f32>(0.0);
#endif
    let s0 = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
    let up = material_update(material_of(p), l, dt, s0, f, q);
    if up.fault != 0u {
        report_fault(up.fault, p);
        return out;
    }
    let s = up.s;
    if !(is_finite(s.x) && is_finite(s.y) && is_finite(s.z)) {
        report_fault(FAULT_NON_FINITE_STRESS, p);
        return out;
    }
    let rho_p = rho[p] / up.j;
    rho[p] = rho_p;
#if DEF_GRAD
    def_grad[p] = up.f;
#endif
#if PLASTIC
    plastic[p] = up.q;
#endif
    stress[3u * p] = s.x;
    stress[3u * p + 1u] = s.y;
    stress[3u * p + 2u] = s.z;
    out.ok = true;
    out.s = s;
    out.rho = rho_p;
    return out;
}

#if FORCES
// What the walks of shared/bins.wgsl (the scatter, or with PATCH the
// per-bin one) take from a particle: its stress update, then its volume,
// new stress and body force for the forces.
fn bin_particle(p: u32, c: ShapeCtx) -> BinParticle {
    var q: BinParticle;
    let up = update_particle(p, c);
    q.ok = up.ok;
    if up.ok {
        let m = mass[p];
        q.vol = m / up.rho;
        q.s = up.s;
        q.mb = m * body_force(p, sim.t + sim.t_lo + sim.dt);
    }
    return q;
}
#endif

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
#if PATCH
    scatter_bin(linear_index(gid, nwg));
#else
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
#if MUSL
    // MUSL runs the stress last, after g2p moved the particles: the weights
    // are those of the step's start (eq. 34), as on the CPU's shape cache.
    let c = shape_ctx(p, x_start[p]);
#else
    let c = shape_ctx(p, x0[p] + u[p]);
#endif
#if FORCES
    let q = bin_particle(p, c);
    if q.ok {
        scatter_particle(c, q);
    }
#else
    _ = update_particle(p, c);
#endif
#endif
}
