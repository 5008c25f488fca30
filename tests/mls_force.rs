//! MLS as a correction of the internal force's quadrature only
//! (`solver.mls_scope = "force"`, issue 28; docs/methods.md, "MLS as a
//! force correction"), on the CPU path (f64):
//!   f_I = −Σ_p V_p σ_p ∇N_I(x_p)
//!         − [Σ_g ω_g σ_h(x_g) ∇N_I(x_g) − Σ_p V_p σ_h(x_p) ∇N_I(x_p)].
//! The bracket makes the force exact for a linear stress field whatever the
//! particle layout, and, with mass, momentum and the updates left to the
//! particles, a free vibration keeps its energy where the paper's step
//! (`"all"`) runs away.

use lme_mpm::cpu::CpuBackend;
use lme_mpm::cpu::ShapeCache;
use lme_mpm::cpu::mls::Mls;
use lme_mpm::cpu::scatter::Scatter;
use lme_mpm::model::shape::Shape;
use lme_mpm::model::shape::bspline::Bspline;
use lme_mpm::model::{Grid, Model};
use lme_mpm::scene::{Override, Scene};

const CASE: &str = include_str!("../cases/aligned_vibration.toml");

/// f64 round-off of the force sums (a few hundred terms of size |σ| h),
/// relative to the largest nodal force: the 1e-12.
const EXACT: f64 = 1e-12;

fn model(text: &str, sets: &[String]) -> Model {
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let scene = Scene::from_str(text, "test", "test", &o).unwrap();
    Model::new(&scene).unwrap()
}

/// −∫ σ ∇N_I over the unit square for every node I, by 3 × 3 Gauss points
/// on each half-cell: exact for B-splines and linear shapes (polynomial on
/// each half-cell, whose breaks hold every knot) times a linear σ.
fn exact_forces(shape: &Shape, grid: &Grid, sig: impl Fn([f64; 2]) -> [f64; 3]) -> Vec<[f64; 2]> {
    let (a, w) = (0.6f64.sqrt(), [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]);
    let pts = [-a, 0.0, a];
    let half = grid.h / 2.0;
    let n_half = 2 * (grid.nx - 1);
    let mut f = vec![[0.0; 2]; grid.n_nodes()];
    let (mut nodes, mut nw) = (
        vec![0u32; shape.max_nodes()],
        vec![[0.0; 3]; shape.max_nodes()],
    );
    for j in 0..n_half {
        for i in 0..n_half {
            for (qy, wy) in pts.iter().zip(w) {
                for (qx, wx) in pts.iter().zip(w) {
                    let x = [
                        (i as f64 + 0.5 + 0.5 * qx) * half,
                        (j as f64 + 0.5 + 0.5 * qy) * half,
                    ];
                    let om = wx * wy * 0.25 * half * half;
                    let s = sig(x);
                    let n = shape
                        .eval(grid, x, &mut [0.0; 2], &mut nodes, &mut nw)
                        .unwrap();
                    for k in 0..n {
                        let g = nw[k];
                        let o = &mut f[nodes[k] as usize];
                        o[0] -= om * (s[0] * g[1] + s[2] * g[2]);
                        o[1] -= om * (s[2] * g[1] + s[1] * g[2]);
                    }
                }
            }
        }
    }
    f
}

/// A linear stress field on jittered particles (24 × 24 over the unit
/// square that fills an 8-cell grid, each moved up to 0.4 of its spacing)
/// gives, at every node (the edge and corner nodes of the open knots
/// included), the nodal internal force of the 2 × 2 Gauss rule applied to
/// the field itself, −Σ_g ω_g σ(x_g) ∇N_I(x_g), whatever the particles'
/// layout and volumes; for linear shapes and bspline2 that rule is exact
/// (σ ∇N is cubic per direction at most), so the force is the exact
/// −∫σ∇N_I. bspline3's N is cubic, σ ∂N/∂x quartic along y, where 2 Gauss
/// points are not exact: its force is the Gauss rule's (7e-3 of the
/// largest force from the exact integral at 8 cells, O(h⁴)). The
/// particles' own quadrature (the bracket left out) misses by more than
/// 1 % of the largest force for all three.
#[test]
fn a_linear_stress_gives_the_exact_nodal_force_on_scattered_particles() {
    for shape in [
        Shape::Linear,
        Shape::Bspline(Bspline::midpoints(2)),
        Shape::Bspline(Bspline::midpoints(3)),
    ] {
        let h = 0.125;
        let grid = Grid::regular(h, [0.0, 0.0], 9, 9);
        let mut rng = lme_mpm::rng::SplitMix64::new(7);
        let mut x = Vec::new();
        for j in 0..24 {
            for i in 0..24 {
                let mut jitter = || rng.range(-0.4, 0.4);
                x.push([
                    (i as f64 + 0.5 + jitter()) * h / 3.0,
                    (j as f64 + 0.5 + jitter()) * h / 3.0,
                ]);
            }
        }
        let n = x.len();
        let sig = |x: [f64; 2]| {
            [
                1e3 * (1.0 + x[0] - 2.0 * x[1]),
                3e2 * x[1],
                -5e2 * x[0] + 1e2,
            ]
        };
        let stress: Vec<[f64; 3]> = x.iter().map(|&p| sig(p)).collect();
        // Volumes that do not sum to the square's area: the correction
        // needs none of the particle quadrature's accuracy.
        let mass: Vec<f64> = (0..n)
            .map(|p| (1.0 + 0.3 * (p % 5) as f64) / n as f64)
            .collect();
        let rho = vec![1.0; n];
        let mut cache = ShapeCache::new(n, shape.max_nodes());
        lme_mpm::cpu::shape_eval::shape_eval(&shape, &grid, &x, &mut [], &mut cache).unwrap();
        let mut mls = Mls::new(&shape, &grid, n).unwrap().for_force_correction();
        mls.fit_stress(&grid, &x, &stress);
        assert!(
            mls.cell_ok.iter().all(|&ok| ok),
            "{shape:?}: every fit is regular"
        );
        let mut force = vec![[0.0; 2]; grid.n_nodes()];
        let body = |_p: usize| [0.0, 0.0];
        mls.corrected_forces(
            &cache,
            &stress,
            &mass,
            &rho,
            &body,
            &mut force,
            &mut Scatter::default(),
        );
        let mut plain = vec![[0.0; 2]; grid.n_nodes()];
        lme_mpm::cpu::forces::forces(
            lme_mpm::cpu::Weights::Cache(&cache),
            &x,
            &stress,
            &[],
            &mass,
            &rho,
            &lme_mpm::cpu::stage_inputs::BodyForce::uniform([0.0, 0.0]),
            &mut plain,
            &mut Scatter::default(),
        )
        .unwrap();
        // The 2 × 2 Gauss rule on the exact field.
        let mut gauss = vec![[0.0; 2]; grid.n_nodes()];
        for g in 0..mls.n_gauss_points() {
            let (s, om) = (sig(mls.gp_x[g]), mls.gp_w[g]);
            let (nodes, w) = mls.gp_shape.particle(g);
            for (&node, wk) in nodes.iter().zip(w) {
                let o = &mut gauss[node as usize];
                o[0] -= om * (s[0] * wk[1] + s[2] * wk[2]);
                o[1] -= om * (s[2] * wk[1] + s[1] * wk[2]);
            }
        }
        let exact = exact_forces(&shape, &grid, sig);
        let scale = exact.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = |f: &[[f64; 2]], r: &[[f64; 2]]| {
            f.iter()
                .zip(r)
                .flat_map(|(a, b)| [(a[0] - b[0]).abs(), (a[1] - b[1]).abs()])
                .fold(0.0f64, f64::max)
                / scale
        };
        let (to_gauss, to_exact, particles) = (
            err(&force, &gauss),
            err(&force, &exact),
            err(&plain, &exact),
        );
        println!(
            "{shape:?}: corrected {to_gauss:.2e} from the Gauss rule, {to_exact:.2e} from the \
             exact integral; particles only {particles:.2e}, of max |f|"
        );
        assert!(to_gauss < EXACT, "{shape:?}: {to_gauss:e}");
        if shape != Shape::Bspline(Bspline::midpoints(3)) {
            assert!(to_exact < EXACT, "{shape:?}: {to_exact:e}");
        }
        assert!(particles > 1e-2, "{shape:?}: {particles:e}");
    }
}

/// The strain-rate correction is the transpose of the force's bracket: for
/// random stresses σ_q and nodal velocities v_I on jittered particles, the
/// stress power of the corrected strain rates, Σ_q V_q σ_q : (L_q + ΔL_q),
/// equals the corrected forces' work −Σ_I v_I · f_I (to f64 round-off, 1e-12
/// of Σ_q V_q |σ_q : L_q| term by term), while the plain L_q alone misses it by the
/// bracket's work (more than 1e-3 of that scale here). That identity is
/// what keeps the free vibration's energy (below).
#[test]
fn the_strain_correction_is_the_transpose_of_the_force_bracket() {
    for shape in [
        Shape::Linear,
        Shape::Bspline(Bspline::midpoints(2)),
        Shape::Bspline(Bspline::midpoints(3)),
    ] {
        let h = 0.125;
        let grid = Grid::regular(h, [0.0, 0.0], 9, 9);
        let mut rng = lme_mpm::rng::SplitMix64::new(5);
        let mut x = Vec::new();
        for j in 0..24 {
            for i in 0..24 {
                let mut jitter = || rng.range(-0.4, 0.4);
                x.push([
                    (i as f64 + 0.5 + jitter()) * h / 3.0,
                    (j as f64 + 0.5 + jitter()) * h / 3.0,
                ]);
            }
        }
        let n = x.len();
        let stress: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                [
                    rng.range(-1e5, 1e5),
                    rng.range(-1e5, 1e5),
                    rng.range(-5e4, 5e4),
                ]
            })
            .collect();
        let mass: Vec<f64> = (0..n)
            .map(|p| (1.0 + 0.3 * (p % 5) as f64) / n as f64)
            .collect();
        let rho: Vec<f64> = (0..n).map(|p| 1.0 + 0.1 * (p % 3) as f64).collect();
        let mv: Vec<[f64; 3]> = (0..grid.n_nodes())
            .map(|_| [1.0, rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)])
            .collect();
        let mut cache = ShapeCache::new(n, shape.max_nodes());
        lme_mpm::cpu::shape_eval::shape_eval(&shape, &grid, &x, &mut [], &mut cache).unwrap();
        let mut mls = Mls::new(&shape, &grid, n).unwrap().for_force_correction();
        mls.fit_stress(&grid, &x, &stress);
        let mut force = vec![[0.0; 2]; grid.n_nodes()];
        let body = |_p: usize| [0.0, 0.0];
        mls.corrected_forces(
            &cache,
            &stress,
            &mass,
            &rho,
            &body,
            &mut force,
            &mut Scatter::default(),
        );
        let mut dl = vec![[0.0; 4]; n];
        mls.strain_correction(&grid, &cache, &mv, &mass, &rho, &mut dl);
        let work: f64 = -force
            .iter()
            .zip(&mv)
            .map(|(f, v)| f[0] * v[1] + f[1] * v[2])
            .sum::<f64>();
        let (mut plain, mut corrected, mut scale) = (0.0, 0.0, 0.0);
        for q in 0..n {
            let (nodes, w) = cache.particle(q);
            let mut l = [0.0; 4];
            for (&node, wk) in nodes.iter().zip(w) {
                let v = mv[node as usize];
                l = [
                    l[0] + v[1] * wk[1],
                    l[1] + v[1] * wk[2],
                    l[2] + v[2] * wk[1],
                    l[3] + v[2] * wk[2],
                ];
            }
            let s = stress[q];
            let vol = mass[q] / rho[q];
            let power = |l: [f64; 4]| vol * (s[0] * l[0] + s[1] * l[3] + s[2] * (l[1] + l[2]));
            let lc = [
                l[0] + dl[q][0],
                l[1] + dl[q][1],
                l[2] + dl[q][2],
                l[3] + dl[q][3],
            ];
            plain += power(l);
            corrected += power(lc);
            scale +=
                vol * ((s[0] * l[0]).abs() + (s[1] * l[3]).abs() + (s[2] * (l[1] + l[2])).abs());
        }
        let (err, miss) = (
            (corrected - work).abs() / scale,
            (plain - work).abs() / scale,
        );
        println!(
            "{shape:?}: corrected power off the forces' work by {err:.2e}, plain by {miss:.2e}"
        );
        assert!(err < EXACT, "{shape:?}: {err:e}");
        assert!(miss > 1e-3, "{shape:?}: {miss:e}");
    }
}

/// What the strain-rate correction costs: it is the transpose of the
/// bracket, not a consistent gradient. Under a uniform velocity gradient L
/// it adds ΔL_q = L (V̂_q − Ṽ_q)/V_q, V̂_q = Σ_g ω_g φ_q(x_g) and
/// Ṽ_q = Σ_p V_p φ_q(x_p) the Gauss rule's and the particles' quadratures
/// of particle q's fit function, which differ by a pattern that scales
/// with h: on 3 × 3 regular particles per cell, measured 2026-11-25,
/// |ΔL_xx / L_xx| reaches 3.6e-3 (bspline2; 6.4e-3 and 5.6e-3 bspline3)
/// more than 3.5 cells from the edges and 0.016 (0.025) within them, the
/// same at 8 and 16 cells. Asserted as measured (bands ×1.5 up, ÷1.5
/// down), so a change that makes the correction consistent, or worse,
/// shows here (docs/methods.md, "MLS as a force correction").
#[test]
fn the_strain_correction_of_a_uniform_gradient_is_as_measured() {
    for cells in [8usize, 16] {
        for (degree, inner_max, edge_max) in [(2, 3.6e-3, 0.016), (3, 6.4e-3, 0.025)] {
            let shape = Shape::Bspline(Bspline {
                degree,
                cells: false,
            });
            let h = 1.0 / cells as f64;
            let grid = Grid::regular(h, [0.0, 0.0], cells + 1, cells + 1);
            let mut x = Vec::new();
            for j in 0..3 * cells {
                for i in 0..3 * cells {
                    x.push([(i as f64 + 0.5) * h / 3.0, (j as f64 + 0.5) * h / 3.0]);
                }
            }
            let n = x.len();
            let (mass, rho) = (vec![1.0 / n as f64; n], vec![1.0; n]);
            // v = L x, L = [[1, 0.5], [−0.3, 2]], at the Greville abscissae
            // (the B-splines reproduce it exactly).
            let gr = |i: usize, nn: usize| {
                lme_mpm::model::shape::bspline::greville(i, nn, degree, 0.0) * h
            };
            let mut mv = vec![[0.0; 3]; grid.n_nodes()];
            for j in 0..grid.ny {
                for i in 0..grid.nx {
                    let (px, py) = (gr(i, grid.nx), gr(j, grid.ny));
                    mv[j * grid.nx + i] = [1.0, px + 0.5 * py, -0.3 * px + 2.0 * py];
                }
            }
            let mut cache = ShapeCache::new(n, shape.max_nodes());
            lme_mpm::cpu::shape_eval::shape_eval(&shape, &grid, &x, &mut [], &mut cache).unwrap();
            let mut mls = Mls::new(&shape, &grid, n).unwrap().for_force_correction();
            mls.fit_stress(&grid, &x, &vec![[0.0; 3]; n]);
            let mut dl = vec![[0.0; 4]; n];
            mls.strain_correction(&grid, &cache, &mv, &mass, &rho, &mut dl);
            let (mut inner, mut edge) = (0.0f64, 0.0f64);
            for (xq, d) in x.iter().zip(&dl) {
                let from_edge = xq[0].min(1.0 - xq[0]).min(xq[1].min(1.0 - xq[1])) / h;
                let r = d[0].abs();
                if from_edge > 3.5 {
                    inner = inner.max(r);
                } else {
                    edge = edge.max(r);
                }
            }
            println!(
                "{cells} cells bspline{degree}: |ΔLxx/Lxx| inside {inner:.2e}, near edges {edge:.3}"
            );
            assert!(
                inner > inner_max / 1.5 && inner < 1.5 * inner_max,
                "{cells} {degree}: {inner}"
            );
            assert!(
                edge > edge_max / 1.5 && edge < 1.5 * edge_max,
                "{cells} {degree}: {edge}"
            );
        }
    }
}

/// Kinetic + strain energy over E0 of the aligned vibration's square
/// vibrating freely (no body force; the case's initial velocity, A = 0.1 m)
/// on `cells` cells with bspline2 and MUSL, at every step to `t_end`:
/// (min, max, whether it completed).
fn free_energy(cells: usize, sets: &[&str], t_end: f64) -> (f64, f64, bool) {
    let mut s = vec![
        "solver.shape=bspline2".to_string(),
        "solver.integrator=musl".to_string(),
        format!("grid.h={}", 1.0 / cells as f64),
    ];
    s.extend(sets.iter().map(|s| s.to_string()));
    let mut m = model(CASE, &s);
    m.manufactured = None;
    let mut cpu = CpuBackend::new(m);
    let energy = |c: &CpuBackend| {
        let e = lme_mpm::cpu::energy::energy(c.model());
        e.kinetic + e.strain
    };
    let e0 = energy(&cpu);
    let (mut lo, mut hi) = (1.0f64, 1.0f64);
    let mut t = 0.0;
    while t < t_end - 1e-12 {
        if cpu.step().is_err() {
            return (lo, hi, false);
        }
        t += cpu.dt();
        cpu.set_time(t);
        let e = energy(&cpu) / e0;
        if !e.is_finite() || e > 10.0 {
            return (lo, hi, false);
        }
        (lo, hi) = (lo.min(e), hi.max(e));
    }
    (lo, hi, true)
}

/// The energy figure: freely vibrating on 8 cells for 0.2 s (ten
/// periods), kinetic + strain energy stays within ±0.5 % of E0. Measured
/// 2026-11-25: plain bspline2 [0.99706, 1.00325] E0; the force correction
/// [0.99706, 1.00325] E0 with the strain-rate correction (the transpose of
/// the bracket, `Mls::strain_correction`), [0.99344, 1.00266] E0 without it:
/// the bracket's work, not stored as strain energy, was the whole 0.66 %
/// loss (docs/methods.md, "MLS as a force correction"). The paper's step
/// leaves [0.85, 1.4] within 0.03 s (`tests/mls_reconstruction.rs`).
/// The band, ±0.5 % of E0.
const ENERGY_BAND: f64 = 0.005;

/// Checks one mode's free vibration to `t_end` against the band. The
/// suite holds two periods (0.04 s); the ten (0.2 s, the force
/// correction's 20000 steps take about 70 s alone on 2 cores, 2026-12-02)
/// are the ignored `…_over_ten_periods` acceptance runs:
///   cargo test --release --test suite -- --ignored mls_force::
fn keeps_energy(name: &str, sets: &[&str], t_end: f64) {
    let (lo, hi, done) = free_energy(8, sets, t_end);
    println!("{name} to {t_end} s: E/E0 in [{lo:.5}, {hi:.5}], completed {done}");
    assert!(done, "{name} completes");
    assert!(
        lo > 1.0 - ENERGY_BAND && hi < 1.0 + ENERGY_BAND,
        "{name}: [{lo}, {hi}]"
    );
}

const FORCE: &[&str] = &["solver.mls=true", "solver.mls_scope=force"];

#[test]
fn the_force_correction_keeps_a_free_vibrations_energy() {
    keeps_energy("force correction", FORCE, 0.04);
}

/// Plain bspline2 beside it, the reference for the band.
#[test]
fn plain_bspline2_keeps_a_free_vibrations_energy() {
    keeps_energy("plain bspline2", &["solver.mls=false"], 0.04);
}

#[test]
#[ignore]
fn the_force_correction_keeps_a_free_vibrations_energy_over_ten_periods() {
    keeps_energy("force correction", FORCE, 0.2);
}

#[test]
#[ignore]
fn plain_bspline2_keeps_a_free_vibrations_energy_over_ten_periods() {
    keeps_energy("plain bspline2", &["solver.mls=false"], 0.2);
}
