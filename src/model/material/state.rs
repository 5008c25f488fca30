//! The per-particle state a material model keeps besides the stress: the
//! deformation gradient (hyperelastic models) or the plastic state
//! (elasto-plastic models). Its own leaf so the registry's trait, the
//! models and the plastic helpers all name it without naming each other.

/// F as [xx, xy, yx, yy].
pub type DefGrad = [f64; 4];

/// Per-particle state of a plastic model:
/// `[σzz (Pa), ε̄p, εp_v, return]`:
/// - σzz: out-of-plane stress (plane strain: εzz = 0, but after yielding
///   σzz ≠ ν(σxx + σyy), so it is carried);
/// - ε̄p: accumulated equivalent plastic strain, Σ sqrt(2/3 Δεp : Δεp);
/// - εp_v: accumulated volumetric plastic strain, Σ tr Δεp (dilation > 0);
/// - return: the surfaces active in the last step's return as a bit mask
///   (`plastic::ACTIVE_*`; 0 = the step was elastic), stored as a float.
pub type PlasticState = [f64; 4];
