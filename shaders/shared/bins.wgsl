// Particles binned by grid cell (passes bin_clear, bin_count, bin_scan,
// bin_fill): cell_start[c] .. cell_start[c + 1] index cell_order, which
// lists the particles of cell c (in no particular order). Cells are numbered
// row by row, (nx − 1) per row. Used by MLS (particles around a Gauss point)
// and by the node-centred (gather) p2g and forces. Built with WALK, also
// the walks p2g, forces and the fused stress + forces share (below).

// Grid cell of lattice point q (points outside the grid go to the edge cell).
fn bin_cell(q: vec2<f32>) -> u32 {
    let i = u32(clamp(floor(q.x), 0.0, f32(params.nx - 2u)));
    let j = u32(clamp(floor(q.y), 0.0, f32(params.ny - 2u)));
    return j * (params.nx - 1u) + i;
}

#if ANCHOR_BINS
// Gather passes bin each particle by its stencil's anchor (`shape_anchor`,
// its lowest node), clamped to the cells, rather than by the cell that
// holds it: node (i, j) then finds every particle that may reach it in the
// SHAPE_WIDTH² cells with anchors i − SHAPE_WIDTH + 1 ..= i (and j alike),
// whatever the shape, its edge rules or rounding. The gather recomputes the
// particle's shape with the same WGSL function, so the anchor is the same.
fn bin_anchor_cell(a: vec2<i32>) -> u32 {
    let top = vec2<i32>(i32(params.nx) - 2, i32(params.ny) - 2);
    let c = vec2<u32>(clamp(a, vec2<i32>(0), top));
    return c.y * (params.nx - 1u) + c.x;
}

// Bins: one per grid cell.
fn bin_count_all() -> u32 {
    return (params.nx - 1u) * (params.ny - 1u);
}

// A patch slot no particle of the bin reached (PATCH).
const NO_PATCH_NODE: u32 = 0xffffffffu;

// A box of cells, inclusive.
struct CellBox {
    lo: vec2<u32>,
    hi: vec2<u32>,
}

// The cells holding the particles whose stencil may include node (i, j).
fn cells_reaching(i: u32, j: u32) -> CellBox {
    let ij = vec2<i32>(i32(i), i32(j));
    let top = vec2<i32>(i32(params.nx) - 2, i32(params.ny) - 2);
    let lo = clamp(ij - vec2<i32>(i32(SHAPE_WIDTH) - 1), vec2<i32>(0), top);
    let hi = clamp(ij, vec2<i32>(0), top);
    return CellBox(vec2<u32>(lo), vec2<u32>(hi));
}
#endif

#if WALK
// The walks of the passes that put per-particle terms on nodes: p2g,
// forces and the fused stress + forces (flag WALK). Each of those passes
// defines only its body:
//   alias BinSum                       its sum per node (p2g: mass and
//                                      momentum; forces: a force);
//   struct BinParticle { ok: bool, .. } what one particle brings (`ok`
//                                      false: skip it, a fault was reported);
//   fn bin_particle(p, c) -> BinParticle   read (or, fused, update) particle p;
//   fn bin_term(q, w) -> BinSum        its term on the node of weight w;
//   fn bin_add(node, s)                add a sum to a node with atomics
//                                      (not with GATHER).
// x0 and u are the pass's bindings. The three walks give the same sums in
// other orders.

#if GATHER
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;

// Node-centred: the sum over the particles whose stencil reaches node
// (i, j), each one's shape evaluated anew; written once, without atomics.
fn gather_node(i: u32, j: u32) -> BinSum {
    let cells = cells_reaching(i, j);
    var sum = BinSum();
    for (var cj = cells.lo.y; cj <= cells.hi.y; cj++) {
        let row = cj * (params.nx - 1u);
        let end = cell_start[row + cells.hi.x + 1u];
        for (var idx = cell_start[row + cells.lo.x]; idx < end; idx++) {
            let p = cell_order[idx];
            let c = shape_ctx(p, x0[p] + u[p]);
            let w = shape_at(c, i, j);
            if !w.ok {
                continue;
            }
            let q = bin_particle(p, c);
            if q.ok {
                sum += bin_term(q, w);
            }
        }
    }
    return sum;
}
#else
// Particle-centred: particle (c, q) adds its term to each node of its
// stencil with atomics.
fn scatter_particle(c: ShapeCtx, q: BinParticle) {
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if !w.ok {
                continue;
            }
            bin_add(w.node, bin_term(q, w));
        }
    }
}

#if PATCH
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;

// Per bin: the particles of bin b share their stencil's anchor, so slot k
// is the same node for each of them; their terms are summed in a register
// patch of STENCIL nodes, then one `bin_add` per node reached, not one per
// particle. A particle whose anchor is not its bin's (`bin_anchor_cell`
// clamps anchors to the cells) scatters its own terms instead. One
// invocation per bin, b its index (past the last bin, or with the run
// stopped, nothing).
fn scatter_bin(b: u32) {
    if sim.running == 0u || b >= bin_count_all() {
        return;
    }
#if SHAPE_LME
    let anchor = vec2<i32>(i32(b % (params.nx - 1u)), i32(b / (params.nx - 1u)));
#endif
    let end = cell_start[b + 1u];
    var sum: array<BinSum, STENCIL>;
    var node: array<u32, STENCIL>;
    for (var k = 0u; k < STENCIL; k++) {
        node[k] = NO_PATCH_NODE;
    }
    for (var idx = cell_start[b]; idx < end; idx++) {
        let p = cell_order[idx];
        let c = shape_ctx(p, x0[p] + u[p]);
        let q = bin_particle(p, c);
        if !q.ok {
            continue;
        }
        // Linear and B-spline anchors are a node of the particle's own
        // cell (unsigned, at most nx − 2), so bin_anchor_cell never moves
        // them and only LME carries this guard: in the B-spline patch it
        // cost about 9 % of the step on llvmpipe (bspline2, 1e6 particles).
#if SHAPE_LME
        if any(shape_anchor(c) != anchor) {
            scatter_particle(c, q);
            continue;
        }
#endif
        for (var r = 0u; r < SHAPE_ROWS; r++) {
            let span = shape_span(c, r);
            for (var k = span.x; k < span.y; k++) {
                let w = shape_node(c, k);
                if !w.ok {
                    continue;
                }
                node[k] = w.node;
                sum[k] += bin_term(q, w);
            }
        }
    }
    for (var k = 0u; k < STENCIL; k++) {
        if node[k] != NO_PATCH_NODE {
            bin_add(node[k], sum[k]);
        }
    }
}
#endif
#endif
#endif
