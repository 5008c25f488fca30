//! Geostatic (K0) initial stress: a body with `initial_stress =
//! "geostatic"` starts with σ_v = −g ∫ ρ dy over the material above each
//! particle (every body's, up to its free surface: a slope, a layered
//! ground or a load of another body gets its own overburden) and σ_h =
//! σ_zz = k0 σ_v, σ_xy = 0. The vertical integral is exact over the
//! bodies' shapes (rectangles, disks, polygons), so a uniform column
//! starts at σ_yy = −ρ g (H − y) at every particle, which is in
//! equilibrium with gravity (∂σ_yy/∂y = ρ g, ∂σ_xx/∂x = 0) whatever k0.
//!
//! Gravity must act along −y at full strength from the start (validated),
//! and the material must carry its stress as its state (elastic,
//! Mohr–Coulomb, Drucker–Prager: not a model on F or one that starts
//! elsewhere, such as Cam-clay at p′0), checked in `Model::new`.

use crate::scene::{BodySpec, Scene};

/// The stretches [y0, y1] (m) of the vertical line at `x` inside `body`'s
/// shapes, merged where they touch.
pub fn column_intervals(body: &BodySpec, x: f64) -> Vec<(f64, f64)> {
    let mut iv: Vec<(f64, f64)> = Vec::new();
    for r in &body.rects {
        if x >= r[0] && x <= r[2] {
            iv.push((r[1], r[3]));
        }
    }
    for d in &body.disks {
        let dx = x - d[0];
        if dx.abs() <= d[2] {
            let half = (d[2] * d[2] - dx * dx).sqrt();
            iv.push((d[1] - half, d[1] + half));
        }
    }
    for poly in &body.polygons {
        // Crossings of the line with the edges, paired bottom to top (the
        // even-odd rule of `scene::seed`).
        let n = poly.len();
        let mut ys: Vec<f64> = (0..n)
            .filter_map(|i| {
                let (a, b) = (poly[i], poly[(i + 1) % n]);
                ((a[0] > x) != (b[0] > x))
                    .then(|| a[1] + (x - a[0]) * (b[1] - a[1]) / (b[0] - a[0]))
            })
            .collect();
        ys.sort_by(f64::total_cmp);
        iv.extend(ys.chunks_exact(2).map(|c| (c[0], c[1])));
    }
    iv.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (a, b) in iv {
        match merged.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    merged
}

/// The overburden at `p` (Pa per m/s² of gravity): ∫ ρ dy over every
/// body's material above `p` (kg/m²), `density` giving each body's ρ in
/// `Scene::bodies()` order.
pub fn overburden(scene: &Scene, density: &[f64], p: [f64; 2]) -> f64 {
    scene
        .bodies()
        .zip(density)
        .map(|((_, b), rho)| {
            rho * column_intervals(b, p[0])
                .iter()
                .map(|&(y0, y1)| (y1 - y0.max(p[1])).max(0.0))
                .sum::<f64>()
        })
        .sum()
}

/// The default k0 of a material's keys: 1 − sin φ (Jaky) where it has a
/// friction angle, else ν/(1 − ν) (the elastic lateral-strain-free ratio).
pub fn default_k0(spec: &crate::scene::MaterialSpec) -> f64 {
    match (spec.get("friction_angle"), spec.get("nu")) {
        (Some(phi), _) => 1.0 - phi.to_radians().sin(),
        (None, Some(nu)) => nu / (1.0 - nu),
        (None, None) => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(rects: Vec<[f64; 4]>, disks: Vec<[f64; 3]>, polygons: Vec<Vec<[f64; 2]>>) -> BodySpec {
        BodySpec {
            material: "m".into(),
            ppc: 2,
            velocity: [0.0; 2],
            layout: None,
            disk_layout: Default::default(),
            rects,
            disks,
            polygons,
            initial_stress: Default::default(),
            k0: None,
            water_table: None,
        }
    }

    #[test]
    fn columns_cross_rects_disks_and_polygons() {
        let b = body(
            vec![[0.0, 0.0, 1.0, 1.0], [0.0, 1.0, 1.0, 2.0]],
            vec![[0.5, 4.0, 0.5]],
            vec![vec![[0.0, 5.0], [1.0, 5.0], [1.0, 6.0]]],
        );
        let iv = column_intervals(&b, 0.5);
        // The touching rects merge; the disk's chord at its centre; the
        // triangle's top edge y = 5 + x.
        assert_eq!(iv.len(), 3);
        assert_eq!(iv[0], (0.0, 2.0));
        assert!((iv[1].0 - 3.5).abs() < 1e-12 && (iv[1].1 - 4.5).abs() < 1e-12);
        assert!((iv[2].0 - 5.0).abs() < 1e-12 && (iv[2].1 - 5.5).abs() < 1e-12);
        assert!(column_intervals(&b, 1.5).is_empty());
    }
}
