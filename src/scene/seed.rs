//! Particle seeding: reads the bodies' shapes, writes particle positions and
//! volumes on the cells of the node lattice (spacing h, through `anchor`).
//!
//! Rectangles are clipped to each cell and the points placed in the clipped
//! part, so mass and the body's edges are exact even where an edge does not
//! fall on a grid line. Disks and polygons keep the cell's points that fall
//! inside them (volume = the point's share of the cell), so their mass is
//! exact only as h → 0 and a disk's edge is a staircase of the lattice;
//! with `disk_layout = "rings"` a disk's particles sit on concentric rings
//! instead (`disk_rings`: round at the particle scale, mass exact). A point
//! already inside a rectangle or an earlier disk or polygon is not seeded
//! twice; that happens within a body only, since `validate` refuses shapes
//! of different bodies that overlap (`overlap`).

use super::Scene;
use super::schema::{DiskLayout, Layout};
use std::f64::consts::PI;

/// One particle before it becomes part of `model::Particles`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seed {
    /// Position (m).
    pub x: [f64; 2],
    /// Initial volume (m² per unit thickness).
    pub volume: f64,
    /// Index of the body in `Scene::bodies()` order.
    pub body: u32,
}

/// Points and weights on [0, 1] for `n` per direction: Gauss-Legendre, or
/// equal sub-cell centres. Weights sum to 1.
pub fn points_1d(layout: Layout, n: u32) -> Vec<(f64, f64)> {
    match layout {
        Layout::Uniform => (0..n)
            .map(|k| ((2 * k + 1) as f64 / (2 * n) as f64, 1.0 / n as f64))
            .collect(),
        Layout::Gauss => gauss_legendre(n as usize)
            .into_iter()
            .map(|(x, w)| (0.5 * (x + 1.0), 0.5 * w))
            .collect(),
    }
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n, Golub-Welsch
/// initial guesses), accurate to round-off for the small n used here.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // Three-term recurrence for P_n(x) and its derivative.
            // After the loop pn = P_n(x) and pn1 = P_{n-1}(x).
            let (mut pn1, mut pn) = (1.0, x);
            for k in 2..=n {
                let next = ((2 * k - 1) as f64 * x * pn - (k - 1) as f64 * pn1) / k as f64;
                pn1 = pn;
                pn = next;
            }
            dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// Signed area of a polygon (shoelace), positive when counter-clockwise.
pub fn polygon_area(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        * 0.5
}

/// Whether `p` lies inside `poly` (even-odd rule).
pub fn inside_polygon(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            inside = !inside;
        }
        j = i;
    }
    inside
}

fn inside_rect(r: &[f64; 4], p: [f64; 2]) -> bool {
    p[0] >= r[0] && p[0] <= r[2] && p[1] >= r[1] && p[1] <= r[3]
}

fn inside_disk(d: &[f64; 3], p: [f64; 2]) -> bool {
    (p[0] - d[0]).hypot(p[1] - d[1]) <= d[2]
}

/// Particles of disk `d` = [cx, cy, r] on concentric rings at spacing
/// about `s` (m), as (position, volume): n_r = round(r/s) rings of width
/// Δr = r/n_r, ring j at radius (j + ½) Δr holding n_j equal shares of its
/// area at angles 2π (i + ½)/n_j, with n_j the multiple of 4 nearest to
/// 2π r_j / s (at least 4). So no particle lies on the disk's horizontal
/// or vertical diameter, and the rings are mirror-symmetric about both: a
/// particle on a grid line through a node-centred disk would stay on it
/// while the disk moves along the line, with nodes beyond that it reaches
/// with weight 0 (see `disk_layout` in docs/scenes.md). The volumes sum to
/// π r² to round-off; the two innermost rings' shares are 0.79 and 1.18
/// s², the others within 10 % of s².
pub fn disk_rings(d: &[f64; 3], s: f64) -> Vec<([f64; 2], f64)> {
    let nr = ((d[2] / s).round() as usize).max(1);
    let dr = d[2] / nr as f64;
    let mut out = Vec::new();
    for j in 0..nr {
        let r = (j as f64 + 0.5) * dr;
        let n = 4 * ((2.0 * PI * r / (4.0 * s)).round() as usize).max(1);
        let area = PI * dr * dr * (2 * j + 1) as f64;
        for i in 0..n {
            let a = 2.0 * PI * (i as f64 + 0.5) / n as f64;
            out.push(([d[0] + r * a.cos(), d[1] + r * a.sin()], area / n as f64));
        }
    }
    out
}

/// Whether `x` already belongs to a rectangle or to an earlier disk or
/// polygon (seeded once only).
fn claimed(rects: &[[f64; 4]], curved: &[Curved], x: [f64; 2]) -> bool {
    rects.iter().any(|r| inside_rect(r, x)) || curved.iter().any(|c| c.contains(x))
}

/// Lattice coordinate of `v` on an axis through `anchor` with spacing `h`,
/// snapped to the nearest integer when within round-off of it.
fn lattice(v: f64, anchor: f64, h: f64) -> f64 {
    let q = (v - anchor) / h;
    if (q - q.round()).abs() < 1e-9 {
        q.round()
    } else {
        q
    }
}

/// Seeds every body of `scene` on the lattice through `anchor` with spacing
/// `h`. Particles come out sorted by cell (row-major) for memory locality.
pub fn seed_particles(scene: &Scene, anchor: [f64; 2], h: f64) -> Vec<Seed> {
    let mut seeds: Vec<([i64; 2], Seed)> = Vec::new();
    let all_rects: Vec<[f64; 4]> = scene
        .bodies()
        .flat_map(|(_, b)| b.rects.iter().copied())
        .collect();
    // Disks and polygons seeded so far, so later ones skip claimed points.
    let mut curved: Vec<Curved> = Vec::new();

    for (bi, (_, body)) in scene.bodies().enumerate() {
        let pts = points_1d(scene.layout(body), body.ppc);
        let body_id = bi as u32;
        for r in &body.rects {
            let (kx0, kx1) = (
                lattice(r[0], anchor[0], h).floor() as i64,
                lattice(r[2], anchor[0], h).ceil() as i64,
            );
            let (ky0, ky1) = (
                lattice(r[1], anchor[1], h).floor() as i64,
                lattice(r[3], anchor[1], h).ceil() as i64,
            );
            for ky in ky0..ky1 {
                let y0 = (anchor[1] + ky as f64 * h).max(r[1]);
                let y1 = (anchor[1] + (ky + 1) as f64 * h).min(r[3]);
                if y1 - y0 <= 1e-12 * h {
                    continue;
                }
                for kx in kx0..kx1 {
                    let x0 = (anchor[0] + kx as f64 * h).max(r[0]);
                    let x1 = (anchor[0] + (kx + 1) as f64 * h).min(r[2]);
                    if x1 - x0 <= 1e-12 * h {
                        continue;
                    }
                    for &(sy, wy) in &pts {
                        for &(sx, wx) in &pts {
                            let x = [x0 + sx * (x1 - x0), y0 + sy * (y1 - y0)];
                            let volume = wx * wy * (x1 - x0) * (y1 - y0);
                            seeds.push((
                                [ky, kx],
                                Seed {
                                    x,
                                    volume,
                                    body: body_id,
                                },
                            ));
                        }
                    }
                }
            }
        }
        let shapes = body
            .disks
            .iter()
            .map(|d| Curved::Disk(*d))
            .chain(body.polygons.iter().map(|p| Curved::Polygon(p.clone())));
        for shape in shapes {
            if let (Curved::Disk(d), DiskLayout::Rings) = (&shape, body.disk_layout) {
                for (x, volume) in disk_rings(d, h / body.ppc as f64) {
                    if !claimed(&all_rects, &curved, x) {
                        let cell = [
                            lattice(x[1], anchor[1], h).floor() as i64,
                            lattice(x[0], anchor[0], h).floor() as i64,
                        ];
                        seeds.push((
                            cell,
                            Seed {
                                x,
                                volume,
                                body: body_id,
                            },
                        ));
                    }
                }
                curved.push(shape);
                continue;
            }
            let bb = shape.bbox();
            let (kx0, kx1) = (
                lattice(bb[0], anchor[0], h).floor() as i64,
                lattice(bb[2], anchor[0], h).ceil() as i64,
            );
            let (ky0, ky1) = (
                lattice(bb[1], anchor[1], h).floor() as i64,
                lattice(bb[3], anchor[1], h).ceil() as i64,
            );
            for ky in ky0..ky1 {
                for kx in kx0..kx1 {
                    let (x0, y0) = (anchor[0] + kx as f64 * h, anchor[1] + ky as f64 * h);
                    for &(sy, wy) in &pts {
                        for &(sx, wx) in &pts {
                            let x = [x0 + sx * h, y0 + sy * h];
                            if shape.contains(x) && !claimed(&all_rects, &curved, x) {
                                seeds.push((
                                    [ky, kx],
                                    Seed {
                                        x,
                                        volume: wx * wy * h * h,
                                        body: body_id,
                                    },
                                ));
                            }
                        }
                    }
                }
            }
            curved.push(shape);
        }
    }
    // Stable sort: within a cell, particles keep their seeding order.
    seeds.sort_by_key(|(cell, _)| *cell);
    seeds.into_iter().map(|(_, s)| s).collect()
}

enum Curved {
    Disk([f64; 3]),
    Polygon(Vec<[f64; 2]>),
}

impl Curved {
    fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Curved::Disk(d) => inside_disk(d, p),
            Curved::Polygon(poly) => inside_polygon(poly, p),
        }
    }

    fn bbox(&self) -> [f64; 4] {
        match self {
            Curved::Disk(d) => disk_bbox(*d),
            Curved::Polygon(poly) => polygon_bbox(poly),
        }
    }
}

/// The box `[xmin, ymin, xmax, ymax]` holding both boxes.
fn union(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

const EMPTY_BOX: [f64; 4] = [
    f64::INFINITY,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
];

/// Bounding box `[xmin, ymin, xmax, ymax]` of the disk `[cx, cy, r]` (m).
pub fn disk_bbox(d: [f64; 3]) -> [f64; 4] {
    [d[0] - d[2], d[1] - d[2], d[0] + d[2], d[1] + d[2]]
}

/// Bounding box `[xmin, ymin, xmax, ymax]` of a polygon's vertices (m).
pub fn polygon_bbox(poly: &[[f64; 2]]) -> [f64; 4] {
    poly.iter()
        .fold(EMPTY_BOX, |b, p| union(b, [p[0], p[1], p[0], p[1]]))
}

/// Bounding box `[xmin, ymin, xmax, ymax]` of every shape of every body (m).
pub fn bodies_bbox(scene: &Scene) -> [f64; 4] {
    scene
        .bodies()
        .fold(EMPTY_BOX, |bb, (_, body)| union(bb, body_bbox(body)))
}

/// Bounding box `[xmin, ymin, xmax, ymax]` of one body's shapes (m).
pub fn body_bbox(body: &crate::scene::schema::BodySpec) -> [f64; 4] {
    let rects = body.rects.iter().copied();
    let disks = body.disks.iter().map(|d| disk_bbox(*d));
    let polygons = body.polygons.iter().map(|p| polygon_bbox(p));
    rects.chain(disks).chain(polygons).fold(EMPTY_BOX, union)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1() {
        for n in 1..=6 {
            let gl = gauss_legendre(n);
            assert!((gl.iter().map(|p| p.1).sum::<f64>() - 2.0).abs() < 1e-13);
            let deg = 2 * n - 1;
            let exact = if deg % 2 == 1 {
                0.0
            } else {
                2.0 / (deg as f64 + 1.0)
            };
            let got: f64 = gl.iter().map(|(x, w)| w * x.powi(deg as i32)).sum();
            assert!((got - exact).abs() < 1e-13, "n = {n}");
            let even = 2 * n - 2;
            let got: f64 = gl.iter().map(|(x, w)| w * x.powi(even as i32)).sum();
            assert!((got - 2.0 / (even as f64 + 1.0)).abs() < 1e-13, "n = {n}");
        }
        let two = gauss_legendre(2);
        assert!((two[1].0 - 1.0 / 3f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn disk_rings_fill_the_disk_at_the_spacing() {
        let d = [0.3, -0.2, 0.2];
        let pts = disk_rings(&d, 0.0125);
        let area: f64 = pts.iter().map(|p| p.1).sum();
        assert!((area / (PI * 0.04) - 1.0).abs() < 1e-12, "{area}");
        // 16 rings; every particle inside, the outer ring half a spacing in.
        let r = |p: &([f64; 2], f64)| (p.0[0] - d[0]).hypot(p.0[1] - d[1]);
        assert!(pts.iter().all(|p| r(p) < d[2]));
        let outer = pts.iter().map(r).fold(0.0, f64::max);
        assert!((outer - (0.2 - 0.00625)).abs() < 1e-12, "{outer}");
        // Shares close to s² beyond the two innermost rings; four
        // particles on the centre ring, none on either diameter.
        for p in &pts {
            let lim = if r(p) < 2.0 * 0.0125 { 0.22 } else { 0.1 };
            assert!(
                (p.1 / 0.0125f64.powi(2) - 1.0).abs() < lim,
                "{} at {}",
                p.1,
                r(p)
            );
            assert!((p.0[0] - d[0]).abs() > 1e-3 && (p.0[1] - d[1]).abs() > 1e-3);
        }
        assert_eq!(pts.iter().filter(|p| r(p) < 0.0125).count(), 4);
    }

    #[test]
    fn polygon_helpers() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(polygon_area(&sq), 1.0);
        assert!(inside_polygon(&sq, [0.5, 0.5]));
        assert!(!inside_polygon(&sq, [1.5, 0.5]));
    }
}
