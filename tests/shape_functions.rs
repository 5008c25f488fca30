//! Shape functions on regular and perturbed grids, at random points including
//! ones near the grid boundary: partition of unity, linear reproduction,
//! gradient consistency, LME → Q4 as γ grows, LME Newton convergence and
//! its reported failure.

use lme_mpm::model::Grid;
use lme_mpm::model::shape::lme::Lme;
use lme_mpm::model::shape::ugimp::Ugimp;
use lme_mpm::model::shape::{Shape, ShapeFault, linear};
use lme_mpm::rng::SplitMix64;

/// Closed-form shapes (Q4, uGIMP) hold the identities to round-off: a few
/// ulps of the O(1) sums, scaled by h for positions.
const TOL_CLOSED: f64 = 1e-12;
/// LME stops Newton when |r| ≤ 1e-10 h and |J⁻¹r| ≤ 1e-10/h
/// (lme::NEWTON_TOL), which bound the reproduction and gradient-sum errors
/// directly; the gradient moment adds round-off of the O(1) sums. 1e-9.
const TOL_LME: f64 = 1e-9;
/// Isoparametric Q4 needs Newton to invert the map; it converges to 1e-14.
const TOL_ISO: f64 = 1e-10;

fn grid(perturb: f64) -> Grid {
    Grid::regular(0.5, [-1.0, 2.0], 11, 9).perturbed(perturb, 7)
}

/// Random points: half anywhere inside the grid (keeping `margin` from the
/// edge), half within 0.05 h of an edge.
fn points(g: &Grid, margin: f64, n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = SplitMix64::new(seed);
    let (lo, hi) = (g.min, g.max());
    let band = 0.05 * g.h;
    (0..n)
        .map(|k| {
            let mut x = [
                rng.range(lo[0] + margin, hi[0] - margin),
                rng.range(lo[1] + margin, hi[1] - margin),
            ];
            if k % 2 == 1 {
                let side = rng.next_u64() % 4;
                let d = margin + rng.range(0.0, band);
                match side {
                    0 => x[0] = lo[0] + d,
                    1 => x[0] = hi[0] - d,
                    2 => x[1] = lo[1] + d,
                    _ => x[1] = hi[1] - d,
                }
            }
            x
        })
        .collect()
}

struct Identities {
    unity: f64,
    reproduction: f64,
    grad_sum: f64,
    grad_moment: f64,
    min_n: f64,
}

fn identities(shape: &Shape, g: &Grid, x: [f64; 2]) -> Result<Identities, ShapeFault> {
    let mut nodes = vec![0u32; shape.max_nodes()];
    let mut w = vec![[0.0; 3]; shape.max_nodes()];
    let mut lam = [0.0; 2];
    let n = shape.eval(g, x, &mut lam, &mut nodes, &mut w)?;
    let (mut s, mut rx, mut gs, mut gm) = (0.0, [0.0; 2], [0.0; 2], [[0.0; 2]; 2]);
    let mut min_n = f64::INFINITY;
    for k in 0..n {
        let node = nodes[k] as usize;
        let xa = g.node_pos(node % g.nx, node / g.nx);
        s += w[k][0];
        min_n = min_n.min(w[k][0]);
        for d in 0..2 {
            rx[d] += w[k][0] * xa[d];
            gs[d] += w[k][1 + d];
            // Moment about x: Σ (x_a − x) ⊗ ∇N_a = I, which equals
            // Σ x_a ⊗ ∇N_a = I given Σ ∇N_a = 0 (checked separately) without
            // multiplying that error by |x|.
            for e in 0..2 {
                gm[d][e] += (xa[d] - x[d]) * w[k][1 + e];
            }
        }
    }
    Ok(Identities {
        unity: (s - 1.0).abs(),
        reproduction: (rx[0] - x[0]).hypot(rx[1] - x[1]) / g.h,
        grad_sum: gs[0].hypot(gs[1]) * g.h,
        grad_moment: (gm[0][0] - 1.0)
            .abs()
            .max(gm[1][1] - 1.0)
            .max(gm[0][1].abs())
            .max(gm[1][0].abs()),
        min_n,
    })
}

fn check_all(shape: &Shape, g: &Grid, margin: f64, tol: f64, what: &str) {
    let mut worst = [0.0f64; 4];
    for x in points(g, margin, 400, 11) {
        let id = identities(shape, g, x).unwrap_or_else(|e| panic!("{what} at {x:?}: {e}"));
        assert!(
            id.min_n >= -TOL_CLOSED,
            "{what}: negative N = {} at {x:?}",
            id.min_n
        );
        for (w, v) in worst
            .iter_mut()
            .zip([id.unity, id.reproduction, id.grad_sum, id.grad_moment])
        {
            *w = w.max(v);
        }
    }
    let names = [
        "partition of unity",
        "linear reproduction",
        "gradient sum",
        "gradient moment",
    ];
    for (name, w) in names.iter().zip(worst) {
        assert!(w <= tol, "{what}: {name} error {w:.3e} > {tol:.1e}");
    }
}

#[test]
fn linear_satisfies_the_identities_on_regular_and_perturbed_grids() {
    check_all(
        &Shape::Linear,
        &grid(0.0),
        0.0,
        TOL_CLOSED,
        "linear, regular",
    );
    check_all(
        &Shape::Linear,
        &grid(0.2),
        0.0,
        TOL_ISO,
        "linear, perturbed 0.2 h",
    );
}

#[test]
fn ugimp_satisfies_the_identities_on_a_regular_grid() {
    for ppc in [1, 2, 3] {
        let u = Ugimp::new(0.5, ppc);
        let lp = u.lp;
        check_all(
            &Shape::Ugimp(u),
            &grid(0.0),
            lp,
            TOL_CLOSED,
            &format!("ugimp ppc {ppc}"),
        );
    }
}

#[test]
fn ugimp_on_a_perturbed_grid_keeps_unity_but_loses_linear_reproduction() {
    // uGIMP is a regular-grid method (paper §3.3): on a perturbed grid our
    // lattice-space extension keeps the partition of unity and Σ∇N = 0, but
    // Σ N_a x_a ≠ x. The defect must be there and of the perturbation's size.
    let g = grid(0.2);
    let u = Ugimp::new(0.5, 2);
    // Keep the particle square inside the grid in lattice units as well:
    // nodes next to the edge move by up to 0.2 h.
    let margin = u.lp + 0.3 * g.h;
    let shape = Shape::Ugimp(u);
    let mut worst_repro = 0.0f64;
    for x in points(&g, margin, 400, 5) {
        let id = identities(&shape, &g, x).unwrap();
        assert!(
            id.unity < TOL_CLOSED && id.grad_sum < TOL_ISO,
            "unity {} grad {}",
            id.unity,
            id.grad_sum
        );
        worst_repro = worst_repro.max(id.reproduction);
    }
    assert!(
        worst_repro > 1e-3,
        "expected a reproduction defect, got {worst_repro:.2e} h"
    );
    assert!(
        worst_repro < 0.2 * std::f64::consts::SQRT_2,
        "defect {worst_repro:.2e} h exceeds the node displacement"
    );
}

#[test]
fn lme_satisfies_the_identities_for_every_gamma_and_layout() {
    for gamma in [0.8, 2.0, 3.0, 4.0, 6.0] {
        for perturb in [0.0, 0.2] {
            let g = grid(perturb);
            let lme = Lme::new(gamma, 1e-6, g.h, perturb);
            check_all(
                &Shape::Lme(lme),
                &g,
                1e-3 * g.h,
                TOL_LME,
                &format!("lme gamma {gamma} perturb {perturb}"),
            );
        }
    }
}

#[test]
fn lme_approaches_bilinear_as_gamma_grows() {
    // On a square lattice the athermal limit of LME is the max-ent
    // combination of the cell's 4 corners: exactly Q4. Compare at interior
    // points (support not cut by the boundary).
    let g = grid(0.0);
    let interior: Vec<[f64; 2]> = points(&g, 2.5 * g.h, 200, 3).into_iter().collect();
    let mut last = f64::INFINITY;
    // Up to γ = 8: nearer the largest γ allowed (10.6 for tol 1e-6) the
    // support cut at r = h·sqrt(−ln tol/γ) drops nodes whose weight is no
    // longer negligible once λ tilts the weights, and the gap grows again.
    for gamma in [1.0, 2.0, 4.0, 6.0, 8.0] {
        let lme = Lme::new(gamma, 1e-6, g.h, 0.0);
        let mut worst = 0.0f64;
        for &x in &interior {
            let (mut nl, mut wl) = (vec![0u32; lme.max_nodes()], vec![[0.0; 3]; lme.max_nodes()]);
            let mut lam = [0.0; 2];
            let n = lme.eval(&g, x, &mut lam, &mut nl, &mut wl).unwrap().0;
            let (mut nq, mut wq) = ([0u32; 4], [[0.0; 3]; 4]);
            linear::eval(&g, x, &mut nq, &mut wq).unwrap();
            for k in 0..n {
                let q = nq
                    .iter()
                    .position(|&m| m == nl[k])
                    .map_or(0.0, |i| wq[i][0]);
                worst = worst.max((wl[k][0] - q).abs());
            }
        }
        assert!(
            worst < last,
            "gamma {gamma}: max |N_lme - N_q4| = {worst:.4} did not drop below {last:.4}"
        );
        last = worst;
    }
    assert!(
        last < 0.01,
        "at gamma 8 LME should be within 0.01 of Q4, got {last:.4}"
    );
}

#[test]
fn lme_newton_converges_from_cold_starts_within_the_cap() {
    let mut worst = 0;
    for gamma in [0.8, 1.5, 3.0, 4.5, 6.0] {
        for perturb in [0.0, 0.2] {
            let g = grid(perturb);
            let lme = Lme::new(gamma, 1e-6, g.h, perturb);
            let mut nodes = vec![0u32; lme.max_nodes()];
            let mut w = vec![[0.0; 3]; lme.max_nodes()];
            for x in points(&g, 1e-3 * g.h, 300, 17) {
                let mut lam = [0.0; 2];
                let (_, its) = lme
                    .eval(&g, x, &mut lam, &mut nodes, &mut w)
                    .unwrap_or_else(|e| {
                        panic!("gamma {gamma} perturb {perturb} at {x:?}: {e}");
                    });
                worst = worst.max(its);
            }
        }
    }
    assert!(
        worst <= lme_mpm::model::shape::lme::NEWTON_MAX_ITER,
        "worst {worst}"
    );
    // A warm start at the solution converges without a single step.
    let g = grid(0.0);
    let lme = Lme::new(4.0, 1e-6, g.h, 0.0);
    let (mut nodes, mut w) = (vec![0u32; lme.max_nodes()], vec![[0.0; 3]; lme.max_nodes()]);
    let x = [0.33, 3.1];
    let mut lam = [0.0; 2];
    lme.eval(&g, x, &mut lam, &mut nodes, &mut w).unwrap();
    let (_, its) = lme.eval(&g, x, &mut lam, &mut nodes, &mut w).unwrap();
    assert_eq!(its, 0, "warm start should already be converged");
}

#[test]
fn lme_newton_failure_is_reported_not_nan() {
    let g = grid(0.0);
    // Forced past its cap: one iteration from a cold start near a corner.
    let mut lme = Lme::new(6.0, 1e-6, g.h, 0.0);
    lme.max_iter = 1;
    let (mut nodes, mut w) = (vec![0u32; lme.max_nodes()], vec![[0.0; 3]; lme.max_nodes()]);
    let mut lam = [0.0; 2];
    let x = [g.min[0] + 1e-4 * g.h, g.min[1] + 0.37 * g.h];
    match lme.eval(&g, x, &mut lam, &mut nodes, &mut w) {
        Err(ShapeFault::LmeNotConverged {
            iterations,
            residual,
        }) => {
            assert_eq!(iterations, 1);
            assert!(residual.is_some_and(|r| r.is_finite() && r > 0.0));
        }
        other => panic!("expected LmeNotConverged, got {other:?}"),
    }
    assert!(
        lam.iter().all(|l| l.is_finite()) && lam == [0.0; 2],
        "λ must be left untouched on failure"
    );
    // Outside the grid: a fault, not a NaN.
    let lme = Lme::new(4.0, 1e-6, g.h, 0.0);
    let out = [g.max()[0] + 0.1, 3.0];
    assert_eq!(
        lme.eval(&g, out, &mut lam, &mut nodes, &mut w).unwrap_err(),
        ShapeFault::OutsideGrid
    );
}

#[test]
fn bsplines_satisfy_the_identities_inside_and_at_the_open_knot_boundary() {
    // With open knot vectors the basis "positions" that reproduce linear
    // fields are the Greville abscissae (nodes away from the edge, pulled in
    // next to it), so reproduction is checked against those.
    use lme_mpm::model::shape::bspline::{Bspline, greville};
    let g = grid(0.0);
    for (degree, cells) in [(2, false), (3, false), (2, true), (3, true)] {
        let b = Bspline { degree, cells };
        let e = b.end();
        let shape = Shape::Bspline(b);
        let mut worst = [0.0f64; 4];
        // The cells layout's bases live e cells inside its nodes.
        for x in points(&g, e * g.h, 400, 23) {
            let mut nodes = vec![0u32; shape.max_nodes()];
            let mut w = vec![[0.0; 3]; shape.max_nodes()];
            let n = shape
                .eval(&g, x, &mut [0.0; 2], &mut nodes, &mut w)
                .unwrap();
            let (mut s, mut rx, mut gs, mut gm) = (0.0, [0.0; 2], [0.0; 2], [[0.0; 2]; 2]);
            for k in 0..n {
                let node = nodes[k] as usize;
                let xa = [
                    g.min[0] + g.h * greville(node % g.nx, g.nx, degree, e),
                    g.min[1] + g.h * greville(node / g.nx, g.ny, degree, e),
                ];
                assert!(w[k][0] >= -TOL_CLOSED);
                s += w[k][0];
                for d in 0..2 {
                    rx[d] += w[k][0] * xa[d];
                    gs[d] += w[k][1 + d];
                    for e in 0..2 {
                        gm[d][e] += (xa[d] - x[d]) * w[k][1 + e];
                    }
                }
            }
            let errs = [
                (s - 1.0).abs(),
                (rx[0] - x[0]).hypot(rx[1] - x[1]) / g.h,
                gs[0].hypot(gs[1]) * g.h,
                (gm[0][0] - 1.0)
                    .abs()
                    .max((gm[1][1] - 1.0).abs())
                    .max(gm[0][1].abs())
                    .max(gm[1][0].abs()),
            ];
            for (w, e) in worst.iter_mut().zip(errs) {
                *w = w.max(e);
            }
        }
        for (name, w) in ["unity", "reproduction", "gradient sum", "gradient moment"]
            .iter()
            .zip(worst)
        {
            assert!(w <= TOL_CLOSED, "bspline{degree}: {name} error {w:.3e}");
        }
    }
}

/// `solver.bspline_knots` is read with B-splines only; a bad value or the
/// key beside another shape is refused with exit 2 naming it.
#[test]
fn bspline_knots_are_checked_naming_the_key() {
    use lme_mpm::scene::{Override, Scene};
    let case = crate::common::case("aligned_vibration.toml");
    for (set, key) in [
        (
            ["solver.shape=lme", "solver.bspline_knots=cells"],
            "solver.bspline_knots",
        ),
        (
            ["solver.shape=bspline2", "solver.bspline_knots=grid"],
            "unknown variant `grid`",
        ),
    ] {
        let o: Vec<Override> = set.iter().map(|s| Override::parse(s).unwrap()).collect();
        let e = Scene::load(&case, &o)
            .err()
            .unwrap_or_else(|| panic!("{set:?} was accepted"));
        let msg = e.to_string();
        assert!(msg.contains(key), "{set:?}: {msg}");
        assert_eq!(lme_mpm::Error::from(e).exit_code(), 2);
    }
    for shape in ["bspline2", "bspline3"] {
        let set = [
            format!("solver.shape={shape}"),
            "solver.bspline_knots=cells".into(),
        ];
        let o: Vec<Override> = set.iter().map(|s| Override::parse(s).unwrap()).collect();
        let scene = Scene::load(&case, &o).unwrap();
        let m = lme_mpm::model::Model::new(&scene).unwrap();
        // 16 cells: 16 + p bases per direction, the nodes shifted out by (p − 1)/2 cells.
        let p = if shape == "bspline2" { 2 } else { 3 };
        assert_eq!(m.grid.nx, 16 + p, "{shape}");
        assert!(
            (m.grid.min[0] + 0.5 * (p - 1) as f64 * m.grid.h).abs() < 1e-12,
            "{shape}"
        );
    }
}
