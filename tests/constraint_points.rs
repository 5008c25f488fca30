//! Constraints at their geometric place (issue 23, item 2): a clamp whose
//! region's edge lies inside the grid holds the body along that edge,
//! whatever the shape. The stiff cantilever (E = 9 GPa, Timoshenko
//! 0.0067806 m) clamped at x = 0, with the grid's edge on the clamp and
//! with the grid two cells beyond it (implicit, static); an explicit
//! column on a base two cells inside a B-spline grid against the same
//! column on the grid's edge, on the CPU and on the GPU; the held velocity
//! at the points themselves.

use crate::common;

use lme_mpm::exact::Errors;
use lme_mpm::exact::cantilever::CantileverErrors;
use lme_mpm::model::Model;
use lme_mpm::solver::RunStatus;

/// The bound: the clamp two cells inside the grid within 0.5 % of
/// the clamp on the grid's edge. Measured (h = 0.25 m, 2 × 2 particles per
/// cell): bspline2 +0.36 %, bspline3 +0.001 % (before the points: +4.66 %
/// and +18.9 %); linear, uGIMP and LME keep their nodes, 0, 0 and +0.09 %
/// (docs/methods.md, "Constraints at their place").
const CLAMP_REL: f64 = 0.005;

/// The stiff beam: cantilever.toml with E 100 times larger, so the
/// deflection is small (linear) and Timoshenko's 0.0067806 m.
const STIFF: &str = "materials.beam.E=9e9";

fn cantilever(r: &common::Run) -> CantileverErrors {
    match &r.errors {
        Some(Errors::Cantilever(e)) => e.clone(),
        other => panic!("not a cantilever score: {other:?}"),
    }
}

/// Tip deflection (m) of the stiff cantilever with `shape`, the grid's left
/// edge at `x0` (m; the clamp's edge is at x = 0).
fn tip(shape: &str, x0: f64) -> f64 {
    let r = common::run(
        "cantilever.toml",
        &[
            STIFF,
            &format!("solver.shape={shape}"),
            &format!("grid.min=[{x0}, -1.5]"),
            "grid.max=[9.5, 2.5]",
        ],
    );
    assert_eq!(r.status, RunStatus::Completed, "{shape} x0 = {x0}");
    // The clamp carries the beam's weight, ρ g L H = 784800 N/m... of the
    // soft beam's density: 1000 · 9.81 · 8 · 1.
    let reaction = r.recorder.samples.last().unwrap().reactions[0][1];
    assert!(
        (reaction - 78_480.0).abs() < 1e-6 * 78_480.0,
        "{shape} x0 = {x0}: reaction {reaction}"
    );
    cantilever(&r).deflection
}

#[test]
fn clamp_inside_the_grid_holds_like_the_grid_edge() {
    let h = 0.25;
    let mut worst = Vec::new();
    for shape in ["bspline2", "bspline3", "linear", "ugimp", "lme"] {
        let edge = tip(shape, 0.0);
        let beyond = tip(shape, -2.0 * h);
        let rel = (beyond - edge) / edge;
        println!(
            "{shape:>8}: tip {edge:.7} m (grid edge on the clamp), {beyond:.7} m (two cells \
             beyond), {:+.3} %",
            100.0 * rel
        );
        worst.push((shape, rel));
    }
    for (shape, rel) in worst {
        assert!(rel.abs() < CLAMP_REL, "{shape}: {:+.3} %", 100.0 * rel);
    }
}

#[test]
fn points_sit_on_the_edge_where_the_body_is() {
    // Two cells of grid beyond the clamp: bspline2's node at x = h weighs
    // 1/8 at x = 0, so the clamp needs its points; along x = 0 over the
    // beam's 1 m at two per cell (h = 0.25): 8 points.
    let s = common::scene(
        "cantilever.toml",
        &[STIFF, "grid.min=[-0.5, -1.5]", "grid.max=[9.5, 2.5]"],
    );
    let m = Model::new(&s).unwrap();
    let pts = &m.constraints.points;
    assert_eq!(pts.len(), 8, "{pts:?}");
    for p in pts {
        assert_eq!(p.x[0], 0.0);
        assert!(p.x[1] > 0.0 && p.x[1] < 1.0, "{p:?}");
    }
    // With the grid's edge on the clamp, with linear shapes (whose nodes
    // beyond x = 0 weigh nothing there), with LME (which keeps its
    // nodes), for a region that is a line (a pin) or one that holds
    // particles: no points, the scene runs as before.
    let beyond = ["grid.min=[-0.5, -1.5]", "grid.max=[9.5, 2.5]"];
    for sets in [
        vec![STIFF],
        vec![STIFF, beyond[0], beyond[1], "solver.shape=linear"],
        vec![STIFF, beyond[0], beyond[1], "solver.shape=lme"],
        vec![
            STIFF,
            beyond[0],
            beyond[1],
            "constraints.clamp.min=[0.0, -inf]",
        ],
        vec![
            STIFF,
            beyond[0],
            beyond[1],
            "constraints.clamp.max=[0.5, inf]",
        ],
    ] {
        let sets = &sets[..];
        let m = Model::new(&common::scene("cantilever.toml", sets)).unwrap();
        assert!(m.constraints.points.is_empty(), "{sets:?}");
    }
}

/// The explicit column: settlement of its top row (m) with `shape`, NPC,
/// the base's region y ≤ 0 and the grid's lower edge at `y0` (m).
fn column_top(shape: &str, y0: f64) -> f64 {
    let r = common::run(
        "elastic_block.toml",
        &[
            &format!("solver.shape={shape}"),
            "grid.h=1.0",
            &format!("grid.min=[-2.0, {y0}]"),
            "grid.max=[12.0, 12.0]",
        ],
    );
    assert_eq!(r.status, RunStatus::Completed, "{shape} y0 = {y0}");
    common::column(&r).settlement_top
}

/// The base two cells inside the grid within this of the base on the
/// grid's edge (explicit NPC, the elastic block at h = 1 m after its
/// gravity ramp). Measured: bspline2 +0.21 %, bspline3 −0.02 % (before the
/// points: +6.7 % and +26.8 %; docs/methods.md).
const BASE_REL: f64 = 0.005;

#[test]
fn explicit_base_inside_the_grid_holds_like_the_grid_edge() {
    for shape in ["bspline2", "bspline3"] {
        let edge = column_top(shape, 0.0);
        let beyond = column_top(shape, -2.0);
        let rel = (beyond - edge) / edge;
        println!(
            "{shape:>8}: top settlement {edge:.6} m (grid edge on the base), {beyond:.6} m (two \
             cells beyond), {:+.3} %",
            100.0 * rel
        );
        assert!(rel.abs() < BASE_REL, "{shape}: {:+.3} %", 100.0 * rel);
    }
}

/// The projection's residual at the points (m/s, for velocities of order
/// 1 m/s): `HOLD_REG` (1e-10) and two refinements leave round-off;
/// measured 1.0e-14 (bspline2) and 6.9e-16 (bspline3), bound 100 times.
const HELD_REL: f64 = 1e-12;

#[test]
fn the_projection_holds_every_point_and_its_force_is_the_reaction() {
    use lme_mpm::cpu::constraint_points::{AsForce, hold};
    for shape in ["bspline2", "bspline3"] {
        let s = common::scene(
            "cantilever.toml",
            &[
                STIFF,
                &format!("solver.shape={shape}"),
                "grid.min=[-0.5, -1.5]",
                "grid.max=[9.5, 2.5]",
                "constraints.clamp.velocity=[0.3, -0.2]",
                // Points cannot move with their region: travel under half
                // a spacing by t_end (0.06 m, h = 0.25), or Model::new
                // refuses the scene.
                "solver.t_end=0.2",
            ],
        );
        let m = Model::new(&s).unwrap();
        let pts = &m.constraints.points;
        assert!(!pts.is_empty());
        // Masses and momenta of a smooth field on the nodes near the clamp.
        let n = m.grid.n_nodes();
        let mut mv = vec![[0.0; 3]; n];
        for (a, node) in mv.iter_mut().enumerate() {
            let (i, j) = ((a % m.grid.nx) as f64, (a / m.grid.nx) as f64);
            if i < 8.0 && (5.0..=11.0).contains(&j) {
                *node = [1.0 + 0.1 * i, (0.7 * i + j).sin(), (0.3 * j - i).cos()];
            }
        }
        let before = mv.clone();
        let mut force = vec![[0.0; 2]; n];
        let mut reactions = vec![[0.0; 2]; 1];
        let gamma_dt = 1e-3;
        hold(
            &mut mv,
            &m.constraints.fix,
            pts,
            &m.constraints.groups,
            1.0,
            1e-12,
            Some(AsForce {
                force: &mut force,
                reactions: &mut reactions,
                gamma_dt,
            }),
        );
        let mut worst = 0.0f64;
        for p in pts {
            for (c, target) in [0.3, -0.2].into_iter().enumerate() {
                let v: f64 = p
                    .nodes
                    .iter()
                    .zip(&p.n)
                    .map(|(&a, &w)| w * mv[a as usize][1 + c])
                    .sum();
                worst = worst.max((v - target).abs());
                assert!((v - target).abs() < HELD_REL, "{shape} {p:?}: v{c} = {v}");
            }
        }
        println!("{shape}: largest |v − v̄| at the points {worst:.1e} m/s");
        // The force is m Δv / γΔt on each node, and the reaction its sum.
        let mut total = [0.0; 2];
        for a in 0..n {
            for c in 0..2 {
                let expect = mv[a][0] * (mv[a][1 + c] - before[a][1 + c]) / gamma_dt;
                assert!((force[a][c] - expect).abs() <= 1e-9 * expect.abs().max(1.0));
                total[c] += force[a][c];
            }
        }
        for c in 0..2 {
            assert!(
                (reactions[0][c] - total[c]).abs() < 1e-9 * total[c].abs().max(1.0),
                "{shape}: reaction {:?} against the nodes' {total:?}",
                reactions[0]
            );
        }
    }
}

/// `column_top` on the GPU backend, or None without an adapter.
fn column_top_gpu(shape: &str, y0: f64) -> Option<f64> {
    use lme_mpm::gpu::GpuBackend;
    use lme_mpm::simulation::Simulation;
    use lme_mpm::solver::{Recorder, Schedule};
    let ctx = common::gpu::open(shape, false)?;
    let scene = common::scene(
        "elastic_block.toml",
        &[
            &format!("solver.shape={shape}"),
            "grid.h=1.0",
            &format!("grid.min=[-2.0, {y0}]"),
            "grid.max=[12.0, 12.0]",
        ],
    );
    let model = Model::new(&scene).unwrap();
    let mut sim = Simulation::with_backend(&scene, Box::new(GpuBackend::new(ctx, model).unwrap()));
    let schedule = Schedule {
        vtk_interval: None,
        ..sim.schedule()
    };
    let status = sim.drive_with(schedule, &mut Recorder::default()).unwrap();
    assert_eq!(status, RunStatus::Completed, "{shape} y0 = {y0} (GPU)");
    match sim.score().unwrap() {
        Some(Errors::Column(e)) => Some(e.settlement_top),
        other => panic!("not a column score: {other:?}"),
    }
}

/// The same acceptance through the GPU backend (f32, the points'
/// projection in `constraint_points.wgsl`), against the same bound, with
/// bspline3 only: the widest stencil reaches furthest past the base, the
/// projection's shader is the same for every shape, and the CPU test runs
/// both (bspline2 on llvmpipe added 25 s to CI; measured +0.210 %).
/// Measured on llvmpipe: see the test's output.
#[test]
fn explicit_base_inside_the_grid_holds_like_the_grid_edge_on_the_gpu() {
    let shape = "bspline3";
    let Some(edge) = column_top_gpu(shape, 0.0) else {
        return;
    };
    let beyond = column_top_gpu(shape, -2.0).expect("the adapter opened once");
    let rel = (beyond - edge) / edge;
    println!(
        "{shape:>8} (GPU): top settlement {edge:.6} m (grid edge on the base), {beyond:.6} m \
         (two cells beyond), {:+.3} %",
        100.0 * rel
    );
    assert!(rel.abs() < BASE_REL, "{shape} (GPU): {:+.3} %", 100.0 * rel);
}

/// On the GPU a constraint group is its region's box of nodes less the
/// nodes its points freed: the box is whole again with them.
#[test]
fn gpu_boxes_count_the_freed_nodes() {
    use lme_mpm::gpu::buffers::constraint_boxes;
    let s = common::scene(
        "elastic_block.toml",
        &[
            "solver.shape=bspline3",
            "grid.h=1.0",
            "grid.min=[-2.0, -2.0]",
            "grid.max=[12.0, 12.0]",
        ],
    );
    let m = Model::new(&s).unwrap();
    let c = &m.constraints;
    assert!(!c.points.is_empty() && !c.freed[0].is_empty());
    let b = constraint_boxes(&m).unwrap();
    let area = ((b[0].i1 - b[0].i0 + 1) * (b[0].j1 - b[0].j0 + 1)) as usize;
    assert_eq!(area, c.groups[0].nodes.len() + c.freed[0].len());
    // Region y ≤ 0 on a grid from y = −2: three rows of nodes.
    assert_eq!((b[0].j0, b[0].j1), (0, 2));
}

/// The GPU marks the nodes a group's points free with a bit per group: a
/// scene with points and more than 32 groups is refused naming the key
/// (exit 2), before anything is uploaded.
#[test]
fn the_gpu_path_refuses_more_than_32_groups_with_points() {
    use lme_mpm::gpu::GpuBackend;
    let mut text = String::from(
        "[grid]\nh = 1.0\nmin = [-2.0, -2.0]\nmax = [40.0, 12.0]\n\
         [materials.m]\nmodel = \"linear_elastic\"\ndensity = 1000.0\nE = 1e7\nnu = 0.3\n\
         [bodies.b]\nmaterial = \"m\"\nrects = [[0.0, 0.0, 36.0, 4.0]]\n\
         [constraints.base]\nmin = [-inf, -inf]\nmax = [inf, 0.0]\nfix = \"xy\"\n\
         [solver]\nshape = \"bspline2\"\nt_end = 0.1\n",
    );
    // 32 pins (node lines inside the body: no points of their own).
    for k in 0..32 {
        text.push_str(&format!(
            "[constraints.pin{k:02}]\nmin = [{x}.0, 1.0]\nmax = [{x}.0, 2.0]\nfix = \"x\"\n",
            x = k + 2
        ));
    }
    let scene = lme_mpm::scene::Scene::from_str(&text, "33 groups", "groups", &[]).unwrap();
    let m = Model::new(&scene).unwrap();
    assert_eq!(m.constraints.groups.len(), 33);
    assert!(!m.constraints.points.is_empty());
    let Some(ctx) = common::gpu::open("33 groups", false) else {
        return;
    };
    let Err(e) = GpuBackend::new(ctx, m) else {
        panic!("the GPU path took 33 groups with points");
    };
    assert_eq!(e.exit_code(), 2, "{e}");
    assert!(e.to_string().contains("constraints"), "{e}");
}
