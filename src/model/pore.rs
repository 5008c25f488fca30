//! Saturated soil (u–p): a material with `permeability` is a mixture of a
//! skeleton and pore water. The particles carry the pore pressure p (Pa,
//! compression positive); the material's model acts on the effective stress
//! σ' = σ + p I, the momentum is the mixture's (total stress σ = σ' − p I,
//! the material's `density` the saturated one), and p follows the fluid's
//! mass balance with incompressible grains and Darcy flow,
//! (n / K_w) ṗ = −∇·v − ∇·w,  w = −(k / γ_w) (∇p − ρ_w b),
//! k Darcy's hydraulic conductivity (m/s), γ_w = ρ_w · 9.81 m/s² (the
//! standard gravity k is measured with), b the scene's gravity.
//! The CPU pass is `cpu::pore_flow`; docs/methods.md, "Saturated soil".

use super::Grid;
use crate::error::SceneError;
use crate::scene::{MaterialSpec, Scene};

/// Standard gravity (m/s²): γ_w = ρ_w · G_STANDARD whatever the scene's
/// gravity, as soil data give k.
pub const G_STANDARD: f64 = 9.81;

/// The material keys of the pore fluid, with their units (a material with
/// `permeability` is saturated).
pub const KEYS: &[(&str, &str)] = &[
    ("permeability", "m/s"),
    ("porosity", "-"),
    ("fluid_bulk", "Pa"),
    ("fluid_density", "kg/m³"),
];

/// Default bulk modulus of water K_w (Pa).
pub const WATER_BULK: f64 = 2.2e9;
/// Default density of water ρ_w (kg/m³).
pub const WATER_DENSITY: f64 = 1000.0;

/// Safety factor on the flow's explicit limit h² S / (4 κ) (S = n / K_w,
/// κ = k / γ_w): the forward-Euler limit of the nodal diffusion on a
/// lumped capacity, halved for the wider stencils of B-splines and LME.
pub const FLOW_SAFETY: f64 = 0.5;

/// One saturated material's pore fluid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fluid {
    /// Hydraulic conductivity k (m/s).
    pub k: f64,
    /// Porosity n.
    pub n: f64,
    /// Fluid bulk modulus K_w (Pa).
    pub kw: f64,
    /// Fluid density ρ_w (kg/m³).
    pub rho_w: f64,
}

impl Fluid {
    /// κ = k / γ_w (m²/(Pa·s)): Darcy's flux per unit pressure gradient.
    pub fn mobility(&self) -> f64 {
        self.k / (self.rho_w * G_STANDARD)
    }

    /// S = n / K_w (1/Pa): the pore volume's storage per unit pressure.
    pub fn storage(&self) -> f64 {
        self.n / self.kw
    }

    /// K_w / n (Pa): the fluid's share of the undrained P-wave modulus,
    /// c² = (M + K_w / n) / ρ.
    pub fn undrained_modulus(&self) -> f64 {
        1.0 / self.storage()
    }

    /// The flow's explicit time-step limit (s) on spacing `h` (m):
    /// `FLOW_SAFETY` · h² S / (4 κ); ∞ where impermeable.
    pub fn flow_dt(&self, h: f64) -> f64 {
        if self.k > 0.0 {
            FLOW_SAFETY * h * h * self.storage() / (4.0 * self.mobility())
        } else {
            f64::INFINITY
        }
    }

    /// The pore fluid of material `name`, or None for a dry one; bad
    /// values exit 2 naming the key.
    pub fn from_spec(name: &str, spec: &MaterialSpec) -> Result<Option<Fluid>, SceneError> {
        let key = |k: &str| format!("materials.{name}.{k}");
        let Some(k) = spec.get("permeability") else {
            if let Some((other, _)) = KEYS[1..].iter().find(|(k, _)| spec.get(k).is_some()) {
                return Err(SceneError::invalid(
                    key(other),
                    "belongs to a saturated material: give `permeability` (m/s) too",
                ));
            }
            return Ok(None);
        };
        if !(k >= 0.0 && k.is_finite()) {
            return Err(SceneError::invalid(
                key("permeability"),
                format!("must be a finite k ≥ 0 (m/s), got {k}"),
            ));
        }
        let n = spec.get("porosity").ok_or_else(|| {
            SceneError::invalid(
                key("porosity"),
                "is required with `permeability`: the porosity n, in (0, 1)",
            )
        })?;
        if !(n > 0.0 && n < 1.0) {
            return Err(SceneError::invalid(
                key("porosity"),
                format!("must be in (0, 1), got {n}"),
            ));
        }
        let kw = spec.get("fluid_bulk").unwrap_or(WATER_BULK);
        if !(kw > 0.0 && kw.is_finite()) {
            return Err(SceneError::invalid(
                key("fluid_bulk"),
                format!("must be a finite K_w > 0 (Pa), got {kw}"),
            ));
        }
        let rho_w = spec.get("fluid_density").unwrap_or(WATER_DENSITY);
        if !(rho_w > 0.0 && rho_w.is_finite()) {
            return Err(SceneError::invalid(
                key("fluid_density"),
                format!("must be a finite ρ_w > 0 (kg/m³), got {rho_w}"),
            ));
        }
        Ok(Some(Fluid { k, n, kw, rho_w }))
    }
}

/// A drained boundary: the nodes of a region and the pore pressure held there.
#[derive(Debug, Clone, PartialEq)]
pub struct Drain {
    pub name: String,
    pub nodes: Vec<u32>,
    /// Pa.
    pub pressure: f64,
    /// Where the region is a half-plane (one finite bound): its nodes
    /// beyond the face row (the drained nodes nearest the soil), each
    /// with its mirror image across that row, an undrained node. The flow
    /// gives a ghost 2 p_D − p_mirror (and −Δp_mirror), so the pressure a
    /// B-spline or LME stencil interpolates on the face row is p_D, as a
    /// linear stencil's is (`cpu::pore_flow`).
    pub ghosts: Vec<(u32, u32)>,
}

/// `Drain::ghosts` of the region [min, max] whose nodes are `drained`
/// (every drain's, by node): none unless exactly one bound is finite.
fn ghosts(
    grid: &Grid,
    min: [f64; 2],
    max: [f64; 2],
    nodes: &[u32],
    drained: &[bool],
) -> Vec<(u32, u32)> {
    let finite: Vec<(usize, bool)> = (0..2)
        .flat_map(|a| [(a, true, min[a]), (a, false, max[a])])
        .filter(|b| b.2.is_finite())
        .map(|b| (b.0, b.1))
        .collect();
    let [(axis, lower)] = finite[..] else {
        return Vec::new();
    };
    let ij = |n: u32| {
        let n = n as usize;
        [n % grid.nx, n / grid.nx]
    };
    let along = nodes.iter().map(|&n| ij(n)[axis]);
    // The face row: the drained nodes nearest the soil.
    let face = if lower { along.min() } else { along.max() };
    let Some(face) = face else { return Vec::new() };
    let len = [grid.nx, grid.ny][axis];
    nodes
        .iter()
        .filter_map(|&n| {
            let mut c = ij(n);
            let k = c[axis].abs_diff(face);
            if k == 0 {
                return None;
            }
            let m = if lower {
                face.checked_sub(k)?
            } else {
                face + k
            };
            if m >= len {
                return None;
            }
            c[axis] = m;
            let mirror = grid.index(c[0], c[1]);
            (!drained[mirror]).then_some((n, mirror as u32))
        })
        .collect()
}

/// The scene's pore fluid: per material (None: dry) and the drained nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct Pore {
    pub fluid: Vec<Option<Fluid>>,
    pub drains: Vec<Drain>,
    /// Per body (`Scene::bodies()` order): its `water_table` (m), above
    /// which its particles (by their start) are dry.
    pub tables: Vec<Option<f64>>,
    /// The volumetric term of the mass balance on the nodes with the
    /// flow (`solver.pore_volumetric = "nodal"`, the stabilised default),
    /// or at each particle (`"particle"`: equal-order, which oscillates).
    pub nodal_volumetric: bool,
}

impl Pore {
    /// The scene's pore fluid, or None when no material is saturated
    /// (then nothing in a step changes: a dry scene runs as before).
    pub fn from_scene(scene: &Scene, grid: &Grid) -> Result<Option<Pore>, SceneError> {
        let f = &scene.file;
        let fluid = f
            .materials
            .iter()
            .map(|(name, spec)| Fluid::from_spec(name, spec))
            .collect::<Result<Vec<_>, _>>()?;
        let needs_fluid = |key: String| {
            Err(SceneError::invalid(
                key,
                "needs a saturated material (one with `permeability`)",
            ))
        };
        let mut tables = Vec::new();
        for (name, b) in scene.bodies() {
            let saturated = f
                .materials
                .keys()
                .position(|m| *m == b.material)
                .is_some_and(|m| fluid[m].is_some());
            if b.water_table.is_some() && !saturated {
                return needs_fluid(format!("bodies.{name}.water_table"));
            }
            tables.push(b.water_table);
        }
        if fluid.iter().all(Option::is_none) {
            if let Some(name) = f.drainage.keys().next() {
                return Err(SceneError::invalid(
                    format!("drainage.{name}"),
                    "needs a saturated material (one with `permeability`)",
                ));
            }
            if f.solver.pore_volumetric.is_some() {
                return Err(SceneError::invalid(
                    "solver.pore_volumetric",
                    "needs a saturated material (one with `permeability`)",
                ));
            }
            return Ok(None);
        }
        refuse_unsupported(scene)?;
        let mut drains = Vec::new();
        for (name, d) in &f.drainage {
            if !d.pressure.is_finite() {
                return Err(SceneError::invalid(
                    format!("drainage.{name}.pressure"),
                    format!("must be finite (Pa), got {}", d.pressure),
                ));
            }
            let nodes: Vec<u32> = grid
                .region(d.min, d.max)
                .map(|(i, j)| grid.index(i, j) as u32)
                .collect();
            if nodes.is_empty() {
                return Err(SceneError::invalid(
                    format!("drainage.{name}"),
                    "matches no grid node".to_string(),
                ));
            }
            drains.push(Drain {
                name: name.clone(),
                nodes,
                pressure: d.pressure,
                ghosts: Vec::new(),
            });
        }
        let mut drained = vec![false; grid.n_nodes()];
        for d in &drains {
            for &n in &d.nodes {
                drained[n as usize] = true;
            }
        }
        for (d, spec) in drains.iter_mut().zip(f.drainage.values()) {
            d.ghosts = ghosts(grid, spec.min, spec.max, &d.nodes, &drained);
        }
        Ok(Some(Pore {
            fluid,
            drains,
            tables,
            nodal_volumetric: f.solver.pore_volumetric.unwrap_or_default()
                == crate::scene::PoreVolumetric::Nodal,
        }))
    }

    /// The fluid of a particle of material `material` and body `body` that
    /// started at height `y0` (m): its material's, unless the body has a
    /// water table at or below y0 (then it is dry).
    #[inline]
    pub fn particle_fluid(&self, material: usize, body: usize, y0: f64) -> Option<Fluid> {
        let f = self.fluid[material]?;
        match self.tables[body] {
            Some(table) if y0 >= table => None,
            _ => Some(f),
        }
    }

    /// `Fluid::undrained_modulus` of material `m` (0 where it is dry).
    pub fn undrained_modulus(&self, m: usize) -> f64 {
        self.fluid[m].map_or(0.0, |f| f.undrained_modulus())
    }

    /// The smallest `Fluid::flow_dt` over the saturated materials (s).
    pub fn flow_dt(&self, h: f64) -> f64 {
        self.fluid
            .iter()
            .flatten()
            .map(|f| f.flow_dt(h))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether every drainage region reaches a saturated particle: a
    /// node of it in the cell of such a particle or in a cell next to it.
    /// Names the first that reaches none.
    pub fn check_reached(
        &self,
        grid: &Grid,
        x: &[[f64; 2]],
        saturated: impl Fn(usize) -> bool,
    ) -> Result<(), SceneError> {
        let mut near = vec![false; grid.n_nodes()];
        for p in (0..x.len()).filter(|&p| saturated(p)) {
            let l = grid.logical(x[p]);
            let (ci, cj) = (l[0].floor() as i64, l[1].floor() as i64);
            for j in cj - 1..=cj + 2 {
                for i in ci - 1..=ci + 2 {
                    if i >= 0 && j >= 0 && (i as usize) < grid.nx && (j as usize) < grid.ny {
                        near[grid.index(i as usize, j as usize)] = true;
                    }
                }
            }
        }
        for d in &self.drains {
            if !d.nodes.iter().any(|&n| near[n as usize]) {
                return Err(SceneError::invalid(
                    format!("drainage.{}", d.name),
                    "touches no particle of a saturated material (none in a cell next to its nodes)",
                ));
            }
        }
        Ok(())
    }
}

/// What saturated soil does not run with yet: exit 2 naming the key.
fn refuse_unsupported(scene: &Scene) -> Result<(), SceneError> {
    use crate::scene::IntegratorKind;
    let f = &scene.file;
    let why = |key: &str, what: &str| {
        Err(SceneError::invalid(
            key,
            format!("saturated soil (a material with `permeability`) runs {what}"),
        ))
    };
    match f.solver.integrator {
        IntegratorKind::Fe | IntegratorKind::Npc => {}
        _ => {
            return why(
                "solver.integrator",
                "with \"npc\" or \"fe\" only (not yet implicit or MUSL)",
            );
        }
    }
    if f.solver.mls {
        return why("solver.mls", "without MLS");
    }
    if !f.contact.is_empty() {
        return why("contact", "without contact pairs (not yet)");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drained_of(grid: &Grid, min: [f64; 2], max: [f64; 2]) -> (Vec<u32>, Vec<bool>) {
        let nodes: Vec<u32> = grid
            .region(min, max)
            .map(|(i, j)| grid.index(i, j) as u32)
            .collect();
        let mut drained = vec![false; grid.n_nodes()];
        nodes.iter().for_each(|&n| drained[n as usize] = true);
        (nodes, drained)
    }

    /// A half-plane's nodes beyond its face row mirror across it; a box
    /// (two finite bounds) has no ghosts.
    #[test]
    fn ghosts_mirror_a_half_plane_across_its_face_row() {
        let grid = Grid::regular(0.5, [0.0, 0.0], 4, 6); // y = 0 … 2.5
        let (min, max) = ([f64::NEG_INFINITY, 1.5], [f64::INFINITY; 2]);
        let (nodes, drained) = drained_of(&grid, min, max);
        let g = ghosts(&grid, min, max, &nodes, &drained);
        // Rows 4 and 5 (y = 2, 2.5) mirror rows 2 and 1 across row 3.
        assert_eq!(g.len(), 2 * grid.nx);
        for (ghost, mirror) in g {
            let (gi, gj) = (ghost as usize % grid.nx, ghost as usize / grid.nx);
            let (mi, mj) = (mirror as usize % grid.nx, mirror as usize / grid.nx);
            assert_eq!(gi, mi);
            assert_eq!(gj - 3, 3 - mj);
        }
        // Drained for x ≥ 1: column 3 mirrors column 1 across column 2.
        let (min, max) = ([1.0, f64::NEG_INFINITY], [f64::INFINITY; 2]);
        let (nodes, drained) = drained_of(&grid, min, max);
        let g = ghosts(&grid, min, max, &nodes, &drained);
        assert_eq!(g.len(), grid.ny);
        assert!(
            g.iter()
                .all(|&(a, b)| a as usize % grid.nx == 3 && b as usize % grid.nx == 1)
        );
        let (min, max) = ([1.0, 1.0], [f64::INFINITY, 2.0]);
        let (nodes, drained) = drained_of(&grid, min, max);
        assert!(ghosts(&grid, min, max, &nodes, &drained).is_empty());
    }
}
