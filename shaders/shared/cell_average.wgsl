// `solver.volumetric_strain = "cell_average"`: the (cell, body) slots of
// cell_average.wgsl's sums, [Σ V tr L, Σ V] each, N_BODIES per cell.

const N_BODIES: u32 = {{N_BODIES}}u;

// The lattice cell holding grid-relative position x, clamped to the grid
// (CPU: `cell_average::cell_of`).
fn cell_of(x: vec2<f32>) -> u32 {
    let cx = params.nx - 1u;
    let cy = params.ny - 1u;
    let g = max(floor(x * params.inv_h), vec2<f32>(0.0));
    let i = min(u32(g.x), cx - 1u);
    let j = min(u32(g.y), cy - 1u);
    return j * cx + i;
}

// The first of the two sums of the slot of a particle of body b at x.
fn cell_slot(x: vec2<f32>, b: u32) -> u32 {
    return 2u * (cell_of(x) * N_BODIES + b);
}
