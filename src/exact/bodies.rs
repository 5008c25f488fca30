//! What the contact references share: each body's rigid-body motion from
//! its particles, and the geometry of a scene's one contact pair (which
//! bodies, and the face of the second the first rests on).

use crate::model::Particles;
use crate::scene::Scene;
use crate::scene::schema::BodySpec;

/// One body's rigid-body motion measured from its particles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMotion {
    /// kg per unit thickness.
    pub mass: f64,
    /// Centre of mass (m).
    pub centre: [f64; 2],
    /// Mass-weighted mean displacement since t = 0 (m): the centre's.
    pub displacement: [f64; 2],
    /// Velocity of the centre of mass (m/s).
    pub v: [f64; 2],
    /// Angular velocity about the centre, Σ m (r × v) / Σ m |r|² (rad/s,
    /// counter-clockwise positive).
    pub omega: f64,
}

/// The motion of each of `n_bodies` bodies (`Particles::body` order).
pub fn body_motion(p: &Particles, n_bodies: usize) -> Vec<BodyMotion> {
    let mut out = vec![
        BodyMotion {
            mass: 0.0,
            centre: [0.0; 2],
            displacement: [0.0; 2],
            v: [0.0; 2],
            omega: 0.0,
        };
        n_bodies
    ];
    for i in 0..p.len() {
        let b = &mut out[p.body[i] as usize];
        let m = p.mass[i];
        b.mass += m;
        for d in 0..2 {
            b.centre[d] += m * p.x[i][d];
            b.displacement[d] += m * (p.x[i][d] - p.x0[i][d]);
            b.v[d] += m * p.v[i][d];
        }
    }
    for b in &mut out {
        let m = b.mass.max(f64::MIN_POSITIVE);
        for d in 0..2 {
            b.centre[d] /= m;
            b.displacement[d] /= m;
            b.v[d] /= m;
        }
    }
    let mut ang = vec![[0.0f64; 2]; n_bodies];
    for i in 0..p.len() {
        let k = p.body[i] as usize;
        let b = &out[k];
        let r = [p.x[i][0] - b.centre[0], p.x[i][1] - b.centre[1]];
        let v = [p.v[i][0] - b.v[0], p.v[i][1] - b.v[1]];
        ang[k][0] += p.mass[i] * (r[0] * v[1] - r[1] * v[0]);
        ang[k][1] += p.mass[i] * (r[0] * r[0] + r[1] * r[1]);
    }
    for (b, a) in out.iter_mut().zip(ang) {
        b.omega = if a[1] > 0.0 { a[0] / a[1] } else { 0.0 };
    }
    out
}

/// The scene's one contact pair: its name, and its two bodies' indices
/// (name order, as `Particles::body`) and specs, first and second.
pub struct Pair<'a> {
    pub name: &'a str,
    pub index: [usize; 2],
    pub body: [&'a BodySpec; 2],
    pub spec: &'a crate::scene::schema::ContactSpec,
}

/// The one contact pair (validated: there is one, of two bodies).
pub fn pair(scene: &Scene) -> Pair<'_> {
    let (name, spec) = scene
        .file
        .contact
        .iter()
        .next()
        .expect("validated: one contact pair");
    let index = |b: &str| {
        scene
            .file
            .bodies
            .keys()
            .position(|k| k == b)
            .expect("validated: the pair's bodies exist")
    };
    Pair {
        name,
        index: [index(&spec.bodies[0]), index(&spec.bodies[1])],
        body: [
            &scene.file.bodies[&spec.bodies[0]],
            &scene.file.bodies[&spec.bodies[1]],
        ],
        spec,
    }
}

/// The outward unit normal of the face of `second`'s bounding box that
/// `first`'s centre lies beyond (the face `first` rests on): the axis
/// along which the centre is furthest outside, relative to the box's size.
pub fn face_normal(first: [f64; 4], second: [f64; 4]) -> [f64; 2] {
    let c = [0.5 * (first[0] + first[2]), 0.5 * (first[1] + first[3])];
    let out = [
        (second[0] - c[0]).max(c[0] - second[2]),
        (second[1] - c[1]).max(c[1] - second[3]),
    ];
    if out[0] > out[1] {
        [if c[0] > second[2] { 1.0 } else { -1.0 }, 0.0]
    } else {
        [0.0, if c[1] > second[3] { 1.0 } else { -1.0 }]
    }
}

/// The pair's face normal, from the second body into the first.
pub fn pair_normal(scene: &Scene) -> [f64; 2] {
    let p = pair(scene);
    face_normal(
        crate::scene::seed::body_bbox(p.body[0]),
        crate::scene::seed::body_bbox(p.body[1]),
    )
}

/// Gravity's parts along and across a face with unit normal `n`: the unit
/// tangent in the direction of g's part along it, g_t and g_n = −g·n.
pub fn split_gravity(g: [f64; 2], n: [f64; 2]) -> ([f64; 2], f64, f64) {
    let gn = g[0] * n[0] + g[1] * n[1];
    let gt = [g[0] - gn * n[0], g[1] - gn * n[1]];
    let len = gt[0].hypot(gt[1]);
    let tangent = if len > 0.0 {
        [gt[0] / len, gt[1] / len]
    } else {
        [n[1], -n[0]]
    };
    (tangent, len, -gn)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_on_a_slab_rests_on_its_top_face_whatever_its_offset() {
        // The block's centre is further off along x than up, but inside
        // the slab's x range: it rests on the top face.
        assert_eq!(
            face_normal([0.2, 0.5, 1.2, 1.0], [0.0, 0.0, 3.0, 0.5]),
            [0.0, 1.0]
        );
        assert_eq!(
            face_normal([3.0, 0.0, 4.0, 1.0], [0.0, 0.0, 3.0, 2.0]),
            [1.0, 0.0]
        );
        assert_eq!(
            face_normal([0.0, -1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0]),
            [0.0, -1.0]
        );
    }

    #[test]
    fn tilted_gravity_splits_into_its_slope_parts() {
        let t = 30f64.to_radians();
        let (tg, gt, gn) = split_gravity([9.81 * t.sin(), -9.81 * t.cos()], [0.0, 1.0]);
        assert_eq!(tg, [1.0, 0.0]);
        assert!((gt - 9.81 * t.sin()).abs() < 1e-12 && (gn - 9.81 * t.cos()).abs() < 1e-12);
    }
}
