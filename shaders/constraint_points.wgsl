// Part of stage `grid_update` (constraint points only): after `predict`
// (and MUSL's remap's predict) and, built with CORRECT, after `correct`,
// the nodal velocities take the smallest mass-weighted change that gives
// every point its group's velocity: per field and held component, with
// C_ba = N_a(x_b) over the nodes with mass whose component is free,
//   Δv = M⁻¹ Cᵀ λ,   (C M⁻¹ Cᵀ + ε diag) λ = v̄ − C v,
// then `REFINE` passes solving for what is left. One invocation per lane
// (field × component; one workgroup each): S assembled node by node from
// the node → point list into the lane's envelope (`PointWork`), a
// Cholesky in the envelope, the solves, then Δv on the nodes. With
// CORRECT the change is also a force m Δv / (γΔt) added to f_I, and each
// point's λ Σ_a N_a / (γΔt) goes to its group's reaction.
// Tables: src/gpu/constraint_points.rs. CPU twin:
// src/cpu/constraint_points.rs (its HOLD_REG is 1e-10, below f32's
// round-off; see HOLD_REG_F32).
#include "shared/common.wgsl"

@group(0) @binding({{B_CONSTRAINTS}}) var<storage, read> constraints: array<Constraint>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
@group(0) @binding({{B_POINT_TABLE}}) var<storage, read> table: array<u32>;
@group(0) @binding({{B_POINT_WORK}}) var<storage, read_write> work: array<f32>;
#if CORRECT
@group(0) @binding({{B_REACTIONS}}) var<storage, read_write> reactions: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=reactions FN=reaction_add
#endif

const N_POINTS: u32 = {{POINT_COUNT}}u;
const SLOTS: u32 = {{POINT_SLOTS}}u;
const N_HELD: u32 = {{POINT_HELD}}u;
const AT_SLOTS: u32 = {{POINT_SLOTS_AT}}u;
const AT_WEIGHTS: u32 = {{POINT_WEIGHTS_AT}}u;
const AT_HELD: u32 = {{POINT_HELD_AT}}u;
const AT_LIST: u32 = {{POINT_LIST_AT}}u;
const ENV: u32 = {{POINT_ENV}}u;
const WORK_STRIDE: u32 = {{POINT_WORK_STRIDE}}u;

// Relative regularisation of the points' system in f32: (S + ε diag S) λ = r.
// Two points per cell are more than the node rows they hold, so S is
// singular; the CPU's 1e-10 would leave the null directions' pivots to
// f32 round-off (~1e-6 of the diagonal after a band of ~20 terms), which
// can turn them negative. 1e-5 keeps them positive; should a pivot still
// fail, the system is assembled again with ε 100 times larger (twice at
// most). The refinements then take the held velocities to round-off
// (stages_match_constraint_points in tests/stage_parity.rs: 1e-6 of the
// largest velocity with ε from 1e-6 to 1e-4 on its random state, where
// 1e-4 with the CPU's two refinements left 1e-2: the system's small
// eigenvalues are resolved only once ε is below them or enough passes ran).
const HOLD_REG_F32: f32 = 1e-5;
// Most refinement passes after the first solve; they stop early once a
// pass no longer halves the largest residual (where two groups ask
// different velocities of shared nodes the system is inconsistent, and
// every pass would add r's inconsistent part / ε to λ along S's null
// space, which Δv does not see but f32 loses digits to).
const REFINE: u32 = 8u;

var<private> base: u32;
var<private> comp: u32;
var<private> bit: u32;

// Offsets into the lane's scratch.
fn held_flag(i: u32) -> u32 {
    return base + ENV + i;
}
fn r_at(i: u32) -> u32 {
    return base + ENV + N_POINTS + i;
}
fn lambda_at(i: u32) -> u32 {
    return base + ENV + 2u * N_POINTS + i;
}
fn cv_at(i: u32) -> u32 {
    return base + ENV + 3u * N_POINTS + i;
}
fn dv_at(k: u32) -> u32 {
    return base + ENV + 4u * N_POINTS + k;
}
// S's entry (i, j), j in first(i)..=i.
fn s_at(i: u32, j: u32) -> u32 {
    return base + table[4u * i + 3u] + j - table[4u * i + 2u];
}
fn first(i: u32) -> u32 {
    return table[4u * i + 2u];
}

var<private> field_base: u32;

// Node index (in the stacked nodal arrays) of held node k.
fn node_of(k: u32) -> u32 {
    return field_base + table[AT_HELD + 4u * k];
}
fn mass_of(k: u32) -> f32 {
    return node_acc[node_of(k) * NODE_STRIDE];
}
// Whether held node k has mass and a free component `comp`.
fn free(k: u32) -> bool {
    return mass_of(k) > params.mass_eps && (table[AT_HELD + 4u * k + 1u] & bit) == 0u;
}
fn vel_of(k: u32) -> f32 {
    return node_acc[node_of(k) * NODE_STRIDE + 1u + comp];
}

// C (v + Δv) at point i; `with_dv` adds the lane's Δv so far.
fn point_velocity(i: u32, with_dv: bool) -> f32 {
    var v = 0.0;
    for (var s = 0u; s < SLOTS; s++) {
        let k = table[AT_SLOTS + i * SLOTS + s];
        if k == 0xffffffffu {
            break;
        }
        var x = vel_of(k);
        if with_dv {
            x += work[dv_at(k)];
        }
        v += bitcast<f32>(table[AT_WEIGHTS + i * SLOTS + s]) * x;
    }
    return v;
}

// Δv_k = Σ_i N_ik λ_i / m_k on the free held nodes (0 elsewhere).
fn change() {
    for (var k = 0u; k < N_HELD; k++) {
        var d = 0.0;
        if free(k) {
            let at = table[AT_HELD + 4u * k + 2u];
            let len = table[AT_HELD + 4u * k + 3u];
            for (var e = at; e < at + len; e++) {
                d += bitcast<f32>(table[AT_LIST + 2u * e + 1u]) * work[lambda_at(table[AT_LIST + 2u * e])];
            }
            d /= mass_of(k);
        }
        work[dv_at(k)] = d;
    }
}

// In-place Cholesky S = L Lᵀ in the envelope; false when a pivot is not
// positive.
fn cholesky() -> bool {
    for (var i = 0u; i < N_POINTS; i++) {
        for (var j = first(i); j <= i; j++) {
            var x = work[s_at(i, j)];
            for (var m = max(first(i), first(j)); m < j; m++) {
                x -= work[s_at(i, m)] * work[s_at(j, m)];
            }
            if j < i {
                work[s_at(i, j)] = x / work[s_at(j, j)];
            } else if x > 0.0 {
                work[s_at(i, i)] = sqrt(x);
            } else {
                return false;
            }
        }
    }
    return true;
}

// Solves L Lᵀ x = r in place (r_at).
fn solve() {
    for (var i = 0u; i < N_POINTS; i++) {
        var x = work[r_at(i)];
        for (var j = first(i); j < i; j++) {
            x -= work[s_at(i, j)] * work[r_at(j)];
        }
        work[r_at(i)] = x / work[s_at(i, i)];
    }
    for (var ii = N_POINTS; ii > 0u; ii--) {
        let i = ii - 1u;
        let xi = work[r_at(i)] / work[s_at(i, i)];
        work[r_at(i)] = xi;
        for (var j = first(i); j < i; j++) {
            work[r_at(j)] -= work[s_at(i, j)] * xi;
        }
    }
}

// S = C M⁻¹ Cᵀ over the free nodes, node by node (lower triangle), with
// `reg` on the diagonal. Points that hold nothing here decouple (their
// rows and columns are zero): λ_i = 0 from a unit pivot and a zero
// residual.
fn assemble(reg: f32) {
    for (var e = 0u; e < ENV; e++) {
        work[base + e] = 0.0;
    }
    for (var k = 0u; k < N_HELD; k++) {
        if !free(k) {
            continue;
        }
        let inv_m = 1.0 / mass_of(k);
        let at = table[AT_HELD + 4u * k + 2u];
        let len = table[AT_HELD + 4u * k + 3u];
        for (var a = at; a < at + len; a++) {
            let i = table[AT_LIST + 2u * a];
            if work[held_flag(i)] == 0.0 {
                continue;
            }
            let wi = bitcast<f32>(table[AT_LIST + 2u * a + 1u]) * inv_m;
            for (var b = at; b <= a; b++) {
                let j = table[AT_LIST + 2u * b];
                if work[held_flag(j)] == 0.0 {
                    continue;
                }
                work[s_at(i, j)] += wi * bitcast<f32>(table[AT_LIST + 2u * b + 1u]);
            }
        }
    }
    for (var i = 0u; i < N_POINTS; i++) {
        if work[held_flag(i)] == 0.0 {
            work[s_at(i, i)] = 1.0;
        } else {
            work[s_at(i, i)] *= 1.0 + reg;
        }
    }
}

@compute @workgroup_size(1)
fn main(@builtin(workgroup_id) wid: vec3<u32>) {
    let lane = wid.x;
    if sim.running == 0u || lane >= 2u * {{POINT_FIELDS}}u {
        return;
    }
    comp = lane % 2u;
    bit = 1u << comp;
    field_base = lane / 2u * params.n_nodes;
    base = lane * WORK_STRIDE;
    let t = sim.t + sim.t_lo + sim.dt;
    // Which points hold this component here: their group fixes it and
    // some node of theirs is free with mass.
    var some = false;
    for (var i = 0u; i < N_POINTS; i++) {
        var held = (table[4u * i + 1u] & bit) != 0u;
        if held {
            held = false;
            for (var s = 0u; s < SLOTS; s++) {
                let k = table[AT_SLOTS + i * SLOTS + s];
                if k == 0xffffffffu {
                    break;
                }
                held = held || free(k);
            }
        }
        work[held_flag(i)] = select(0.0, 1.0, held);
        some = some || held;
        work[lambda_at(i)] = 0.0;
    }
    if !some {
        return;
    }
    var reg = HOLD_REG_F32;
    var factored = false;
    for (var attempt = 0u; attempt < 3u && !factored; attempt++) {
        assemble(reg);
        factored = cholesky();
        reg *= 100.0;
    }
    if !factored {
        return;
    }
    for (var i = 0u; i < N_POINTS; i++) {
        work[cv_at(i)] = point_velocity(i, false);
    }
    var last = 0.0;
    for (var sweep = 0u; sweep <= REFINE; sweep++) {
        var worst = 0.0;
        for (var i = 0u; i < N_POINTS; i++) {
            var r = 0.0;
            if work[held_flag(i)] != 0.0 {
                let c = constraints[table[4u * i]];
                var ramp = 1.0;
                if c.ramp_time > 0.0 {
                    ramp = clamp(t / c.ramp_time, 0.0, 1.0);
                }
                let goal = ramp * select(c.vx, c.vy, comp == 1u);
                r = goal - work[cv_at(i)];
            }
            work[r_at(i)] = r;
            worst = max(worst, abs(r));
        }
        if sweep > 0u && worst > 0.5 * last {
            break;
        }
        last = worst;
        solve();
        for (var i = 0u; i < N_POINTS; i++) {
            work[lambda_at(i)] += work[r_at(i)];
        }
        change();
        for (var i = 0u; i < N_POINTS; i++) {
            work[cv_at(i)] = point_velocity(i, true);
        }
    }
    // The change on the nodes (and with CORRECT as a force).
#if CORRECT
    let gdt = params.npc_gamma * sim.dt;
#endif
    for (var k = 0u; k < N_HELD; k++) {
        let d = work[dv_at(k)];
        if d == 0.0 {
            continue;
        }
        let b = node_of(k) * NODE_STRIDE;
        node_acc[b + 1u + comp] += d;
#if CORRECT
        node_acc[b + 3u + comp] += node_acc[b] * d / gdt;
#endif
    }
#if CORRECT
    // Each point's momentum change λ_i Σ_a N_ia over its free nodes.
    for (var i = 0u; i < N_POINTS; i++) {
        let l = work[lambda_at(i)];
        if l == 0.0 {
            continue;
        }
        var w = 0.0;
        for (var s = 0u; s < SLOTS; s++) {
            let k = table[AT_SLOTS + i * SLOTS + s];
            if k == 0xffffffffu {
                break;
            }
            if free(k) {
                w += bitcast<f32>(table[AT_WEIGHTS + i * SLOTS + s]);
            }
        }
        reaction_add(2u * table[4u * i] + comp, w * l / gdt);
    }
#endif
}
