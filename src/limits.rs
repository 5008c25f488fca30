//! Bounds that scene validation and the shape functions both need, kept
//! here so `scene/` checks a scene without reaching into `model::shape`.
//! Pure numbers and formulas: this module imports nothing.

/// An LME support may span at most this many cells from the particle: it
/// bounds the stencil (and per-particle memory) and sets the smallest γ allowed.
pub const LME_MAX_REACH_CELLS: f64 = 6.0;

/// Smallest LME γ whose support stays within `LME_MAX_REACH_CELLS`
/// (0.38 for tol = 1e-6).
pub fn lme_gamma_min(tol: f64) -> f64 {
    -tol.ln() / (LME_MAX_REACH_CELLS * LME_MAX_REACH_CELLS)
}

/// Largest LME γ for which the support (radius r) holds 3 nodes that are
/// not collinear around any point. The worst point is the middle of a cell
/// edge: its two nearest nodes lie on the edge and the next are √5/2 h
/// away, so r ≥ (√5/2 + √2·perturb)·h, with 2% to spare (10.6 for tol 1e-6).
pub fn lme_gamma_max(tol: f64, perturb: f64) -> f64 {
    let reach = 1.02 * (0.5 * 5f64.sqrt() + std::f64::consts::SQRT_2 * perturb);
    -tol.ln() / (reach * reach)
}

/// Largest |coordinate| (m) a scene may use: shapes, grid corners, origin,
/// probes and finite constraint bounds. A kilometre-scale scene fits a
/// thousand times over; beyond this, f64 positions lose the sub-millimetre
/// resolution a cell needs and counts over the domain overflow.
pub const COORD_MAX: f64 = 1e6;

/// Largest scene file read (bytes): a scene is a few kilobytes; this
/// stops `lme-mpm check /dev/zero` at once.
pub const SCENE_FILE_MAX: u64 = 16 << 20;

/// Most shapes (rects, disks, polygons) over all bodies: validation checks
/// rectangle pairs and seeding checks each point against earlier shapes,
/// both quadratic in this count.
pub const MAX_SHAPES: usize = 1000;

/// Most polygon vertices over all bodies (each seeded point is tested
/// against a polygon's every edge).
pub const MAX_POLYGON_VERTICES: usize = 10_000;

/// The MLS weight's support half-width (cells, `solver.mls_support`): at
/// most the paper's 3 (the neighbour search reaches 3 cells), at least 1.5
/// (with 2 particles per cell or more a Gauss point then still sees at
/// least 3 particles per direction).
pub const MLS_SUPPORT_MIN: f64 = 1.5;
pub const MLS_SUPPORT_MAX: f64 = 3.0;

/// GMM's search radius (units of the initial node spacing h,
/// `solver.gmm_search_radius`): default the paper's r = sqrt(2 h²) (§5.1,
/// §5.3). Below, a point in the middle of a cell edge, whose nearest nodes
/// are the edge's two and then two at √5/2 h, would see collinear nodes
/// only: at least √5/2 with 2 % to spare. Above 4 cells a cloud holds
/// some fifty nodes, far beyond any use of the paper's (at most 1.5 √2).
pub const GMM_SEARCH_RADIUS_DEFAULT: f64 = std::f64::consts::SQRT_2;
pub const GMM_SEARCH_RADIUS_MIN: f64 = 1.02 * 1.118_033_988_749_895;
pub const GMM_SEARCH_RADIUS_MAX: f64 = 4.0;

/// GMM-MLS dilation f (units of h, `solver.gmm_dilation`): the weight
/// vanishes at 2 f, so 2 f must exceed √5/2 as the search radius must
/// (0.6 with 7 % to spare); at most the search radius's bound.
pub const GMM_DILATION_MIN: f64 = 0.6;
pub const GMM_DILATION_MAX: f64 = 4.0;

/// GMM-LME γ (`solver.lme_gamma` with `method = "gmm"`): the paper's
/// "0.6 (spread out) to 4 (close to linear finite elements)" (§4.2.2),
/// widened to [0.5, 10]; the cloud is cut at the search radius, so the
/// grid's tolerance-based bounds do not apply.
pub const GMM_LME_GAMMA_MIN: f64 = 0.5;
pub const GMM_LME_GAMMA_MAX: f64 = 10.0;
