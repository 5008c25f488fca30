// Particles binned by grid cell (passes bin_clear, bin_count, bin_scan,
// bin_fill): cell_start[c] .. cell_start[c + 1] index cell_order, which
// lists the particles of cell c (in no particular order). Cells are numbered
// row by row, (nx − 1) per row. Used by MLS (particles around a Gauss point)
// and by the node-centred (gather) p2g and forces.

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
