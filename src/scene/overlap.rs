//! Whether two shapes of a scene overlap (share interior, not only an edge
//! or a point), and where. The seeder gives a point inside two shapes to
//! the first that claims it (`seed`), so shapes of different bodies that
//! overlap would cut one body; `validate` refuses them with the place this
//! finds.
//!
//! Rectangles are polygons here. Disk against disk and disk against
//! polygon are exact (distance of the centres, distance of the centre to
//! the polygon); polygon against polygon splits every edge of each where
//! it meets the other's edges and tests a point just inside each piece,
//! on its own polygon's side: two simple polygons share interior exactly
//! when one of those points lies inside the other. Flush shapes (an edge
//! on an edge, a disk resting on a rectangle) touch within `tol` and do
//! not overlap.

use super::seed::inside_polygon;
use super::seed::polygon_area;

/// A body's shape, as the scene gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    Rect([f64; 4]),
    Disk([f64; 3]),
    Polygon(Vec<[f64; 2]>),
}

impl Shape {
    fn vertices(&self) -> Option<Vec<[f64; 2]>> {
        match self {
            Shape::Rect(r) => Some(vec![[r[0], r[1]], [r[2], r[1]], [r[2], r[3]], [r[0], r[3]]]),
            Shape::Polygon(p) => Some(p.clone()),
            Shape::Disk(_) => None,
        }
    }
}

/// A point inside both `a` and `b` (or on the boundary of one, inside the
/// other, for a disk against a polygon) and, with a disk, how deep the
/// overlap is there (m), when they overlap by more than `tol` (m); None when they are apart
/// or touch.
pub fn overlap(a: &Shape, b: &Shape, tol: f64) -> Option<([f64; 2], Option<f64>)> {
    match (a, b) {
        (Shape::Disk(d), Shape::Disk(e)) => {
            let (dx, dy) = (e[0] - d[0], e[1] - d[1]);
            let dist = dx.hypot(dy);
            let depth = d[2] + e[2] - dist;
            if depth <= tol {
                return None;
            }
            // The middle of the lens along the line of centres (the
            // centre itself when they share it).
            let s = if dist > 0.0 {
                0.5 * (d[2] + dist - e[2]) / dist
            } else {
                0.0
            };
            Some((
                [d[0] + s * dx, d[1] + s * dy],
                Some(depth.min(2.0 * d[2].min(e[2]))),
            ))
        }
        (Shape::Disk(d), p) | (p, Shape::Disk(d)) => {
            let poly = p.vertices().expect("not a disk");
            let c = [d[0], d[1]];
            let (q, dist) = if inside_polygon(&poly, c) {
                (c, 0.0)
            } else {
                closest_on_boundary(&poly, c)
            };
            let depth = d[2] - dist;
            (depth > tol).then_some((q, Some(depth.min(2.0 * d[2]))))
        }
        _ => {
            let (pa, pb) = (a.vertices().unwrap(), b.vertices().unwrap());
            piece_inside(&pa, &pb, tol)
                .or_else(|| piece_inside(&pb, &pa, tol))
                .map(|x| (x, None))
        }
    }
}

/// A point just inside `a`, beside a piece of its boundary split at `b`'s
/// edges, that lies inside `b`; None if no such piece.
fn piece_inside(a: &[[f64; 2]], b: &[[f64; 2]], tol: f64) -> Option<[f64; 2]> {
    let ccw = polygon_area(a) > 0.0;
    let n = a.len();
    for i in 0..n {
        let (p0, p1) = (a[i], a[(i + 1) % n]);
        let e = [p1[0] - p0[0], p1[1] - p0[1]];
        let len = e[0].hypot(e[1]);
        if len <= tol {
            continue;
        }
        let mut cuts = vec![0.0, 1.0];
        for j in 0..b.len() {
            cuts.extend(crossings(p0, e, b[j], b[(j + 1) % b.len()]));
        }
        cuts.retain(|t| (0.0..=1.0).contains(t));
        cuts.sort_by(f64::total_cmp);
        // Inward normal of `a` at this edge.
        let inward = if ccw {
            [-e[1] / len, e[0] / len]
        } else {
            [e[1] / len, -e[0] / len]
        };
        for w in cuts.windows(2) {
            let piece = (w[1] - w[0]) * len;
            if piece <= tol {
                continue;
            }
            let t = 0.5 * (w[0] + w[1]);
            // Far enough off the piece to be clear of round-off on a
            // shared edge, close enough to stay inside `a`.
            let off = (1e-6 * piece).max(2.0 * tol).min(0.25 * piece);
            let x = [
                p0[0] + t * e[0] + off * inward[0],
                p0[1] + t * e[1] + off * inward[1],
            ];
            if inside_polygon(b, x) && inside_polygon(a, x) {
                return Some(x);
            }
        }
    }
    None
}

/// Parameters t along p0 + t e where the segment meets segment [q0, q1]
/// (the overlap's ends when they are collinear).
fn crossings(p0: [f64; 2], e: [f64; 2], q0: [f64; 2], q1: [f64; 2]) -> Vec<f64> {
    let f = [q1[0] - q0[0], q1[1] - q0[1]];
    let cross = |u: [f64; 2], v: [f64; 2]| u[0] * v[1] - u[1] * v[0];
    let d = [q0[0] - p0[0], q0[1] - p0[1]];
    let den = cross(e, f);
    let ee = e[0] * e[0] + e[1] * e[1];
    let scale = ee.sqrt() * f[0].hypot(f[1]);
    if den.abs() <= 1e-12 * scale {
        // Parallel: where the other's ends project, if on the same line.
        if cross(d, e).abs() <= 1e-12 * ee {
            let proj = |q: [f64; 2]| ((q[0] - p0[0]) * e[0] + (q[1] - p0[1]) * e[1]) / ee;
            return vec![proj(q0), proj(q1)];
        }
        return Vec::new();
    }
    let t = cross(d, f) / den;
    let u = cross(d, e) / den;
    if (-1e-12..=1.0 + 1e-12).contains(&u) {
        vec![t]
    } else {
        Vec::new()
    }
}

/// The point of `poly`'s boundary nearest `c`, and its distance.
fn closest_on_boundary(poly: &[[f64; 2]], c: [f64; 2]) -> ([f64; 2], f64) {
    let n = poly.len();
    let mut best = (poly[0], f64::INFINITY);
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let ee = e[0] * e[0] + e[1] * e[1];
        let t = if ee > 0.0 {
            (((c[0] - a[0]) * e[0] + (c[1] - a[1]) * e[1]) / ee).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + t * e[0], a[1] + t * e[1]];
        let dist = (c[0] - q[0]).hypot(c[1] - q[1]);
        if dist < best.1 {
            best = (q, dist);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: f64 = 1e-9;

    fn hit(a: &Shape, b: &Shape) -> bool {
        let one = overlap(a, b, TOL);
        let two = overlap(b, a, TOL);
        assert_eq!(one.is_some(), two.is_some(), "{a:?} {b:?}");
        one.is_some()
    }

    #[test]
    fn disks_overlap_apart_and_flush() {
        let d = Shape::Disk([0.0, 0.0, 1.0]);
        assert!(hit(&d, &Shape::Disk([1.5, 0.0, 1.0])));
        let (x, depth) = overlap(&d, &Shape::Disk([1.5, 0.0, 1.0]), TOL).unwrap();
        assert!((x[0] - 0.75).abs() < 1e-12 && x[1] == 0.0, "{x:?}");
        assert!((depth.unwrap() - 0.5).abs() < 1e-12);
        // One inside the other, and the same disk twice.
        assert!(hit(&d, &Shape::Disk([0.1, 0.0, 0.2])));
        assert!(hit(&d, &d));
        assert!(!hit(&d, &Shape::Disk([2.0, 0.0, 1.0])));
        assert!(!hit(&d, &Shape::Disk([3.0, 0.0, 1.0])));
    }

    #[test]
    fn disk_against_rect_and_polygon() {
        let slab = Shape::Rect([-0.6, 0.0, 2.0, 0.25]);
        // contact_rolling's disk resting on its slab: flush.
        assert!(!hit(&Shape::Disk([0.0, 0.75, 0.5]), &slab));
        // Sunk 0.1 into it, and wholly inside it.
        let sunk = overlap(&Shape::Disk([0.0, 0.65, 0.5]), &slab, TOL).unwrap();
        assert!((sunk.1.unwrap() - 0.1).abs() < 1e-12 && (sunk.0[1] - 0.25).abs() < 1e-12);
        assert!(hit(&Shape::Disk([0.5, 0.1, 0.05]), &slab));
        // A disk holding the whole slab.
        assert!(hit(&Shape::Disk([0.7, 0.1, 5.0]), &slab));
        // Near a corner, apart along the diagonal though within the box.
        assert!(!hit(&Shape::Disk([2.3, 0.55, 0.4]), &slab));
        assert!(hit(&Shape::Disk([2.2, 0.45, 0.4]), &slab));
        let tri = Shape::Polygon(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert!(hit(&Shape::Disk([0.6, 0.6, 0.2]), &tri));
        assert!(!hit(&Shape::Disk([0.6, 0.6, 0.1]), &tri));
    }

    #[test]
    fn polygons_and_rects() {
        let a = Shape::Rect([0.0, 0.0, 1.0, 1.0]);
        // Flush on an edge, on part of an edge, at a corner: touching.
        assert!(!hit(&a, &Shape::Rect([1.0, 0.0, 2.0, 1.0])));
        assert!(!hit(&a, &Shape::Rect([1.0, 0.5, 2.0, 3.0])));
        assert!(!hit(&a, &Shape::Rect([1.0, 1.0, 2.0, 2.0])));
        // Crossing, one inside the other, the same rectangle twice.
        assert!(hit(&a, &Shape::Rect([0.5, 0.5, 2.0, 2.0])));
        assert!(hit(&a, &Shape::Rect([0.2, 0.2, 0.4, 0.4])));
        assert!(hit(&a, &a));
        // A cross: no vertex of either inside the other.
        assert!(hit(
            &Shape::Rect([-1.0, 0.4, 2.0, 0.6]),
            &Shape::Rect([0.4, -1.0, 0.6, 2.0])
        ));
        // Half of the square by its diagonal (clockwise): inside, all its
        // vertices on the square's boundary.
        let half = Shape::Polygon(vec![[0.0, 0.0], [1.0, 1.0], [1.0, 0.0]]);
        assert!(hit(&a, &half));
        // The other half, beside the first along the diagonal: flush.
        let other = Shape::Polygon(vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0]]);
        assert!(!hit(&half, &other));
        let (x, _) = overlap(&half, &a, TOL).unwrap();
        assert!(x[0] > x[1] && (0.0..1.0).contains(&x[0]), "{x:?}");
        // A triangle poking into the square's side, and one beside it.
        let poke = Shape::Polygon(vec![[0.9, 0.5], [1.5, 0.0], [1.5, 1.0]]);
        assert!(hit(&a, &poke));
        let beside = Shape::Polygon(vec![[1.0, 0.5], [1.5, 0.0], [1.5, 1.0]]);
        assert!(!hit(&a, &beside));
    }
}
