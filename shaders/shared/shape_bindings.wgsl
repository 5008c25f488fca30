// Bindings the shape functions read. Include with LME_ACCESS=read_write
// where λ and the LME cache are written (lme_newton).
#if PERTURBED
@group(0) @binding({{B_NODE_POS}}) var<storage, read> node_pos: array<vec2<f32>>;
#endif
#if CONTACT
// Contact pairs (`model::contact`): each particle's field, the copy of the
// grid's nodes its body moves on; node i of field f is f · n_nodes + i, so
// `shape_node` offsets each particle's nodes into its field (the CPU's
// `contact::offset_nodes` after `shape_eval`) and every pass that
// scatters or gathers through it works per field unchanged.
@group(0) @binding({{B_FIELD}}) var<storage, read> field: array<u32>;

// The first node of particle p's field.
fn field_base(p: u32) -> u32 {
    return field[p] * params.n_nodes;
}
#endif
#if SHAPE_LME
@group(0) @binding({{B_LAMBDA}}) var<storage, {{LME_ACCESS}}> lambda: array<vec2<f32>>;
#if LME_STORED
// Per particle and search-box slot: node index (LME_EMPTY when outside the
// support) and [N, dN/dx, dN/dy].
@group(0) @binding({{B_LME_NODES}}) var<storage, {{LME_ACCESS}}> lme_nodes: array<u32>;
@group(0) @binding({{B_LME_W}}) var<storage, {{LME_ACCESS}}> lme_w: array<f32>;
#else
// Per particle: log Z and J⁻¹ [00, 01, 11].
@group(0) @binding({{B_LME_CACHE}}) var<storage, {{LME_ACCESS}}> lme_cache: array<vec4<f32>>;
#endif
#endif
