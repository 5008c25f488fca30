//! Range checks on every scene value. Each failure names the key and says
//! what is allowed. Geometric checks that need the grid (empty bodies, bodies
//! outside an explicit grid, constraints that match no node) are in
//! `model::Model::new`.

use super::Scene;
use super::schema::*;
use crate::error::SceneError;
use crate::limits;

fn finite(key: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::invalid(
            key,
            format!("must be a finite number, got {v}"),
        ))
    }
}

fn positive(key: &str, v: f64) -> Result<(), SceneError> {
    finite(key, v)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(key, format!("must be > 0, got {v}")))
    }
}

fn finite_point(key: &str, p: &[f64]) -> Result<(), SceneError> {
    for &v in p {
        finite(key, v)?;
    }
    Ok(())
}

/// A position or length (m): finite and within ±`limits::COORD_MAX`.
fn coord(key: &str, p: &[f64]) -> Result<(), SceneError> {
    for &v in p {
        finite(key, v)?;
        if v.abs() > limits::COORD_MAX {
            return Err(SceneError::invalid(
                key,
                format!(
                    "holds {v:e} m, beyond the ±{:e} m a scene may span",
                    limits::COORD_MAX
                ),
            ));
        }
    }
    Ok(())
}

pub(super) fn check(mut file: SceneFile, default_name: &str) -> Result<Scene, SceneError> {
    let name = file
        .name
        .clone()
        .unwrap_or_else(|| default_name.to_string());
    folder_name(&name)?;

    check_solver(&file)?;
    check_gmm(&file)?;
    check_grid(&file)?;
    check_materials(&file)?;
    check_bodies(&file)?;
    check_constraints(&file)?;
    check_walls(&file)?;
    check_contact(&file)?;
    check_platens(&file)?;
    check_loads(&file)?;
    check_gravity(&file)?;
    let sample_interval = check_output(&file)?;
    check_manufactured_section(&mut file)?;
    check_solver_options(&file)?;
    check_keys_apply(&file)?;
    if let Some(kind) = file.exact {
        check_exact(&file, kind)?;
    }

    let (s, g) = (&file.solver, &file.grid);
    let margin = match g.margin {
        Some(m) => m,
        None => {
            file.bodies
                .values()
                .map(|b| b.velocity[0].hypot(b.velocity[1]))
                .fold(0.0, f64::max)
                * s.t_end
        }
    };
    let mut chosen = Vec::new();
    if let Some((pic, why)) = super::defaults::pic_fraction(&file) {
        file.solver.pic_fraction = Some(pic);
        chosen.push(why);
    }
    Ok(Scene {
        name,
        file,
        margin,
        sample_interval,
        chosen,
    })
}

/// The longest `name`, in bytes: a folder name's limit on Linux and macOS
/// (NAME_MAX), less the `.tmp` that atomic writes append beside it.
pub const NAME_MAX_BYTES: usize = 255 - ".tmp".len();

/// `name` is the run's folder (`out/<name>`): a name a folder can hold,
/// checked here so that `check` refuses what `run` could not create.
fn folder_name(name: &str) -> Result<(), SceneError> {
    let why = if name.is_empty() || name == "." || name == ".." {
        Some("is not a folder name".to_string())
    } else if let Some(c) = name
        .chars()
        .find(|c| matches!(c, '/' | '\\') || c.is_control())
    {
        Some(format!(
            "holds {c:?}; a folder name holds no slash, backslash, NUL or other control character"
        ))
    } else if name.len() > NAME_MAX_BYTES {
        Some(format!(
            "is {} bytes long; a folder name holds at most {NAME_MAX_BYTES}",
            name.len()
        ))
    } else {
        None
    };
    match why {
        Some(why) => Err(SceneError::invalid(
            "name",
            format!(
                "must be a plain folder name (outputs go to out/<name>): {name:?} {why}",
                name = if name.len() > 40 {
                    format!("{}…", name.chars().take(40).collect::<String>())
                } else {
                    name.to_string()
                }
            ),
        )),
        None => Ok(()),
    }
}

/// `[solver]`: times, Courant number, integrator and shape parameters.
fn check_solver(file: &SceneFile) -> Result<(), SceneError> {
    let s = &file.solver;
    positive("solver.t_end", s.t_end)?;
    finite("solver.cfl", s.cfl)?;
    let implicit = s.integrator == IntegratorKind::Implicit;
    // Explicit steps are stable only below the Courant limit; the implicit
    // Newmark step (β = 1/4) is unconditionally stable, and 100 keeps Δt a
    // time step rather than a typo.
    let cfl_max = if implicit { 100.0 } else { 1.0 };
    if !(s.cfl > 0.0 && s.cfl <= cfl_max) {
        return Err(SceneError::invalid(
            "solver.cfl",
            format!(
                "must be in (0, {cfl_max}] with integrator = \"{}\", got {}",
                if implicit {
                    "implicit"
                } else {
                    "npc\" or \"fe"
                },
                s.cfl
            ),
        ));
    }
    check_implicit(s)?;
    finite("solver.npc_gamma", s.npc_gamma)?;
    if !(s.npc_gamma > 0.0 && s.npc_gamma <= 1.0) {
        return Err(SceneError::invalid(
            "solver.npc_gamma",
            format!("must be in (0, 1], got {}", s.npc_gamma),
        ));
    }
    finite("solver.lme_tol", s.lme_tol)?;
    if !(s.lme_tol > 0.0 && s.lme_tol <= 1e-2) {
        return Err(SceneError::invalid(
            "solver.lme_tol",
            format!("must be in (0, 1e-2], got {}", s.lme_tol),
        ));
    }
    check_dissipation(s)
}

/// `solver.pic_fraction` in [0, 1] and `solver.local_damping` in [0, 1),
/// both explicit only (the implicit step has no FLIP update and no
/// unbalanced nodal force to damp).
fn check_dissipation(s: &SolverSpec) -> Result<(), SceneError> {
    let pic_fraction = s.pic_fraction.unwrap_or(0.0);
    finite("solver.pic_fraction", pic_fraction)?;
    if !(0.0..=1.0).contains(&pic_fraction) {
        return Err(SceneError::invalid(
            "solver.pic_fraction",
            format!("must be in [0, 1] (0 = FLIP, 1 = PIC), got {pic_fraction}"),
        ));
    }
    finite("solver.local_damping", s.local_damping)?;
    if !(s.local_damping >= 0.0 && s.local_damping < 1.0) {
        return Err(SceneError::invalid(
            "solver.local_damping",
            format!(
                "must be in [0, 1) (1 would remove every unbalanced force), got {}",
                s.local_damping
            ),
        ));
    }
    if s.integrator == IntegratorKind::Implicit {
        for (key, v) in [
            ("solver.pic_fraction", pic_fraction),
            ("solver.local_damping", s.local_damping),
        ] {
            if v != 0.0 {
                return Err(SceneError::invalid(
                    key,
                    "is read by the explicit integrators only (fe, npc, musl); drop it with integrator = \"implicit\"",
                ));
            }
        }
    }
    if s.volumetric_strain == VolumetricStrain::CellAverage {
        if s.integrator == IntegratorKind::Implicit {
            return Err(SceneError::invalid(
                "solver.volumetric_strain",
                "= \"cell_average\" is read by the explicit integrators only (fe, npc, musl); \
                 drop it with integrator = \"implicit\"",
            ));
        }
        if s.mls {
            return Err(SceneError::invalid(
                "solver.volumetric_strain",
                "= \"cell_average\" does not combine with mls = true (the fit has its own strain \
                 rate): drop one of them",
            ));
        }
    }
    Ok(())
}

/// The implicit integrator's keys (checked whatever the integrator, so a
/// typo is caught before it matters).
fn check_implicit(s: &SolverSpec) -> Result<(), SceneError> {
    finite("solver.newmark_beta", s.newmark_beta)?;
    if !(s.newmark_beta > 0.0 && s.newmark_beta <= 0.5) {
        return Err(SceneError::invalid(
            "solver.newmark_beta",
            format!("must be in (0, 0.5], got {}", s.newmark_beta),
        ));
    }
    finite("solver.newmark_gamma", s.newmark_gamma)?;
    if !(s.newmark_gamma >= 0.5 && s.newmark_gamma <= 1.0) {
        return Err(SceneError::invalid(
            "solver.newmark_gamma",
            format!(
                "must be in [0.5, 1] (below 0.5 Newmark amplifies), got {}",
                s.newmark_gamma
            ),
        ));
    }
    finite("solver.newton_tol", s.newton_tol)?;
    if !(s.newton_tol >= 1e-14 && s.newton_tol <= 1e-2) {
        return Err(SceneError::invalid(
            "solver.newton_tol",
            format!("must be in [1e-14, 1e-2], got {}", s.newton_tol),
        ));
    }
    if s.newton_max_iter == 0 || s.newton_max_iter > 1000 {
        return Err(SceneError::invalid(
            "solver.newton_max_iter",
            format!("must be in [1, 1000], got {}", s.newton_max_iter),
        ));
    }
    if s.newton_max_cuts > 30 {
        return Err(SceneError::invalid(
            "solver.newton_max_cuts",
            format!(
                "must be at most 30 (2^-30 of the step), got {}",
                s.newton_max_cuts
            ),
        ));
    }
    if s.load_steps == 0 || s.load_steps > 1_000_000 {
        return Err(SceneError::invalid(
            "solver.load_steps",
            format!("must be in [1, 1e6], got {}", s.load_steps),
        ));
    }
    let implicit = s.integrator == IntegratorKind::Implicit;
    if s.static_analysis && !implicit {
        return Err(SceneError::invalid(
            "solver.static",
            "needs integrator = \"implicit\" (an explicit step has no static form)",
        ));
    }
    if implicit && s.mls {
        return Err(SceneError::invalid(
            "solver.mls",
            "is not available with integrator = \"implicit\" (the implicit step integrates at the particles)",
        ));
    }
    Ok(())
}

/// `solver.method = "gmm"` and its keys (checked whatever the method, so a
/// typo is caught before it matters): GMM runs the implicit step only,
/// and what it does not do (contact pairs, the grid's MLS keys) is
/// refused, naming the key; walls act on the cloud's nodes.
fn check_gmm(file: &SceneFile) -> Result<(), SceneError> {
    let s = &file.solver;
    finite("solver.gmm_search_radius", s.gmm_search_radius)?;
    if !(s.gmm_search_radius >= limits::GMM_SEARCH_RADIUS_MIN
        && s.gmm_search_radius <= limits::GMM_SEARCH_RADIUS_MAX)
    {
        return Err(SceneError::invalid(
            "solver.gmm_search_radius",
            format!(
                "must be in [{:.3}, {}] (units of grid.h; below, a point mid-way along a cell edge sees \
                 collinear nodes only), got {}",
                limits::GMM_SEARCH_RADIUS_MIN,
                limits::GMM_SEARCH_RADIUS_MAX,
                s.gmm_search_radius
            ),
        ));
    }
    finite("solver.gmm_dilation", s.gmm_dilation)?;
    if !(s.gmm_dilation >= limits::GMM_DILATION_MIN && s.gmm_dilation <= limits::GMM_DILATION_MAX) {
        return Err(SceneError::invalid(
            "solver.gmm_dilation",
            format!(
                "must be in [{}, {}] (units of grid.h; the MLS weight vanishes at twice it), got {}",
                limits::GMM_DILATION_MIN,
                limits::GMM_DILATION_MAX,
                s.gmm_dilation
            ),
        ));
    }
    if s.method != SolverMethod::Gmm {
        return Ok(());
    }
    if s.integrator != IntegratorKind::Implicit {
        return Err(SceneError::invalid(
            "solver.method",
            "= \"gmm\" needs integrator = \"implicit\" (the paper's GMM is the implicit \
             Newmark-Newton step on a moving node cloud)",
        ));
    }
    if s.gmm_basis == GmmBasis::Lme {
        finite("solver.lme_gamma", s.lme_gamma)?;
        if !(s.lme_gamma >= limits::GMM_LME_GAMMA_MIN && s.lme_gamma <= limits::GMM_LME_GAMMA_MAX) {
            return Err(SceneError::invalid(
                "solver.lme_gamma",
                format!(
                    "must be in [{}, {}] with method = \"gmm\" (the paper uses 0.6 to 4), got {}",
                    limits::GMM_LME_GAMMA_MIN,
                    limits::GMM_LME_GAMMA_MAX,
                    s.lme_gamma
                ),
            ));
        }
    }
    if let Some(name) = file.contact.keys().next() {
        return Err(SceneError::invalid(
            format!("contact.{name}"),
            "is not available with method = \"gmm\" (a node cloud per body would need its own \
             contact between clouds)",
        ));
    }
    if s.mls_scope != MlsScope::All {
        return Err(SceneError::invalid(
            "solver.mls_scope",
            "is the grid MLS's key; with method = \"gmm\" use gmm_basis = \"mls\" and gmm_dilation",
        ));
    }
    if s.mls_support != limits::MLS_SUPPORT_MAX {
        return Err(SceneError::invalid(
            "solver.mls_support",
            "is the grid MLS's key; with method = \"gmm\" use gmm_basis = \"mls\" and gmm_dilation",
        ));
    }
    Ok(())
}

/// `[grid]`: spacing, extent, origin, perturbation; the shape’s grid needs.
fn check_grid(file: &SceneFile) -> Result<(), SceneError> {
    let s = &file.solver;
    let g = &file.grid;
    positive("grid.h", g.h)?;
    coord("grid.h", &[g.h])?;
    if let Some(o) = g.origin {
        coord("grid.origin", &o)?;
    }
    if let Some(m) = g.margin {
        coord("grid.margin", &[m])?;
        if m < 0.0 {
            return Err(SceneError::invalid(
                "grid.margin",
                format!("must be >= 0, got {m}"),
            ));
        }
    }
    match (g.min, g.max) {
        (None, None) => {}
        (Some(lo), Some(hi)) => {
            coord("grid.min", &lo)?;
            coord("grid.max", &hi)?;
            if !(lo[0] < hi[0] && lo[1] < hi[1]) {
                return Err(SceneError::invalid(
                    "grid.max",
                    format!("must exceed grid.min in both coordinates, got min {lo:?}, max {hi:?}"),
                ));
            }
        }
        (Some(_), None) => {
            return Err(SceneError::invalid(
                "grid.max",
                "is required when grid.min is set",
            ));
        }
        (None, Some(_)) => {
            return Err(SceneError::invalid(
                "grid.min",
                "is required when grid.max is set",
            ));
        }
    }
    finite("grid.perturb", g.perturb)?;
    if !(0.0..0.25).contains(&g.perturb) {
        return Err(SceneError::invalid(
            "grid.perturb",
            format!(
                "must be in [0, 0.25) (a fraction of h; larger moves can fold Q4 cells), got {}",
                g.perturb
            ),
        ));
    }

    if matches!(s.shape, ShapeKind::Bspline2 | ShapeKind::Bspline3) && g.perturb != 0.0 {
        return Err(SceneError::invalid(
            "grid.perturb",
            "must be 0 with B-spline shapes: their knot vectors need a regular grid",
        ));
    }
    if s.shape == ShapeKind::Lme && s.method == SolverMethod::Mpm {
        finite("solver.lme_gamma", s.lme_gamma)?;
        let (gmin, gmax) = (
            limits::lme_gamma_min(s.lme_tol),
            limits::lme_gamma_max(s.lme_tol, g.perturb),
        );
        if !(s.lme_gamma >= gmin && s.lme_gamma <= gmax) {
            return Err(SceneError::invalid(
                "solver.lme_gamma",
                format!(
                    "must be in [{gmin:.2}, {gmax:.2}] for lme_tol = {:e} and grid.perturb = {} \
                     (above, the support cannot enclose a cell; below, it spans more than {} cells), got {}",
                    s.lme_tol,
                    g.perturb,
                    limits::LME_MAX_REACH_CELLS,
                    s.lme_gamma
                ),
            ));
        }
    }
    Ok(())
}

/// `[materials]`: at least one, each with a positive density. The model's
/// name and its own keys are checked by the material registry
/// (`model::material::check`, run by `preflight` and `Model::new`), which
/// knows each model's keys; a scene is validated without the model layer.
fn check_materials(file: &SceneFile) -> Result<(), SceneError> {
    if file.materials.is_empty() {
        return Err(SceneError::invalid(
            "materials",
            "must define at least one material",
        ));
    }
    for (mname, m) in &file.materials {
        positive(&format!("materials.{mname}.density"), m.density)?;
    }
    Ok(())
}

/// `[bodies]`: at least one; shapes, particles per cell, materials, sizes and overlaps.
fn check_bodies(file: &SceneFile) -> Result<(), SceneError> {
    let s = &file.solver;
    if file.bodies.is_empty() {
        return Err(SceneError::invalid(
            "bodies",
            "must define at least one body",
        ));
    }
    let mut ugimp_ppc: Option<(String, u32)> = None;
    for (bname, b) in &file.bodies {
        let key = |k: &str| format!("bodies.{bname}.{k}");
        if !file.materials.contains_key(&b.material) {
            let known: Vec<_> = file.materials.keys().map(String::as_str).collect();
            return Err(SceneError::invalid(
                key("material"),
                format!(
                    "names `{}`, which is not defined; defined: {}",
                    b.material,
                    known.join(", ")
                ),
            ));
        }
        if !(1..=6).contains(&b.ppc) {
            return Err(SceneError::invalid(
                key("ppc"),
                format!("must be in 1..=6, got {}", b.ppc),
            ));
        }
        finite_point(&key("velocity"), &b.velocity)?;
        if b.rects.is_empty() && b.disks.is_empty() && b.polygons.is_empty() {
            return Err(SceneError::invalid(
                bname_key(bname),
                "is empty: give at least one of rects, disks, polygons",
            ));
        }
        for (i, r) in b.rects.iter().enumerate() {
            coord(&format!("bodies.{bname}.rects[{i}]"), r)?;
            if !(r[0] < r[2] && r[1] < r[3]) {
                return Err(SceneError::invalid(
                    format!("bodies.{bname}.rects[{i}]"),
                    format!(
                        "must be [xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax, got {r:?}"
                    ),
                ));
            }
        }
        for (i, d) in b.disks.iter().enumerate() {
            coord(&format!("bodies.{bname}.disks[{i}]"), d)?;
            if d[2] <= 0.0 {
                return Err(SceneError::invalid(
                    format!("bodies.{bname}.disks[{i}]"),
                    format!("must be [cx, cy, r] with r > 0, got {d:?}"),
                ));
            }
        }
        if b.disk_layout == DiskLayout::Rings && b.disks.is_empty() {
            return Err(SceneError::invalid(
                key("disk_layout"),
                "is `rings`, which places the particles of disks, but the body has no disk",
            ));
        }
        for (i, poly) in b.polygons.iter().enumerate() {
            for p in poly {
                coord(&format!("bodies.{bname}.polygons[{i}]"), p)?;
            }
            if poly.len() < 3 || super::seed::polygon_area(poly).abs() <= 0.0 {
                return Err(SceneError::invalid(
                    format!("bodies.{bname}.polygons[{i}]"),
                    "must have at least 3 vertices enclosing a positive area",
                ));
            }
        }
        if s.shape == ShapeKind::Ugimp {
            match &ugimp_ppc {
                None => ugimp_ppc = Some((bname.clone(), b.ppc)),
                Some((first, ppc)) if *ppc != b.ppc => {
                    return Err(SceneError::invalid(
                        key("ppc"),
                        format!(
                            "is {} but bodies.{first}.ppc is {ppc}: uGIMP uses one particle size \
                             h/(2 ppc), so every body needs the same ppc",
                            b.ppc
                        ),
                    ));
                }
                Some(_) => {}
            }
        }
    }
    let shapes: usize = file
        .bodies
        .values()
        .map(|b| b.rects.len() + b.disks.len() + b.polygons.len())
        .sum();
    if shapes > limits::MAX_SHAPES {
        return Err(SceneError::invalid(
            "bodies",
            format!(
                "hold {shapes} shapes, more than {}: merge rectangles",
                limits::MAX_SHAPES
            ),
        ));
    }
    let vertices: usize = file
        .bodies
        .values()
        .flat_map(|b| b.polygons.iter().map(Vec::len))
        .sum();
    if vertices > limits::MAX_POLYGON_VERTICES {
        return Err(SceneError::invalid(
            "bodies",
            format!(
                "hold {vertices} polygon vertices, more than {}",
                limits::MAX_POLYGON_VERTICES
            ),
        ));
    }
    check_rect_overlaps(file)?;
    check_body_overlaps(file)?;
    for (bname, b) in &file.bodies {
        check_initial_stress(file, bname, b)?;
    }
    Ok(())
}

/// A body's `initial_stress` and `k0`: geostatic needs full gravity along
/// −y from the start; k0 > 0 and only with it.
fn check_initial_stress(file: &SceneFile, bname: &str, b: &BodySpec) -> Result<(), SceneError> {
    let key = |k: &str| format!("bodies.{bname}.{k}");
    if let Some(k0) = b.k0 {
        finite(&key("k0"), k0)?;
        if k0 <= 0.0 {
            return Err(SceneError::invalid(
                key("k0"),
                format!("must be > 0 (σ_h / σ_v), got {k0}"),
            ));
        }
        if b.initial_stress != InitialStress::Geostatic {
            return Err(SceneError::invalid(
                key("k0"),
                "applies only with initial_stress = \"geostatic\"",
            ));
        }
    }
    if let Some(wt) = b.water_table {
        finite(&key("water_table"), wt)?;
        if b.initial_stress != InitialStress::Geostatic {
            return Err(SceneError::invalid(
                key("water_table"),
                "applies only with initial_stress = \"geostatic\" (the hydrostatic start below the table)",
            ));
        }
    }
    if b.initial_stress == InitialStress::Geostatic {
        let ok = file
            .gravity
            .as_ref()
            .is_some_and(|g| g.g[0] == 0.0 && g.g[1] < 0.0 && g.ramp == Ramp::None);
        if !ok {
            return Err(SceneError::invalid(
                key("initial_stress"),
                "= \"geostatic\" needs gravity along -y (gravity.g = [0, -g]) at full strength from the start (gravity.ramp = \"none\")",
            ));
        }
    }
    Ok(())
}

/// `[constraints]`: boxes with finite or infinite bounds in order.
fn check_constraints(file: &SceneFile) -> Result<(), SceneError> {
    for (cname, c) in &file.constraints {
        for v in c.min.iter().chain(&c.max) {
            if v.is_nan() || (v.is_finite() && v.abs() > limits::COORD_MAX) {
                return Err(SceneError::invalid(
                    format!("constraints.{cname}"),
                    format!(
                        "min/max must be ±inf or within ±{:e} m, got {v}",
                        limits::COORD_MAX
                    ),
                ));
            }
        }
        if !(c.min[0] <= c.max[0] && c.min[1] <= c.max[1]) {
            return Err(SceneError::invalid(
                format!("constraints.{cname}.max"),
                format!(
                    "must be >= min in both coordinates, got min {:?}, max {:?}",
                    c.min, c.max
                ),
            ));
        }
        finite_point(&format!("constraints.{cname}.velocity"), &c.velocity)?;
        ramp_time(&format!("constraints.{cname}.ramp_time"), c.ramp_time)?;
    }
    Ok(())
}

/// A ramp time (s): finite and ≥ 0 (0 = sudden).
fn ramp_time(key: &str, v: f64) -> Result<(), SceneError> {
    finite(key, v)?;
    if v < 0.0 {
        return Err(SceneError::invalid(
            key,
            format!("must be >= 0 (0 = applied from the start), got {v}"),
        ));
    }
    Ok(())
}

/// Most walls a scene may have: the GPU marks a node's walls in one u32.
pub const MAX_WALLS: usize = 32;

/// `[walls]`: a point, a non-zero normal, a contact law and its μ.
fn check_walls(file: &SceneFile) -> Result<(), SceneError> {
    if file.walls.len() > MAX_WALLS {
        return Err(SceneError::invalid(
            "walls",
            format!(
                "has {} walls, more than {MAX_WALLS} (a node keeps its walls in 32 bits)",
                file.walls.len()
            ),
        ));
    }
    for (name, w) in &file.walls {
        let key = format!("walls.{name}");
        if file.constraints.contains_key(name) {
            return Err(SceneError::invalid(
                key,
                "has the name of a constraint; reactions are reported by name, so give it another",
            ));
        }
        coord(&format!("{key}.point"), &w.point)?;
        finite_point(&format!("{key}.normal"), &w.normal)?;
        let len = w.normal[0].hypot(w.normal[1]);
        if len == 0.0 {
            return Err(SceneError::invalid(
                format!("{key}.normal"),
                format!("must have a non-zero length, got {:?}", w.normal),
            ));
        }
        check_friction(&key, "contact", w.contact, w.friction)?;
        check_gate(file, &key, w)?;
    }
    Ok(())
}

/// `KEY.friction` against `KEY.LAW_KEY` (a wall's `contact`, a pair's
/// `law`): required and ≥ 0 with friction, refused otherwise.
fn check_friction(
    key: &str,
    law_key: &str,
    law: Contact,
    friction: Option<f64>,
) -> Result<(), SceneError> {
    match (law, friction) {
        (Contact::Friction, None) => Err(SceneError::invalid(
            format!("{key}.friction"),
            format!("is required with {law_key} = \"friction\" (Coulomb's μ >= 0)"),
        )),
        (Contact::Friction, Some(mu)) => {
            finite(&format!("{key}.friction"), mu)?;
            if mu < 0.0 {
                return Err(SceneError::invalid(
                    format!("{key}.friction"),
                    format!("must be >= 0, got {mu}"),
                ));
            }
            Ok(())
        }
        (_, Some(_)) => Err(SceneError::invalid(
            format!("{key}.friction"),
            format!(
                "is only read with {law_key} = \"friction\"; drop it or set {law_key} = \"friction\""
            ),
        )),
        (_, None) => Ok(()),
    }
}

/// `[contact.NAME]`: two different bodies of the scene, each pair once,
/// the law's friction as for walls; the explicit integrators without MLS
/// (the implicit step and the MLS transfers have one velocity field).
fn check_contact(file: &SceneFile) -> Result<(), SceneError> {
    let mut seen: Vec<[&str; 2]> = Vec::new();
    for (name, c) in &file.contact {
        let key = format!("contact.{name}");
        for b in &c.bodies {
            if !file.bodies.contains_key(b) {
                return Err(SceneError::invalid(
                    format!("{key}.bodies"),
                    format!(
                        "names {b:?}, which is not a body of the scene (bodies: {})",
                        file.bodies.keys().cloned().collect::<Vec<_>>().join(", ")
                    ),
                ));
            }
        }
        let [a, b] = [c.bodies[0].as_str(), c.bodies[1].as_str()];
        if a == b {
            return Err(SceneError::invalid(
                format!("{key}.bodies"),
                format!("pairs {a:?} with itself; a contact pair needs two different bodies"),
            ));
        }
        let pair = if a < b { [a, b] } else { [b, a] };
        if seen.contains(&pair) {
            return Err(SceneError::invalid(
                format!("{key}.bodies"),
                format!("pairs {a:?} and {b:?} a second time; declare each pair once"),
            ));
        }
        seen.push(pair);
        check_friction(&key, "law", c.law, c.friction)?;
        if file.solver.integrator == IntegratorKind::Implicit {
            return Err(SceneError::invalid(
                key,
                "is not available with solver.integrator = \"implicit\" (its Newton step has one \
                 velocity field); use \"npc\", \"fe\" or \"musl\"",
            ));
        }
        if file.solver.mls {
            return Err(SceneError::invalid(
                key,
                "is not available with solver.mls = true (the MLS transfers have one velocity field)",
            ));
        }
    }
    Ok(())
}

/// `[platens.NAME]`: a region (min ≤ max), on the explicit integrators
/// of one velocity field (the implicit step's Newton and GMM's cloud do
/// not tie nodes; contact pairs have a field per body). That it holds
/// nodes, none of them fixed along its axis, is `Model::new`'s check.
fn check_platens(file: &SceneFile) -> Result<(), SceneError> {
    for (name, p) in &file.platens {
        let key = format!("platens.{name}");
        for k in 0..2 {
            if p.min[k].is_nan() || p.max[k].is_nan() || p.min[k] > p.max[k] {
                return Err(SceneError::invalid(
                    format!("{key}.min"),
                    format!("{:?} to {:?} is not a region (min ≤ max)", p.min, p.max),
                ));
            }
        }
        finite(&format!("{key}.force"), p.force)?;
        ramp_time(&format!("{key}.ramp_time"), p.ramp_time)?;
        let refuse = |why: &str| Err(SceneError::invalid(key.clone(), why.to_string()));
        if file.solver.integrator == IntegratorKind::Implicit {
            return refuse(
                "is read by the explicit integrators only (fe, npc, musl); the implicit step ties no nodes",
            );
        }
        if !file.contact.is_empty() {
            return refuse(
                "does not combine with [contact] pairs yet (a platen ties one velocity field)",
            );
        }
    }
    Ok(())
}

/// A wall's `appear_at` and `remove_at` (s): finite, ≥ 0, and the wall
/// acts for appear_at ≤ t < remove_at, so appear_at < remove_at. The
/// implicit step holds its walls' contact states through Newton and does
/// not read them.
fn check_gate(file: &SceneFile, key: &str, w: &WallSpec) -> Result<(), SceneError> {
    let timed = w.appear_at != 0.0 || w.remove_at.is_some();
    if timed && file.solver.integrator == IntegratorKind::Implicit {
        let k = if w.remove_at.is_some() {
            "remove_at"
        } else {
            "appear_at"
        };
        return Err(SceneError::invalid(
            format!("{key}.{k}"),
            "is read by the explicit integrators only (fe, npc, musl)",
        ));
    }
    finite(&format!("{key}.appear_at"), w.appear_at)?;
    if w.appear_at < 0.0 {
        return Err(SceneError::invalid(
            format!("{key}.appear_at"),
            format!("must be >= 0 (s), got {}", w.appear_at),
        ));
    }
    if let Some(r) = w.remove_at {
        finite(&format!("{key}.remove_at"), r)?;
        if r < 0.0 {
            return Err(SceneError::invalid(
                format!("{key}.remove_at"),
                format!("must be >= 0 (s), got {r}"),
            ));
        }
        if w.appear_at >= r {
            return Err(SceneError::invalid(
                format!("{key}.appear_at"),
                format!(
                    "must be below remove_at ({r} s): the wall acts for appear_at <= t < remove_at, got {}",
                    w.appear_at
                ),
            ));
        }
    }
    Ok(())
}

/// `[tractions]` and `[point_loads]`: finite values, a segment of non-zero
/// length, ramp times ≥ 0. Whether they touch a body is checked in
/// `model::Model::new`, which has the particles.
fn check_loads(file: &SceneFile) -> Result<(), SceneError> {
    if file.solver.mls && !(file.tractions.is_empty() && file.point_loads.is_empty()) {
        return Err(SceneError::invalid(
            "solver.mls",
            "cannot carry tractions or point loads (MLS fits the body force as a smooth field, \
             which would smear a load on a few particles); drop the loads or set mls = false",
        ));
    }
    for (name, t) in &file.tractions {
        let key = format!("tractions.{name}");
        coord(&format!("{key}.from"), &t.from)?;
        coord(&format!("{key}.to"), &t.to)?;
        finite_point(&format!("{key}.traction"), &t.traction)?;
        ramp_time(&format!("{key}.ramp_time"), t.ramp_time)?;
        if (t.to[0] - t.from[0]).hypot(t.to[1] - t.from[1]) <= 1e-9 * file.grid.h.abs() {
            return Err(SceneError::invalid(
                format!("{key}.to"),
                format!(
                    "must differ from `from`: the segment {:?} to {:?} has zero length",
                    t.from, t.to
                ),
            ));
        }
    }
    for (name, l) in &file.point_loads {
        let key = format!("point_loads.{name}");
        coord(&format!("{key}.at"), &l.at)?;
        finite_point(&format!("{key}.force"), &l.force)?;
        ramp_time(&format!("{key}.ramp_time"), l.ramp_time)?;
    }
    Ok(())
}

/// `[gravity]`: a finite vector and a ramp with its period.
fn check_gravity(file: &SceneFile) -> Result<(), SceneError> {
    if let Some(gr) = &file.gravity {
        finite_point("gravity.g", &gr.g)?;
        match (gr.ramp, gr.ramp_period) {
            (Ramp::Sine, None) => {
                return Err(SceneError::invalid(
                    "gravity.ramp_period",
                    "is required with ramp = \"sine\"",
                ));
            }
            (_, Some(t)) => positive("gravity.ramp_period", t)?,
            _ => {}
        }
    }
    Ok(())
}

/// `[output]`: intervals and probes; returns the sample interval (s), t_end / 500 by default.
fn check_output(file: &SceneFile) -> Result<f64, SceneError> {
    let s = &file.solver;
    let o = &file.output;
    let sample_interval = match o.sample_interval {
        Some(v) => {
            positive("output.sample_interval", v)?;
            v
        }
        None => s.t_end / 500.0,
    };
    if let Some(v) = o.vtk_interval {
        positive("output.vtk_interval", v)?;
    }
    if let Some(v) = o.checkpoint_interval {
        positive("output.checkpoint_interval", v)?;
    }
    for (pname, p) in &o.probes {
        coord(&format!("output.probes.{pname}"), p)?;
    }
    Ok(sample_interval)
}

/// `[manufactured]`: its own checks, and `exact` set to score against it.
fn check_manufactured_section(file: &mut SceneFile) -> Result<(), SceneError> {
    if let Some(m) = &file.manufactured {
        check_manufactured(file, m)?;
        match file.exact {
            None | Some(ExactKind::AlignedVibration) => {
                file.exact = Some(ExactKind::AlignedVibration)
            }
            Some(other) => {
                return Err(SceneError::invalid(
                    "exact",
                    format!(
                        "is {other:?} but [manufactured] scores the run against its own solution: drop `exact`"
                    ),
                ));
            }
        }
    } else if file.exact == Some(ExactKind::AlignedVibration) {
        return Err(SceneError::invalid(
            "exact",
            "= \"aligned_vibration\" needs a [manufactured] section",
        ));
    }
    Ok(())
}

/// `solver.dt` and `solver.mls` against the shape and the grid.
fn check_solver_options(file: &SceneFile) -> Result<(), SceneError> {
    let s = &file.solver;
    let g = &file.grid;
    if let Some(dt) = s.dt {
        positive("solver.dt", dt)?;
    }
    if s.mls && matches!(s.shape, ShapeKind::Ugimp | ShapeKind::Lme) {
        return Err(SceneError::invalid(
            "solver.mls",
            "works with bspline2, bspline3 and linear only: MLS integrates at Gauss points of \
             polynomial cells, where uGIMP's particle-domain averages have no meaning and LME's \
             non-polynomial functions are not integrated exactly",
        ));
    }
    finite("solver.mls_support", s.mls_support)?;
    if !(crate::limits::MLS_SUPPORT_MIN..=crate::limits::MLS_SUPPORT_MAX).contains(&s.mls_support) {
        return Err(SceneError::invalid(
            "solver.mls_support",
            format!(
                "must be in [{}, {}] cells (3 is the paper's weight), got {}",
                crate::limits::MLS_SUPPORT_MIN,
                crate::limits::MLS_SUPPORT_MAX,
                s.mls_support
            ),
        ));
    }
    if s.mls && g.perturb != 0.0 {
        return Err(SceneError::invalid(
            "solver.mls",
            "needs a regular grid (grid.perturb = 0): its Gauss points sit in the grid's rectangular cells",
        ));
    }
    if s.bspline_knots.is_some() && !matches!(s.shape, ShapeKind::Bspline2 | ShapeKind::Bspline3) {
        return Err(SceneError::invalid(
            "solver.bspline_knots",
            "is only read with shape = \"bspline2\" or \"bspline3\"; drop it or choose a B-spline",
        ));
    }
    Ok(())
}

/// One rule for keys that only some settings read: a key set under
/// settings that never read it is refused, naming the key and what would
/// make it apply, rather than ignored. "Set" is a value other than the
/// key's default (the defaults are filled in on reading, and a resolved
/// scene file holds them all), or any value of an optional key. Keys
/// refused elsewhere by the same rule: `solver.pic_fraction`,
/// `solver.local_damping`, `solver.volumetric_strain`, `solver.static`,
/// `solver.bspline_knots`, the grid MLS keys with `method = "gmm"`, a
/// wall's or contact pair's `friction`, a body's `k0`.
fn check_keys_apply(file: &SceneFile) -> Result<(), SceneError> {
    let d = SolverSpec::defaults();
    let s = &file.solver;
    let implicit = s.integrator == IntegratorKind::Implicit;
    let npc = s.integrator == IntegratorKind::Npc;
    let gmm = s.method == SolverMethod::Gmm;
    const IMPLICIT: &str = "solver.integrator = \"implicit\"";
    const NPC: &str = "solver.integrator = \"npc\"";
    const MLS: &str = "solver.mls = true";
    const GMM: &str = "solver.method = \"gmm\" (with integrator = \"implicit\")";
    // LME on the grid, or GMM's LME basis over its cloud.
    let lme = s.shape == ShapeKind::Lme || (gmm && s.gmm_basis == GmmBasis::Lme);
    const LME: &str = "solver.shape = \"lme\", or method = \"gmm\" with gmm_basis = \"lme\"";
    // (key, set, read under the scene's settings, what makes it read)
    let keys: [(&str, bool, bool, &str); 19] = [
        (
            "gravity.ramp_period",
            file.gravity
                .as_ref()
                .is_some_and(|g| g.ramp_period.is_some()),
            file.gravity.as_ref().is_some_and(|g| g.ramp == Ramp::Sine),
            "gravity.ramp = \"sine\"",
        ),
        (
            "solver.mls_support",
            s.mls_support != d.mls_support,
            s.mls,
            MLS,
        ),
        ("solver.mls_scope", s.mls_scope != d.mls_scope, s.mls, MLS),
        ("solver.npc_gamma", s.npc_gamma != d.npc_gamma, npc, NPC),
        (
            "solver.npc_position",
            s.npc_position != d.npc_position,
            npc,
            NPC,
        ),
        (
            "solver.newmark_beta",
            s.newmark_beta != d.newmark_beta,
            implicit,
            IMPLICIT,
        ),
        (
            "solver.newmark_gamma",
            s.newmark_gamma != d.newmark_gamma,
            implicit,
            IMPLICIT,
        ),
        (
            "solver.newton_tol",
            s.newton_tol != d.newton_tol,
            implicit,
            IMPLICIT,
        ),
        (
            "solver.newton_max_iter",
            s.newton_max_iter != d.newton_max_iter,
            implicit,
            IMPLICIT,
        ),
        (
            "solver.newton_max_cuts",
            s.newton_max_cuts != d.newton_max_cuts,
            implicit,
            IMPLICIT,
        ),
        (
            "solver.newton_jacobian",
            s.newton_jacobian != d.newton_jacobian,
            implicit,
            IMPLICIT,
        ),
        (
            "solver.load_steps",
            s.load_steps != d.load_steps,
            implicit && s.static_analysis,
            "solver.static = true (with integrator = \"implicit\")",
        ),
        (
            "solver.implicit_start",
            s.implicit_start != d.implicit_start,
            implicit && !s.static_analysis,
            "a dynamic implicit run (integrator = \"implicit\", static = false)",
        ),
        (
            "solver.implicit_mass",
            s.implicit_mass != d.implicit_mass,
            implicit,
            IMPLICIT,
        ),
        ("solver.lme_gamma", s.lme_gamma != d.lme_gamma, lme, LME),
        ("solver.lme_tol", s.lme_tol != d.lme_tol, lme, LME),
        ("solver.gmm_basis", s.gmm_basis != d.gmm_basis, gmm, GMM),
        (
            "solver.gmm_search_radius",
            s.gmm_search_radius != d.gmm_search_radius,
            gmm,
            GMM,
        ),
        (
            "solver.gmm_dilation",
            s.gmm_dilation != d.gmm_dilation,
            gmm && s.gmm_basis == GmmBasis::Mls,
            "solver.method = \"gmm\" with gmm_basis = \"mls\"",
        ),
    ];
    match keys.iter().find(|(_, set, read, _)| *set && !*read) {
        Some((key, _, _, needs)) => Err(SceneError::invalid(
            *key,
            format!("has no effect here: it is read only with {needs}; drop it, or set that"),
        )),
        None => Ok(()),
    }
}

fn bname_key(bname: &str) -> String {
    format!("bodies.{bname}")
}

/// Rectangles may touch but not overlap (overlaps would double the mass).
fn check_rect_overlaps(file: &SceneFile) -> Result<(), SceneError> {
    let rects: Vec<(String, [f64; 4])> = file
        .bodies
        .iter()
        .flat_map(|(n, b)| {
            b.rects
                .iter()
                .enumerate()
                .map(move |(i, r)| (format!("bodies.{n}.rects[{i}]"), *r))
        })
        .collect();
    for (i, (ka, a)) in rects.iter().enumerate() {
        for (kb, b) in &rects[i + 1..] {
            let ox = a[2].min(b[2]) - a[0].max(b[0]);
            let oy = a[3].min(b[3]) - a[1].max(b[1]);
            if ox > 0.0 && oy > 0.0 {
                let over = [
                    a[0].max(b[0]),
                    a[1].max(b[1]),
                    a[2].min(b[2]),
                    a[3].min(b[3]),
                ];
                return Err(SceneError::invalid(
                    ka.clone(),
                    format!(
                        "overlaps {kb} over [{}, {}, {}, {}]: rectangles may touch but not overlap",
                        over[0], over[1], over[2], over[3]
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Shapes of different bodies may touch but not overlap, whatever their
/// kinds: the seeder gives a point inside both to the shape seeded first,
/// so the other body would lose the overlap in silence. (Rectangles
/// against rectangles are `check_rect_overlaps`'; a body's own disks and
/// polygons may overlap each other and its rectangles: the first claims
/// the points.)
fn check_body_overlaps(file: &SceneFile) -> Result<(), SceneError> {
    use super::overlap::{Shape, overlap};
    let tol = 1e-9 * file.grid.h;
    let mut shapes: Vec<(usize, String, Shape, [f64; 4])> = Vec::new();
    for (bi, (n, b)) in file.bodies.iter().enumerate() {
        let mut add = |kind: &str, i: usize, s: Shape| {
            let bb = match &s {
                Shape::Rect(r) => *r,
                Shape::Disk(d) => super::seed::disk_bbox(*d),
                Shape::Polygon(p) => super::seed::polygon_bbox(p),
            };
            shapes.push((bi, format!("bodies.{n}.{kind}[{i}]"), s, bb));
        };
        b.rects
            .iter()
            .enumerate()
            .for_each(|(i, r)| add("rects", i, Shape::Rect(*r)));
        b.disks
            .iter()
            .enumerate()
            .for_each(|(i, d)| add("disks", i, Shape::Disk(*d)));
        b.polygons
            .iter()
            .enumerate()
            .for_each(|(i, p)| add("polygons", i, Shape::Polygon(p.clone())));
    }
    for (i, (ba, ka, a, bba)) in shapes.iter().enumerate() {
        for (bb_, kb, b, bbb) in &shapes[i + 1..] {
            let rects = matches!((a, b), (Shape::Rect(_), Shape::Rect(_)));
            let apart = bba[2].min(bbb[2]) - bba[0].max(bbb[0]) <= tol
                || bba[3].min(bbb[3]) - bba[1].max(bbb[1]) <= tol;
            if ba == bb_ || rects || apart {
                continue;
            }
            if let Some((x, depth)) = overlap(a, b, tol) {
                let deep = depth.map_or(String::new(), |d| format!(", {d:.6} m deep"));
                return Err(SceneError::invalid(
                    ka.clone(),
                    format!(
                        "overlaps {kb}, a shape of another body, at ({:.6}, {:.6}){deep}: \
                         shapes of different bodies may touch but not overlap (the overlap \
                         would be cut from one of them)",
                        x[0], x[1]
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn check_manufactured(file: &SceneFile, m: &ManufacturedSpec) -> Result<(), SceneError> {
    let mat = file.materials.values().collect::<Vec<_>>();
    if mat.len() != 1 || mat[0].model != "neo_hookean" {
        return Err(SceneError::invalid(
            "manufactured",
            "needs exactly one material, of model \"neo_hookean\" (the solution is derived for it)",
        ));
    }
    let rects: Vec<&[f64; 4]> = file.bodies.values().flat_map(|b| b.rects.iter()).collect();
    let curved = file
        .bodies
        .values()
        .any(|b| !b.disks.is_empty() || !b.polygons.is_empty());
    let square = rects.len() == 1 && !curved && {
        let r = rects[0];
        ((r[2] - r[0]) - (r[3] - r[1])).abs() <= 1e-9 * (r[2] - r[0])
    };
    if !square {
        return Err(SceneError::invalid(
            "manufactured",
            "needs one body made of one square rect",
        ));
    }
    if file.gravity.as_ref().is_some_and(|g| g.g != [0.0, 0.0]) {
        return Err(SceneError::invalid(
            "manufactured",
            "needs no gravity (the body force is the solution's)",
        ));
    }
    if file.bodies.values().any(|b| b.velocity != [0.0, 0.0]) {
        return Err(SceneError::invalid(
            "manufactured",
            "sets the initial velocity itself: leave the bodies' velocity at [0, 0]",
        ));
    }
    let r = rects[0];
    let limit = (r[2] - r[0]) / (2.0 * std::f64::consts::PI);
    finite("manufactured.amplitude", m.amplitude)?;
    if !(m.amplitude > 0.0 && m.amplitude < limit) {
        return Err(SceneError::invalid(
            "manufactured.amplitude",
            format!(
                "must be in (0, L/(2π) = {limit:.4}) m so that det F stays positive, got {}",
                m.amplitude
            ),
        ));
    }
    Ok(())
}

fn check_exact(file: &SceneFile, kind: ExactKind) -> Result<(), SceneError> {
    let what = match kind {
        ExactKind::DykaBar => "dyka_bar",
        ExactKind::ElasticColumn => "elastic_column",
        ExactKind::AlignedVibration => return Ok(()),
        ExactKind::SlidingBlock => return check_sliding_block(file),
        ExactKind::RollingDisk => return check_rolling_disk(file),
        ExactKind::Cantilever => "cantilever",
        ExactKind::ContactSliding
        | ExactKind::ContactRolling
        | ExactKind::DiskImpact
        | ExactKind::PrandtlFooting => return check_pair_reference(file, kind),
        ExactKind::CriticalState => return check_critical_state(file),
        ExactKind::ColumnCollapse | ExactKind::GranularCollapse => {
            return check_collapse(file, kind);
        }
        ExactKind::Energy => return check_energy(file),
        ExactKind::Terzaghi => return check_terzaghi(file),
        ExactKind::Mandel => return check_mandel(file),
    };
    if file.materials.len() != 1 {
        return Err(SceneError::invalid(
            "exact",
            format!(
                "= \"{what}\" needs exactly one material, the scene has {}",
                file.materials.len()
            ),
        ));
    }
    let m = file.materials.values().next().expect("one material");
    if m.get("E").is_none() {
        return Err(SceneError::invalid(
            "exact",
            format!(
                "= \"{what}\" is scored by an elastic solution and needs a material with Young's modulus E (model = \"{}\" has none)",
                m.model
            ),
        ));
    }
    let nu = m.get("nu");
    if nu != Some(0.0) {
        return Err(SceneError::invalid(
            "exact",
            format!(
                "= \"{what}\" is scored by a 1D (bar or beam) solution and needs nu = 0 (plane strain then has no lateral coupling), got nu = {}",
                nu.map_or("none".to_string(), |v| v.to_string())
            ),
        ));
    }
    if file
        .bodies
        .values()
        .any(|b| !b.disks.is_empty() || !b.polygons.is_empty())
    {
        return Err(SceneError::invalid(
            "exact",
            format!("= \"{what}\" needs bodies made of rects only"),
        ));
    }
    match kind {
        ExactKind::AlignedVibration
        | ExactKind::SlidingBlock
        | ExactKind::RollingDisk
        | ExactKind::ContactSliding
        | ExactKind::ContactRolling
        | ExactKind::DiskImpact
        | ExactKind::PrandtlFooting
        | ExactKind::CriticalState
        | ExactKind::ColumnCollapse
        | ExactKind::GranularCollapse
        | ExactKind::Energy
        | ExactKind::Terzaghi
        | ExactKind::Mandel => {}
        ExactKind::DykaBar => {
            if file.gravity.as_ref().is_some_and(|g| g.g != [0.0, 0.0]) {
                return Err(SceneError::invalid(
                    "exact",
                    "= \"dyka_bar\" needs no gravity",
                ));
            }
            if file.bodies.values().any(|b| b.velocity[1] != 0.0) {
                return Err(SceneError::invalid(
                    "exact",
                    "= \"dyka_bar\" needs horizontal initial velocities",
                ));
            }
        }
        ExactKind::Cantilever => {
            let ok = file
                .gravity
                .as_ref()
                .is_some_and(|g| g.g[0] == 0.0 && g.g[1] < 0.0);
            if !ok {
                return Err(SceneError::invalid(
                    "exact",
                    "= \"cantilever\" needs gravity along -y (gravity.g = [0, -g])",
                ));
            }
        }
        ExactKind::ElasticColumn => {
            let ok = file
                .gravity
                .as_ref()
                .is_some_and(|g| g.g[0] == 0.0 && g.g[1] < 0.0);
            if !ok {
                return Err(SceneError::invalid(
                    "exact",
                    "= \"elastic_column\" needs gravity along -y (gravity.g = [0, -g])",
                ));
            }
            if file.bodies.values().any(|b| b.velocity != [0.0, 0.0]) {
                return Err(SceneError::invalid(
                    "exact",
                    "= \"elastic_column\" needs bodies at rest",
                ));
            }
        }
    }
    Ok(())
}

/// `exact = "sliding_block"`: one slip or friction wall, gravity, bodies
/// at rest, no other loads or constraints.
fn check_sliding_block(file: &SceneFile) -> Result<(), SceneError> {
    let fail = |why: &str| {
        Err(SceneError::invalid(
            "exact",
            format!("= \"sliding_block\" needs {why}"),
        ))
    };
    if file.walls.len() != 1 || file.walls.values().any(|w| w.contact == Contact::Stick) {
        return fail("exactly one wall, with contact = \"slip\" or \"friction\"");
    }
    if !file.gravity.as_ref().is_some_and(|g| g.g != [0.0, 0.0]) {
        return fail("gravity");
    }
    if file.bodies.values().any(|b| b.velocity != [0.0, 0.0]) {
        return fail("bodies at rest");
    }
    if !(file.constraints.is_empty() && file.tractions.is_empty() && file.point_loads.is_empty()) {
        return fail("no constraints, tractions or point loads (gravity and the wall only)");
    }
    Ok(())
}

/// The `exact` value's name as a scene writes it.
fn exact_name(kind: ExactKind) -> String {
    serde_json::to_value(kind)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// The references on a contact pair (`contact_sliding`, `contact_rolling`,
/// `disk_impact`, `prandtl_footing`): one pair, and what each reads of it.
fn check_pair_reference(file: &SceneFile, kind: ExactKind) -> Result<(), SceneError> {
    let name = exact_name(kind);
    let bad = |msg: String| Err(SceneError::invalid("exact", format!("= \"{name}\" {msg}")));
    if file.contact.len() != 1 {
        return bad(format!(
            "needs exactly one [contact.<name>] pair, the scene has {}",
            file.contact.len()
        ));
    }
    let pair = file.contact.values().next().expect("one pair");
    let (Some(first), Some(second)) = (
        file.bodies.get(&pair.bodies[0]),
        file.bodies.get(&pair.bodies[1]),
    ) else {
        // check_contact names the missing body.
        return Ok(());
    };
    let rects = |b: &BodySpec| !b.rects.is_empty() && b.disks.is_empty() && b.polygons.is_empty();
    let one_disk = |b: &BodySpec| b.disks.len() == 1 && b.rects.is_empty() && b.polygons.is_empty();
    let gravity = file.gravity.as_ref().is_some_and(|g| g.g != [0.0, 0.0]);
    match kind {
        ExactKind::ContactSliding | ExactKind::ContactRolling => {
            let roll = kind == ExactKind::ContactRolling;
            if roll && !one_disk(first) {
                return bad(
                    "needs the pair's first body made of one disk (the rolling disk)".into(),
                );
            }
            if !roll && !rects(first) {
                return bad("needs the pair's first body (the sliding one) made of rects".into());
            }
            if !rects(second) {
                return bad(
                    "needs the pair's second body (the one slid or rolled on) made of rects".into(),
                );
            }
            if !gravity {
                return bad("needs gravity".into());
            }
            if first.velocity != [0.0, 0.0] {
                return bad("needs the pair's first body at rest".into());
            }
            if roll && pair.law == Contact::Slip {
                return bad(
                    "needs law = \"friction\" or \"stick\": a disk on a slip pair slides".into(),
                );
            }
            if roll
                && file
                    .gravity
                    .as_ref()
                    .is_some_and(|g| g.ramp != crate::scene::schema::Ramp::None)
            {
                return bad("needs constant gravity (gravity.ramp = \"none\")".into());
            }
        }
        ExactKind::DiskImpact => {
            if !(one_disk(first) && one_disk(second)) {
                return bad("needs the pair's two bodies made of one disk each".into());
            }
            if pair.law != Contact::Slip {
                return bad("needs a frictionless pair (law = \"slip\")".into());
            }
            if gravity || !file.tractions.is_empty() || !file.point_loads.is_empty() {
                return bad("needs no gravity, tractions or point loads (momentum is kept)".into());
            }
        }
        _ => {
            if !rects(first) {
                return bad("needs the pair's first body (the footing) made of rects".into());
            }
            let soil = file.materials.get(&second.material);
            let tresca = soil.is_some_and(|m| {
                m.get("cohesion").is_some_and(|c| c > 0.0)
                    && m.get("friction_angle").unwrap_or(0.0) == 0.0
            });
            if !tresca {
                return bad(
                    "needs the pair's second body (the soil) of a material with cohesion > 0 and friction_angle = 0 (Tresca): Prandtl's (2 + pi) c is for that soil".into(),
                );
            }
            if first.velocity == [0.0, 0.0] {
                return bad(
                    "needs the footing's velocity into the soil (bodies.<footing>.velocity)".into(),
                );
            }
        }
    }
    Ok(())
}

/// `exact = "critical_state"`: a modified Cam-clay material.
/// `exact = "terzaghi"`: one body of one rect (the layer), one saturated
/// linear-elastic material, one traction along the layer's top, normal to it.
fn check_terzaghi(file: &SceneFile) -> Result<(), SceneError> {
    let bad = |msg: &str| {
        Err(SceneError::invalid(
            "exact",
            format!("= \"terzaghi\" {msg}"),
        ))
    };
    let rect = match file.bodies.values().collect::<Vec<_>>().as_slice() {
        [b] if b.rects.len() == 1 && b.disks.is_empty() && b.polygons.is_empty() => b.rects[0],
        _ => return bad("needs one body made of one rect (the layer)"),
    };
    match file.materials.values().collect::<Vec<_>>().as_slice() {
        [m] if m.model == "linear_elastic" && m.get("permeability").is_some() => {}
        _ => return bad("needs one material, linear_elastic with `permeability` (saturated)"),
    }
    let traction = match file.tractions.values().collect::<Vec<_>>().as_slice() {
        [] => false,
        [t] if t.from[1] == rect[3]
            && t.to[1] == rect[3]
            && t.traction[0] == 0.0
            && t.traction[1] < 0.0 =>
        {
            true
        }
        _ => return bad("needs one traction [0, -p0] along the layer's top (y = its rect's ymax)"),
    };
    let platen = match file.platens.values().collect::<Vec<_>>().as_slice() {
        [] => false,
        [p] if p.axis == Axis::Y && p.force < 0.0 && p.ramp_time == 0.0 && p.min[1] >= rect[3] => {
            true
        }
        _ => {
            return bad(
                "takes one [platens.<name>] along y at the layer's top (min y >= its rect's ymax), \
                 loaded by a sudden force < 0 (-p0 times the layer's width, N/m)",
            );
        }
    };
    if traction == platen || !file.point_loads.is_empty() {
        return bad(
            "is loaded once: by one traction [0, -p0] along its top or by one platen there \
             (no [point_loads])",
        );
    }
    if file.drainage.is_empty() {
        return bad("needs a [drainage.<name>] region at the layer's top");
    }
    Ok(())
}

/// `exact = "mandel"`: the quarter specimen, one rect from [0, 0] (the
/// symmetry planes), one saturated linear-elastic material, one platen
/// on its top loaded by −F, no other load, and a drained region.
fn check_mandel(file: &SceneFile) -> Result<(), SceneError> {
    let bad = |msg: &str| Err(SceneError::invalid("exact", format!("= \"mandel\" {msg}")));
    let rect = match file.bodies.values().collect::<Vec<_>>().as_slice() {
        [b] if b.rects.len() == 1 && b.disks.is_empty() && b.polygons.is_empty() => b.rects[0],
        _ => return bad("needs one body made of one rect (the quarter specimen)"),
    };
    if rect[0] != 0.0 || rect[1] != 0.0 {
        return bad(
            "models the quarter x >= 0, y >= 0: the rect must start at [0, 0] (the symmetry planes)",
        );
    }
    match file.materials.values().collect::<Vec<_>>().as_slice() {
        [m] if m.model == "linear_elastic" && m.get("permeability").is_some() => {}
        _ => return bad("needs one material, linear_elastic with `permeability` (saturated)"),
    }
    match file.platens.values().collect::<Vec<_>>().as_slice() {
        [p] if p.axis == Axis::Y && p.force < 0.0 && p.ramp_time == 0.0 && p.min[1] >= rect[3] => {}
        _ => {
            return bad(
                "needs one [platens.<name>] along y at the specimen's top (min y >= its rect's ymax), \
                 loaded by a sudden force < 0 (-F, N/m, on the half-width a)",
            );
        }
    }
    if !file.tractions.is_empty() || !file.point_loads.is_empty() {
        return bad("loads the specimen through its platen only (no [tractions] or [point_loads])");
    }
    if file.drainage.is_empty() {
        return bad("needs a [drainage.<name>] region at the side x = a");
    }
    Ok(())
}

fn check_critical_state(file: &SceneFile) -> Result<(), SceneError> {
    if !file
        .materials
        .values()
        .any(|m| m.model == "modified_cam_clay")
    {
        return Err(SceneError::invalid(
            "exact",
            "= \"critical_state\" needs a material with model = \"modified_cam_clay\" (its M is the reference)",
        ));
    }
    Ok(())
}

/// The column `exact = "column_collapse"`'s reference figures are for,
/// `[xmin, ymin, xmax, ymax]` (m): cases/column_collapse.toml's.
pub const COLUMN_COLLAPSE_RECT: [f64; 4] = [0.0, 0.0, 2.0, 4.0];

/// `exact = "column_collapse"` / `"granular_collapse"`: one body, one rect
/// from x = 0 (the back wall), gravity along −y.
fn check_collapse(file: &SceneFile, kind: ExactKind) -> Result<(), SceneError> {
    let name = exact_name(kind);
    let bad = |msg: String| Err(SceneError::invalid("exact", format!("= \"{name}\" {msg}")));
    let rect = match file.bodies.values().collect::<Vec<_>>().as_slice() {
        [b] if b.rects.len() == 1 && b.disks.is_empty() && b.polygons.is_empty() => b.rects[0],
        _ => return bad("needs one body made of one rect (the column)".into()),
    };
    if rect[0] != 0.0 {
        return bad(format!(
            "measures the run-out from x = 0, the back wall: the column must start there (its rect starts at x = {})",
            rect[0]
        ));
    }
    if !file
        .gravity
        .as_ref()
        .is_some_and(|g| g.g[0] == 0.0 && g.g[1] < 0.0)
    {
        return bad("needs gravity along -y (gravity.g = [0, -g])".into());
    }
    if kind == ExactKind::ColumnCollapse && rect != COLUMN_COLLAPSE_RECT {
        return bad(format!(
            "compares with `study column`'s figures for the 2 m x 4 m column of cases/column_collapse.toml (rect [0, 0, 2, 4]), got {rect:?}; exact = \"granular_collapse\" scales with any column"
        ));
    }
    Ok(())
}

/// `exact = "energy"`: nothing that does work on the bodies.
fn check_energy(file: &SceneFile) -> Result<(), SceneError> {
    let bad = |what: &str| {
        Err(SceneError::invalid(
            "exact",
            format!("= \"energy\" needs nothing doing work on the bodies: remove {what}"),
        ))
    };
    if file.gravity.as_ref().is_some_and(|g| g.g != [0.0, 0.0]) {
        return bad("gravity");
    }
    if !file.tractions.is_empty() || !file.point_loads.is_empty() {
        return bad("the tractions and point loads");
    }
    if file.constraints.values().any(|c| c.velocity != [0.0, 0.0]) {
        return bad("the prescribed velocities (constraints' velocity)");
    }
    if !file.walls.is_empty() {
        return bad("the walls (their contact forces do work)");
    }
    if file.platens.values().any(|p| p.force != 0.0) {
        return bad("the platens' loads");
    }
    if file.manufactured.is_some() {
        return bad("[manufactured] (its body force does work)");
    }
    Ok(())
}

/// `exact = "rolling_disk"`: one body made of one disk, at rest, one wall,
/// constant gravity with a component along the wall.
fn check_rolling_disk(file: &SceneFile) -> Result<(), SceneError> {
    let bad = |msg: &str| {
        Err(SceneError::invalid(
            "exact",
            format!("= \"rolling_disk\" {msg}"),
        ))
    };
    let one_disk = file.bodies.len() == 1
        && file
            .bodies
            .values()
            .all(|b| b.disks.len() == 1 && b.rects.is_empty() && b.polygons.is_empty());
    if !one_disk {
        return bad("needs one body made of one disk");
    }
    if file.bodies.values().any(|b| b.velocity != [0.0, 0.0]) {
        return bad("needs the disk at rest");
    }
    if file.walls.len() != 1 {
        return bad(&format!(
            "needs exactly one wall (the plane), the scene has {}",
            file.walls.len()
        ));
    }
    if file.walls.values().any(|w| w.contact == Contact::Slip) {
        return bad("needs a `stick` or `friction` wall: a disk on a slip wall slides");
    }
    let Some(g) = file.gravity.as_ref() else {
        return bad("needs gravity");
    };
    if g.ramp != crate::scene::schema::Ramp::None {
        return bad("needs constant gravity (ramp = \"none\")");
    }
    let w = file.walls.values().next().expect("one wall");
    let nn = w.normal[0].hypot(w.normal[1]);
    let along = (g.g[0] * w.normal[1] - g.g[1] * w.normal[0]).abs() / nn.max(f64::MIN_POSITIVE);
    if along <= 1e-12 * g.g[0].hypot(g.g[1]) {
        return bad("needs gravity with a component along the wall");
    }
    Ok(())
}
