//! Disk rolling without slip down an inclined plane (implicit-MPM paper
//! §5.2). A solid disk starting at rest on a plane with normal n under
//! constant gravity g accelerates along the plane at two thirds of the
//! tangential gravity, a = (2/3)(g − (g·n) n) (eq. 64: a = (2/3) g sin θ
//! for vertical g and a plane inclined at θ). Its centre then moves
//! u(t) = ½ a t² (eqs. 65–66 with v(0) = 0; the paper projects on x).
//!
//! The disk's centre is its centre of mass, so the numerical displacement
//! is the mass-weighted mean particle displacement: no particle needs to sit
//! at the centre, and the disk's rotation does not enter it.
//!
//! The error over a run is eq. 67's sum over the sample times t_i of
//! (u_x(t_i) − u_x,num(t_i))²; the extracted text of the paper lost its
//! symbols, and Table 1's heading reads "Error (%)", so we report the
//! relative form 100 · sqrt(Σ (u − u_num)²) / sqrt(Σ u²), in percent.

use crate::model::Particles;
use crate::scene::Scene;
use serde::Serialize;

#[derive(Debug, Clone, PartialEq)]
pub struct RollingDisk {
    /// Acceleration of the centre (m/s²).
    pub accel: [f64; 2],
    /// Incline angle θ between the plane and the horizontal (rad), from
    /// the angle between the wall's normal and −g.
    pub theta: f64,
    /// Disk radius (m).
    pub radius: f64,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct RollingErrors {
    /// Centre displacement along x at the end (m).
    pub u_x: f64,
    /// Exact ½ a_x t² (m).
    pub u_x_exact: f64,
    /// |u_x − exact| / |exact|.
    pub u_x_rel_error: f64,
    /// Centre velocity along the plane at the end (m/s), and exact a t.
    pub v_along: f64,
    pub v_along_exact: f64,
}

impl RollingDisk {
    /// From the scene's gravity, its one wall and its one disk (validated).
    pub fn from_scene(scene: &Scene) -> RollingDisk {
        let g = scene.file.gravity.as_ref().map_or([0.0, 0.0], |g| g.g);
        let wall = scene
            .file
            .walls
            .values()
            .next()
            .expect("validated: one wall");
        let radius = scene
            .file
            .bodies
            .values()
            .flat_map(|b| b.disks.iter())
            .next()
            .expect("validated: one disk")[2];
        RollingDisk::new(g, wall.normal, radius)
    }

    /// `normal` need not be unit length.
    pub fn new(g: [f64; 2], normal: [f64; 2], radius: f64) -> RollingDisk {
        let nn = (normal[0] * normal[0] + normal[1] * normal[1]).sqrt();
        let n = [normal[0] / nn, normal[1] / nn];
        let gn = g[0] * n[0] + g[1] * n[1];
        let gt = [g[0] - gn * n[0], g[1] - gn * n[1]];
        let g_mag = (g[0] * g[0] + g[1] * g[1]).sqrt();
        let gt_mag = (gt[0] * gt[0] + gt[1] * gt[1]).sqrt();
        RollingDisk {
            accel: [2.0 / 3.0 * gt[0], 2.0 / 3.0 * gt[1]],
            theta: if g_mag > 0.0 {
                (gt_mag / g_mag).asin()
            } else {
                0.0
            },
            radius,
        }
    }

    /// Magnitude of the centre's acceleration along the plane (m/s²).
    pub fn accel_along(&self) -> f64 {
        self.accel[0].hypot(self.accel[1])
    }

    /// Exact centre displacement at `t` (m).
    pub fn displacement(&self, t: f64) -> [f64; 2] {
        [0.5 * self.accel[0] * t * t, 0.5 * self.accel[1] * t * t]
    }

    /// Mass-weighted mean displacement and velocity of the particles: the
    /// centre of mass's.
    pub fn centre(p: &Particles) -> ([f64; 2], [f64; 2]) {
        let mut m = 0.0;
        let (mut u, mut v) = ([0.0; 2], [0.0; 2]);
        for i in 0..p.len() {
            let w = p.mass[i];
            m += w;
            for d in 0..2 {
                u[d] += w * (p.x[i][d] - p.x0[i][d]);
                v[d] += w * p.v[i][d];
            }
        }
        let m = m.max(f64::MIN_POSITIVE);
        ([u[0] / m, u[1] / m], [v[0] / m, v[1] / m])
    }

    pub fn score(&self, p: &Particles, t: f64) -> RollingErrors {
        let (u, v) = Self::centre(p);
        let exact = self.displacement(t);
        let a = self.accel_along();
        let dir = if a > 0.0 {
            [self.accel[0] / a, self.accel[1] / a]
        } else {
            [0.0, 0.0]
        };
        RollingErrors {
            u_x: u[0],
            u_x_exact: exact[0],
            u_x_rel_error: (u[0] - exact[0]).abs() / exact[0].abs().max(f64::MIN_POSITIVE),
            v_along: v[0] * dir[0] + v[1] * dir[1],
            v_along_exact: a * t,
        }
    }

    /// Eq. 67 in relative form (percent): `history` is (t, numerical u_x).
    pub fn history_error_percent(&self, history: &[(f64, f64)]) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        for &(t, u) in history {
            let e = self.displacement(t)[0];
            num += (e - u) * (e - u);
            den += e * e;
        }
        100.0 * (num / den.max(f64::MIN_POSITIVE)).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thirty_degrees_gives_a_third_of_g() {
        let t = 30f64.to_radians();
        let d = RollingDisk::new([0.0, -9.81], [t.sin(), t.cos()], 0.2);
        assert!((d.accel_along() - 9.81 / 3.0).abs() < 1e-12);
        assert!((d.theta - t).abs() < 1e-12);
        // Down the slope: +x, −y.
        assert!(d.accel[0] > 0.0 && d.accel[1] < 0.0);
        assert!((d.accel[0] - 9.81 / 3.0 * t.cos()).abs() < 1e-12);
    }

    #[test]
    fn tilted_gravity_on_a_flat_floor_is_the_same_problem() {
        let t = 20f64.to_radians();
        let a = RollingDisk::new([9.81 * t.sin(), -9.81 * t.cos()], [0.0, 1.0], 0.2);
        let b = RollingDisk::new([0.0, -9.81], [t.sin(), t.cos()], 0.2);
        assert!((a.accel_along() - b.accel_along()).abs() < 1e-12);
        assert!((a.theta - b.theta).abs() < 1e-12);
    }

    #[test]
    fn history_error_is_zero_on_the_exact_curve_and_grows_with_an_offset() {
        let d = RollingDisk::new([0.0, -9.81], [0.5, 0.75f64.sqrt()], 0.2);
        let exact: Vec<(f64, f64)> = (1..=10)
            .map(|k| {
                let t = 0.05 * k as f64;
                (t, d.displacement(t)[0])
            })
            .collect();
        assert_eq!(d.history_error_percent(&exact), 0.0);
        let off: Vec<(f64, f64)> = exact.iter().map(|&(t, u)| (t, 1.01 * u)).collect();
        assert!((d.history_error_percent(&off) - 1.0).abs() < 1e-9);
    }
}
