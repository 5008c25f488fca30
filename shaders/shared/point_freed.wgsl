// Constraint points only: the region nodes each group's points freed
// (`model::Constraints::freed`), a bit per group per grid node at the end
// of the points' table (src/gpu/constraint_points.rs). A group holds the
// nodes of its box (`Constraint`) that it did not free.
@group(0) @binding({{B_POINT_TABLE}}) var<storage, read> point_table: array<u32>;

// Whether group g's points freed grid node (i, j).
fn freed(g: u32, i: u32, j: u32) -> bool {
    return (point_table[{{POINT_FREED_AT}}u + j * params.nx + i] & (1u << g)) != 0u;
}
