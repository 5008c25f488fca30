// Bindings the material functions read.
@group(0) @binding({{B_MATERIALS}}) var<storage, read> materials: array<Material>;
#if MULTI_MATERIAL
@group(0) @binding({{B_MAT}}) var<storage, read> mat: array<u32>;
#endif
