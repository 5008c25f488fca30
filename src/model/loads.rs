//! Loads on the model that both backends apply: gravity with its time
//! history, and the body force of a manufactured solution (the 2D aligned
//! vibration of the B-spline paper), whose exact field also sets the
//! initial velocity. Scoring against that field is `exact::mms`.
//!
//! The manufactured 2D aligned vibration (B-spline paper, eq. 38, after
//! Sadeghirad et al. 2011) on a square of side L, Neo-Hookean:
//!   u(X, t) = A [sin(2πX/L) sin(cπt/L), sin(2πY/L) sin(cπt/L + π)],
//! c = sqrt(E/ρ0), X relative to the square's lower-left corner. F is
//! diagonal: F_xx = 1 + (2πA/L) cos(2πX/L) sin(cπt/L), likewise F_yy.
//!
//! Body force (derived here; the paper's eq. 42 prints π where π² belongs):
//! with P_xx = λ ln J / F_xx + μ (F_xx − 1/F_xx) and ∂F_xx/∂X = −(2π/L)² u_x,
//!   b_x = ü_x − (1/ρ0) ∂P_xx/∂X
//!       = (π² u_x / L²) [4μ/ρ0 − c² + 4 (λ (1 − ln J) + μ) / (ρ0 F_xx²)],
//! and b_y the same with y for x. The test `momentum_balance_holds`
//! checks it against finite differences of the exact fields.

use crate::error::SceneError;
use crate::model::Particles;
use crate::model::material::NeoHookean;
use crate::scene::{Ramp, Scene};
use std::f64::consts::PI;

/// Gravity with its time history.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gravity {
    /// Full value (m/s²).
    pub g: [f64; 2],
    pub ramp: Ramp,
    /// T of eq. 45 (s); unused without a ramp.
    pub period: f64,
}

impl Gravity {
    /// Gravity at time `t` (m/s²): paper eq. 45 with a sine ramp.
    pub fn at(&self, t: f64) -> [f64; 2] {
        let f = match self.ramp {
            Ramp::None => 1.0,
            Ramp::Sine if t <= 0.5 * self.period => {
                0.5 * ((2.0 * std::f64::consts::PI * t / self.period - std::f64::consts::FRAC_PI_2)
                    .sin()
                    + 1.0)
            }
            Ramp::Sine => 1.0,
        };
        [f * self.g[0], f * self.g[1]]
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct AlignedVibration {
    /// A (m).
    pub amplitude: f64,
    /// L (m).
    pub length: f64,
    /// c = sqrt(E/ρ0) (m/s).
    pub c: f64,
    /// Lower-left corner of the square (m).
    pub origin: [f64; 2],
    pub material: NeoHookean,
}

impl AlignedVibration {
    /// From a scene with `[manufactured]`: the square is the bodies' bounding
    /// box, the material its single (Neo-Hookean) material.
    pub fn from_scene(scene: &Scene) -> Option<AlignedVibration> {
        let spec = scene.file.manufactured.as_ref()?;
        let m = scene.materials().next()?.1;
        let bb = crate::scene::seed::bodies_bbox(scene);
        let (e, nu) = (m.get("E")?, m.get("nu")?);
        Some(AlignedVibration {
            amplitude: spec.amplitude,
            length: bb[2] - bb[0],
            c: (e / m.density).sqrt(),
            origin: [bb[0], bb[1]],
            material: NeoHookean::new(e, nu, m.density),
        })
    }

    fn k(&self) -> f64 {
        2.0 * PI / self.length
    }

    fn omega(&self) -> f64 {
        self.c * PI / self.length
    }

    /// Displacement at reference position `x` (m) and time `t` (s).
    pub fn displacement(&self, x: [f64; 2], t: f64) -> [f64; 2] {
        let (k, w) = (self.k(), self.omega());
        let (xx, yy) = (x[0] - self.origin[0], x[1] - self.origin[1]);
        [
            self.amplitude * (k * xx).sin() * (w * t).sin(),
            self.amplitude * (k * yy).sin() * (w * t + PI).sin(),
        ]
    }

    /// Velocity (m/s).
    pub fn velocity(&self, x: [f64; 2], t: f64) -> [f64; 2] {
        let (k, w) = (self.k(), self.omega());
        let (xx, yy) = (x[0] - self.origin[0], x[1] - self.origin[1]);
        [
            self.amplitude * w * (k * xx).sin() * (w * t).cos(),
            self.amplitude * w * (k * yy).sin() * (w * t + PI).cos(),
        ]
    }

    /// Deformation gradient [xx, xy, yx, yy] (diagonal).
    pub fn def_grad(&self, x: [f64; 2], t: f64) -> [f64; 4] {
        let (k, w) = (self.k(), self.omega());
        let (xx, yy) = (x[0] - self.origin[0], x[1] - self.origin[1]);
        let fxx = 1.0 + self.amplitude * k * (k * xx).cos() * (w * t).sin();
        let fyy = 1.0 + self.amplitude * k * (k * yy).cos() * (w * t + PI).sin();
        [fxx, 0.0, 0.0, fyy]
    }

    /// Cauchy stress [xx, yy, xy] (Pa).
    pub fn cauchy(&self, x: [f64; 2], t: f64) -> [f64; 3] {
        self.material
            .cauchy(&self.def_grad(x, t))
            .unwrap_or([f64::NAN; 3])
    }

    /// Body force per unit mass that makes the field a solution (m/s²).
    pub fn body_force(&self, x: [f64; 2], t: f64) -> [f64; 2] {
        let m = &self.material;
        let rho0 = m.density;
        let u = self.displacement(x, t);
        let f = self.def_grad(x, t);
        let lnj = (f[0] * f[3]).ln();
        let l2 = self.length * self.length;
        let common = 4.0 * m.shear / rho0 - self.c * self.c;
        let tail = 4.0 * (m.lame * (1.0 - lnj) + m.shear) / rho0;
        [
            PI * PI * u[0] / l2 * (common + tail / (f[0] * f[0])),
            PI * PI * u[1] / l2 * (common + tail / (f[3] * f[3])),
        ]
    }

    /// The most kinetic + stored energy (J/m) the exact field holds over one
    /// period 2L/c, on the particles' reference positions and masses (64
    /// instants). The body force feeds the field this energy and takes it
    /// back each period, so it is what a run may hold without running away.
    pub fn peak_energy(&self, p: &Particles) -> f64 {
        let period = 2.0 * self.length / self.c;
        (0..64)
            .map(|k| {
                let t = period * k as f64 / 64.0;
                (0..p.len())
                    .map(|i| {
                        let (x0, v) = (p.x0[i], self.velocity(p.x0[i], t));
                        let w = self.material.energy_density(&self.def_grad(x0, t));
                        let f = self.def_grad(x0, t);
                        let volume = p.mass[i] / self.material.density * (f[0] * f[3]);
                        0.5 * p.mass[i] * (v[0] * v[0] + v[1] * v[1]) + w * volume
                    })
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }
}

/// Linear ramp factor at time `t` (s) of a load or prescribed velocity
/// reaching full value at `ramp_time` (s); 0 = full from the start.
#[inline]
pub fn ramp_factor(t: f64, ramp_time: f64) -> f64 {
    if ramp_time > 0.0 {
        (t / ramp_time).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// Tractions and point loads as forces on particles (dead loads: fixed in
/// size and direction, carried by the same particles all run). Made only
/// when the scene has such loads.
#[derive(Debug, Clone, PartialEq)]
pub struct ExternalForces {
    /// Full force per particle (N per unit thickness); zero for most.
    pub force: Vec<[f64; 2]>,
    /// Its ramp time (s), 0 = sudden.
    pub ramp_time: Vec<f64>,
}

impl ExternalForces {
    /// Force on particle `p` at time `t` (N/m).
    #[inline]
    pub fn at(&self, p: usize, t: f64) -> [f64; 2] {
        let r = ramp_factor(t, self.ramp_time[p]);
        [r * self.force[p][0], r * self.force[p][1]]
    }

    /// The loads of `scene` on `particles` (initial positions), or None
    /// without `[tractions]` and `[point_loads]`.
    ///
    /// A traction on segment AB (length L) is carried by the layer of
    /// particles nearest the segment: among the particles whose projection
    /// on AB falls within it, those within `layer` (a quarter of the
    /// smallest particle spacing, h / (4 ppc)) of the nearest one. Each
    /// gets traction × the length of its share of AB: the half-way points
    /// between neighbours (sorted along AB) split it, the ends go to the
    /// first and last, so the shares add up to L exactly. A point load goes
    /// to the nearest particle.
    pub fn from_scene(
        scene: &Scene,
        particles: &Particles,
    ) -> Result<Option<ExternalForces>, SceneError> {
        let f = &scene.file;
        if f.tractions.is_empty() && f.point_loads.is_empty() {
            return Ok(None);
        }
        let h = f.grid.h;
        let n = particles.len();
        let ppc = scene.bodies().map(|(_, b)| b.ppc).max().unwrap_or(2) as f64;
        let layer = 0.25 * h / ppc;
        let mut out = ExternalForces {
            force: vec![[0.0; 2]; n],
            ramp_time: vec![0.0; n],
        };
        // Which load set each particle's ramp, to refuse two ramps on one particle.
        let mut owner: Vec<Option<String>> = vec![None; n];
        let mut add = |key: &str, p: usize, force: [f64; 2], ramp: f64| {
            if let Some(prev) = &owner[p] {
                if out.ramp_time[p] != ramp {
                    return Err(SceneError::invalid(
                        format!("{key}.ramp_time"),
                        format!(
                            "differs from that of `{prev}`, which loads the same particle at \
                             ({:.6}, {:.6}); give loads that meet the same ramp_time",
                            particles.x0[p][0], particles.x0[p][1]
                        ),
                    ));
                }
            }
            owner[p] = Some(key.to_string());
            out.ramp_time[p] = ramp;
            out.force[p][0] += force[0];
            out.force[p][1] += force[1];
            Ok(())
        };
        for (name, t) in &f.tractions {
            let key = format!("tractions.{name}");
            let (a, b) = (t.from, t.to);
            let d = [b[0] - a[0], b[1] - a[1]];
            let len = d[0].hypot(d[1]);
            let u = [d[0] / len, d[1] / len];
            // (particle, position along AB, distance to AB)
            let on: Vec<(usize, f64, f64)> = (0..n)
                .filter_map(|p| {
                    let x = particles.x0[p];
                    let r = [x[0] - a[0], x[1] - a[1]];
                    let s = r[0] * u[0] + r[1] * u[1];
                    let dist = (r[0] * u[1] - r[1] * u[0]).abs();
                    (s >= -1e-9 * h && s <= len + 1e-9 * h).then_some((p, s, dist))
                })
                .collect();
            let nearest = on.iter().map(|c| c.2).fold(f64::INFINITY, f64::min);
            if nearest.is_nan() || nearest > h {
                return Err(SceneError::invalid(
                    key,
                    format!(
                        "touches no particle: no particle lies within one cell (h = {h} m) of the \
                         segment {a:?} to {b:?}; put it on a body's boundary"
                    ),
                ));
            }
            let mut layer_p: Vec<(usize, f64)> = on
                .iter()
                .filter(|c| c.2 <= nearest + layer)
                .map(|c| (c.0, c.1))
                .collect();
            layer_p.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
            let k = layer_p.len();
            for i in 0..k {
                let lo = if i == 0 {
                    0.0
                } else {
                    0.5 * (layer_p[i - 1].1 + layer_p[i].1)
                };
                let hi = if i + 1 == k {
                    len
                } else {
                    0.5 * (layer_p[i].1 + layer_p[i + 1].1)
                };
                let share = hi - lo;
                add(
                    &key,
                    layer_p[i].0,
                    [t.traction[0] * share, t.traction[1] * share],
                    t.ramp_time,
                )?;
            }
        }
        for (name, l) in &f.point_loads {
            let key = format!("point_loads.{name}");
            let p = particles.nearest(l.at);
            let x = particles.x0[p];
            let d = (x[0] - l.at[0]).hypot(x[1] - l.at[1]);
            if d > h {
                return Err(SceneError::invalid(
                    format!("{key}.at"),
                    format!(
                        "is {d:.4e} m from the nearest particle, more than one cell (h = {h} m): \
                         it lies outside every body"
                    ),
                ));
            }
            add(&key, p, l.force, l.ramp_time)?;
        }
        Ok(Some(out))
    }
}
