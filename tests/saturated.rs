//! Saturated soil (issue 52): Terzaghi's consolidation on the CPU against
//! the series (`exact::terzaghi`), for linear, bspline2 and LME.

use crate::common;
use lme_mpm::backend::Backend;
use lme_mpm::cpu::CpuBackend;
use lme_mpm::exact::terzaghi::Terzaghi;
use lme_mpm::model::Model;
use lme_mpm::scene::{Override, Scene};
use std::sync::atomic::AtomicBool;

/// A layer 1 m high and 0.2 m wide, h = 0.05 m (H/h = 20), ν = 0 so that
/// M = E, K_w / n = 10 M, c_v = 0.1 m²/s (T_v = 1 at 10 s): the undrained
/// wave (74 m/s, period 0.054 s) rings about nine periods before T_v =
/// 0.05, long enough for `local_damping = 0.1` to settle it (with c_v four
/// times larger the ringing put 6–7 % on the pressure at T_v = 0.05–0.1).
pub const TERZAGHI: &str = r#"
name = "terzaghi"
[grid]
h = 0.05
[materials.clay]
model = "linear_elastic"
density = 2000.0
E = 1e6
nu = 0.0
permeability = 1.0791e-3
porosity = 0.4
fluid_bulk = 4e6
[bodies.layer]
material = "clay"
rects = [[0.0, 0.0, 0.2, 1.0]]
[constraints.base]
min = [-inf, -inf]
max = [inf, 0.0]
fix = "xy"
[constraints.sides]
min = [-inf, -inf]
max = [0.0, inf]
fix = "x"
[constraints.right]
min = [0.2, -inf]
max = [inf, inf]
fix = "x"
[platens.load]
min = [-inf, 1.0]
max = [inf, inf]
force = -2e3
[drainage.top]
min = [-inf, 1.0]
max = [inf, inf]
[solver]
shape = "linear"
t_end = 1.97
local_damping = 0.1
"#;

pub fn scene(sets: &[&str]) -> Scene {
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    Scene::from_str(TERZAGHI, "terzaghi", "terzaghi", &o).unwrap()
}

/// The layer on `shape` to each T_v, scored against the series.
fn consolidate(
    shape: &str,
    extra: &[&str],
    tvs: &[f64],
) -> Vec<lme_mpm::exact::terzaghi::TerzaghiErrors> {
    let set = format!("solver.shape={shape}");
    let mut sets = extra.to_vec();
    sets.push(&set);
    let scene = scene(&sets);
    let layer = Terzaghi::from_scene(&scene);
    let mut b = CpuBackend::new(Model::new(&scene).unwrap());
    let stop = AtomicBool::new(false);
    tvs.iter()
        .map(|&tv| {
            let t = tv * layer.height() * layer.height() / layer.cv();
            b.advance(t, &stop)
                .unwrap_or_else(|e| panic!("{shape}: {e:?}"));
            let e = layer.score(b.particles().unwrap(), t);
            println!("{shape} {extra:?} T_v {tv}: {e:?}");
            e
        })
        .collect()
}

/// The issue's bounds (RMS of (p − p_exact)/p_start ≤ 2 %, U at T_v =
/// 0.197 within 1 % absolute, settlement within 1 %) where this step
/// meets them, and the measured figures plus a margin where it does not
/// yet (stated per shape; docs/verification.md, "Terzaghi's
/// consolidation"). The load comes through a rigid plate on the top nodes
/// (`[platens.load]`, as the case's). Measured on 2026-12-03, T_v 0.05 /
/// 0.1 / 0.197: linear RMS 1.56 / 1.46 / 0.78 %, U 49.31 % against
/// 50.03 %, settlement −0.9 / −0.1 / −0.1 %; LME 1.54 / 1.46 / 0.78 %,
/// U 49.31 %, −0.8 / −0.1 / −0.1 %; bspline2 2.05 / 1.83 / 1.66 %, U
/// 48.50 %, +0.3 / +0.3 / +0.2 %: bspline2 drains its top more slowly
/// (2.96 / 2.56 / 2.24 %, U 47.81 % before the drained face's ghost
/// nodes, `Drain::ghosts`).
/// (With a traction on the top particles instead, a quarter cell below
/// the surface, the settlement was −2.9 % at 0.197 on linear and LME.)
fn check(shape: &str, rms: f64, du: f64, ds: f64) {
    let e = consolidate(shape, &[], &[0.05, 0.1, 0.197]);
    for e in &e {
        assert!(e.pressure_rms <= rms, "{shape}: {e:?}");
    }
    let last = &e[2];
    assert!(
        (last.consolidation - last.consolidation_exact).abs() <= du,
        "{shape}: {last:?}"
    );
    assert!(last.settlement_rel_error.abs() <= ds, "{shape}: {last:?}");
}

#[test]
fn terzaghi_linear_follows_the_series() {
    check("linear", 0.02, 0.01, 0.01);
}

#[test]
fn terzaghi_lme_follows_the_series() {
    check("lme", 0.02, 0.01, 0.01);
}

/// bspline2 is above the issue's 2 % (2.05 % at T_v = 0.05) and its U
/// 1.5 % short at 0.197: not met yet; the bounds are those figures plus
/// a margin, so a regression still fails. Its settlement meets the 1 %.
#[test]
fn terzaghi_bspline2_follows_the_series() {
    check("bspline2", 0.023, 0.018, 0.01);
}

/// Equal-order u–p (the volumetric term at each particle) oscillates from
/// particle to particle: RMS 46 % at T_v 0.05 on linear, where the nodal
/// form has 1.6 % (measured 2026-12-03).
#[test]
fn particle_volumetric_term_oscillates_and_the_nodal_one_does_not() {
    let bad = consolidate("linear", &["solver.pore_volumetric=particle"], &[0.05]);
    assert!(bad[0].pressure_rms > 0.2, "{:?}", bad[0]);
    let good = consolidate("linear", &["solver.pore_volumetric=nodal"], &[0.05]);
    assert!(good[0].pressure_rms < 0.02, "{:?}", good[0]);
}

/// Bad input exits 2 naming the key, before anything runs.
#[test]
fn bad_pore_input_names_the_key() {
    let cases: &[(&[&str], &str)] = &[
        (&["materials.clay.porosity=1.0"], "materials.clay.porosity"),
        (&["materials.clay.porosity=0.0"], "materials.clay.porosity"),
        (
            &["materials.clay.permeability=-1e-3"],
            "materials.clay.permeability",
        ),
        (
            &["materials.clay.fluid_bulk=0.0"],
            "materials.clay.fluid_bulk",
        ),
        (
            &["materials.clay.fluid_density=-1.0"],
            "materials.clay.fluid_density",
        ),
        (&["drainage.top.min=[-inf, 3.0]"], "drainage.top"),
        (
            &[
                "drainage.side.min=[5.0, 5.0]",
                "drainage.side.max=[6.0, 6.0]",
            ],
            "drainage.side",
        ),
        (&["solver.integrator=musl"], "solver.integrator"),
        // A water table needs the geostatic start it sets up.
        (
            &["bodies.layer.water_table=0.5"],
            "bodies.layer.water_table",
        ),
    ];
    for (sets, key) in cases {
        let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let err = Scene::from_str(TERZAGHI, "t", "t", &o)
            .map_err(|e| e.to_string())
            .and_then(|s| Model::new(&s).map(|_| ()).map_err(|e| e.to_string()))
            .expect_err(&format!("{sets:?} was accepted"));
        assert!(err.contains(key), "{sets:?}: {err}");
    }
    // `exact = "terzaghi"` is loaded once, by a traction along the top or
    // by a platen there (the case's), not both and not neither.
    let case = std::fs::read_to_string(common::case("terzaghi.toml")).unwrap();
    let traction = "[tractions.load]\nfrom = [0.0, 1.0]\nto = [0.2, 1.0]\ntraction = [0.0, -1e4]\n";
    let plate = case.find("[platens.load]").unwrap();
    let plate_end = plate + case[plate..].find("\n\n").unwrap() + 1;
    let neither = format!("{}{}", &case[..plate], &case[plate_end..]);
    let as_traction = format!("{}{traction}{}", &case[..plate], &case[plate_end..]);
    let both = format!("{case}\n{traction}");
    let upward = case.replace("force = -2e3", "force = 2e3");
    for text in [&neither, &both, &upward] {
        let err = Scene::from_str(text, "t", "terzaghi.toml", &[]).unwrap_err();
        assert!(err.to_string().contains("exact"), "{err}");
    }
    let traction_load =
        Terzaghi::from_scene(&Scene::from_str(&as_traction, "t", "t", &[]).unwrap());
    let plate_load = Terzaghi::from_scene(&Scene::from_str(&case, "t", "t", &[]).unwrap());
    assert_eq!(traction_load.p0, plate_load.p0);
    // A dry scene with a drainage region: the region needs water.
    let dry = TERZAGHI
        .replace("permeability = 1.0791e-3\n", "")
        .replace("porosity = 0.4\n", "")
        .replace("fluid_bulk = 4e6\n", "");
    let err = Model::new(&Scene::from_str(&dry, "t", "t", &[]).unwrap()).unwrap_err();
    assert!(err.to_string().contains("drainage.top"), "{err}");
    // Porosity without permeability.
    let half = TERZAGHI.replace("permeability = 1.0791e-3\n", "");
    let err = Model::new(&Scene::from_str(&half, "t", "t", &[]).unwrap()).unwrap_err();
    assert!(err.to_string().contains("materials.clay.porosity"), "{err}");
    // A water table in a dry material.
    let dry_column = COLUMN
        .replace("permeability = 1e-4\n", "")
        .replace("porosity = 0.4\n", "")
        .replace("fluid_bulk = 1e8\n", "");
    let o = [Override::parse("bodies.column.water_table=0.5").unwrap()];
    let err = Model::new(&Scene::from_str(&dry_column, "t", "t", &o).unwrap()).unwrap_err();
    assert!(
        err.to_string().contains("bodies.column.water_table"),
        "{err}"
    );
}

/// A platen's bad input exits 2 naming it, before anything runs; the GPU
/// path, which has none yet, refuses one by name, and auto takes the CPU.
#[test]
fn bad_platen_input_names_the_key() {
    // Without `exact`, whose own check (a platen at the top, loaded)
    // would name `exact` first; the last case keeps it.
    let case = std::fs::read_to_string(common::case("mandel.toml")).unwrap();
    let plain = case.replace("exact = \"mandel\"", "");
    let load = |sets: &[&str]| {
        let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let text = if sets[0].contains("force") {
            &case
        } else {
            &plain
        };
        Scene::from_str(text, "mandel", "mandel.toml", &o)
            .map_err(|e| e.to_string())
            .and_then(|s| Model::new(&s).map_err(|e| e.to_string()))
    };
    let cases: &[(&[&str], &str)] = &[
        (&["platens.plate.min=[-inf, 5.0]"], "platens.plate"),
        // Its region reaches the base's nodes, which are fixed along y.
        (&["platens.plate.min=[-inf, -inf]"], "platens.plate"),
        (
            &[
                "platens.plate.min=[0.5, 0.3]",
                "platens.plate.max=[0.2, 0.4]",
            ],
            "platens.plate.min",
        ),
        (&["platens.plate.ramp_time=-1.0"], "platens.plate.ramp_time"),
        (
            &["solver.integrator=implicit", "solver.local_damping=0"],
            "platens.plate",
        ),
        // Mandel's plate carries the load; without one there is nothing to score.
        (&["platens.plate.force=0.0"], "exact"),
    ];
    for (sets, key) in cases {
        let err = load(sets).expect_err(&format!("{sets:?} was accepted"));
        assert!(err.contains(key), "{sets:?}: {err}");
    }
    use lme_mpm::simulation::{BackendChoice, BackendSpec, open_backend};
    let dry = || {
        let mut s = Scene::load(&common::case("mandel.toml"), &[]).unwrap();
        s.file.exact = None;
        s.file.drainage.clear();
        let soil = s.file.materials.get_mut("soil").unwrap();
        for k in ["permeability", "porosity", "fluid_bulk"] {
            soil.values.remove(k);
        }
        Model::new(&s).unwrap()
    };
    let err = open_backend(&BackendSpec::new(BackendChoice::Gpu), dry())
        .err()
        .expect("the GPU accepted a platen");
    assert!(err.to_string().contains("platens.plate"), "{err}");
    let b = open_backend(&BackendSpec::new(BackendChoice::Auto), dry()).unwrap();
    assert!(b.name().starts_with("cpu"), "{}", b.name());
}

/// The GPU path has no pore pressure yet: asked for, it refuses, naming why.
#[test]
fn the_gpu_refuses_saturated_soil_and_auto_takes_the_cpu() {
    use lme_mpm::simulation::{BackendChoice, BackendSpec, open_backend};
    let model = || Model::new(&scene(&[])).unwrap();
    let gpu = BackendSpec::new(BackendChoice::Gpu);
    let err = open_backend(&gpu, model())
        .err()
        .expect("the GPU accepted it");
    assert!(err.to_string().contains("CPU path only"), "{err}");
    let auto = BackendSpec::new(BackendChoice::Auto);
    let b = open_backend(&auto, model()).unwrap();
    assert!(b.name().starts_with("cpu"), "{}", b.name());
}

/// The figures of docs/verification.md, "Terzaghi's consolidation": each
/// shape to T_v = 1 (about 90 s on 2 cores; out of the suite).
///   cargo test --release --test suite saturated::terzaghi_to_tv_1 -- --ignored --nocapture
#[test]
#[ignore]
fn terzaghi_to_tv_1() {
    let tvs = [0.05, 0.1, 0.197, 0.5, 0.848, 1.0];
    println!("| shape | T_v | RMS (p − p_exact)/p_start | U | U exact | settlement | exact |");
    println!("|---|---|---|---|---|---|---|");
    for shape in ["linear", "bspline2", "lme"] {
        for e in consolidate(shape, &["solver.t_end=10"], &tvs) {
            println!(
                "| {shape} | {:.3} | {:.2} % | {:.2} % | {:.2} % | {:.3} mm ({:+.1} %) | {:.3} mm |",
                e.time_factor,
                100.0 * e.pressure_rms,
                100.0 * e.consolidation,
                100.0 * e.consolidation_exact,
                1e3 * e.settlement,
                100.0 * e.settlement_rel_error,
                1e3 * e.settlement_exact
            );
        }
    }
}

/// A saturated column 1 m high under its own weight (ρ = 2000 kg/m³, the
/// mixture's; ρ_w = 1000), drained where `drain` says, with its water
/// table at `table` (m): it starts hydrostatic below the table and
/// geostatic in effective stress (`initial_stress = "geostatic"`, k0 = 1
/// at ν = 0.5 would be singular: ν = 0.25, k0 = 1/3).
const COLUMN: &str = r#"
name = "wet column"
[grid]
h = 0.05
[materials.soil]
model = "linear_elastic"
density = 2000.0
E = 1e7
nu = 0.25
permeability = 1e-4
porosity = 0.4
fluid_bulk = 1e8
[bodies.column]
material = "soil"
rects = [[0.0, 0.0, 0.2, 1.0]]
initial_stress = "geostatic"
[constraints.base]
min = [-inf, -inf]
max = [inf, 0.0]
fix = "xy"
[constraints.left]
min = [-inf, -inf]
max = [0.0, inf]
fix = "x"
[constraints.right]
min = [0.2, -inf]
max = [inf, inf]
fix = "x"
[gravity]
g = [0.0, -9.81]
[solver]
shape = "linear"
t_end = 0.2
"#;

/// The wet column from its start to 0.2 s: the largest pore-pressure
/// departure from hydrostatic over ρ_w g H, the largest speed (m/s), the
/// largest effective σ_yy departure from geostatic over ρ g H, at the end.
fn wet_column(table: f64, drained_top: bool, shape: &str) -> (f64, f64, f64) {
    let mut text = COLUMN.replace(
        "initial_stress = \"geostatic\"",
        &format!("initial_stress = \"geostatic\"\nwater_table = {table}"),
    );
    if drained_top {
        text.push_str("[drainage.top]\nmin = [-inf, 1.0]\nmax = [inf, inf]\n");
    }
    let o = [Override::parse(&format!("solver.shape={shape}")).unwrap()];
    let scene = Scene::from_str(&text, "wet column", "wet", &o).unwrap();
    let mut b = CpuBackend::new(Model::new(&scene).unwrap());
    let (g, rho, rho_w, h) = (9.81, 2000.0, 1000.0, 1.0);
    let hydro = |y: f64| rho_w * g * (table - y).max(0.0);
    let sigma = |y: f64| {
        let total = -rho * g * (h - y);
        total + hydro(y)
    };
    {
        let p = b.particles().unwrap();
        for i in 0..p.len() {
            assert_eq!(p.pore_pressure[i], hydro(p.x[i][1]), "the start at {i}");
        }
    }
    b.advance(0.2, &AtomicBool::new(false)).unwrap();
    let p = b.particles().unwrap();
    let (mut dp, mut v, mut ds) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..p.len() {
        let y0 = p.x0[i][1];
        dp = dp.max((p.pore_pressure[i] - hydro(y0)).abs() / (rho_w * g * h));
        v = v.max(p.v[i][0].hypot(p.v[i][1]));
        ds = ds.max((p.stress[i][1] - sigma(y0)).abs() / (rho * g * h));
    }
    println!(
        "wet column, table {table} m, drained top {drained_top}, {shape}: |p - hydrostatic| <= {dp:.2e} rho_w g H, |v| <= {v:.2e} m/s, |sigma'_yy - geostatic| <= {ds:.2e} rho g H"
    );
    (dp, v, ds)
}

/// The column starts at the hydrostatic pressure below its table exactly,
/// and holds its start: to 0.2 s (about 17 periods of the undrained wave
/// over the column) its pressure settles to the discrete hydrostatic state
/// within a fraction of a cell's head (the boundary nodes' one-sided
/// averages), and it barely moves. Measured 2026-12-02 at 0.2 s:
/// |p − hydrostatic| ≤ 1.96e-2 ρ_w g H on linear with the table at the
/// drained top or at 0.6 m (above it dry), 2.0e-2 LME, 2.1e-2 bspline2
/// (to 0.5 s: at most 2.1e-2, bspline2 at 0.6 m 5.4e-2); |v| ≤ 1.7e-6 m/s
/// linear, 2.1e-4 LME and bspline2; σ'_yy within 4.6e-3 ρ g H (linear,
/// LME) and 4.8e-2 (bspline2, whose fixed base nodes carry the column's
/// weight unevenly).
#[test]
fn a_water_table_starts_hydrostatic_and_stays_at_rest() {
    for (table, drained, shape, p_max, s_max) in [
        (1.0, true, "linear", 0.03, 0.01),
        (0.6, false, "linear", 0.03, 0.01),
        (0.6, false, "lme", 0.03, 0.01),
        (1.0, true, "bspline2", 0.03, 0.06),
    ] {
        let (dp, v, ds) = wet_column(table, drained, shape);
        assert!(dp < p_max, "{shape}, table {table}: p off by {dp}");
        assert!(v < 1e-3, "{shape}, table {table}: |v| {v}");
        assert!(ds < s_max, "{shape}, table {table}: σ'_yy off by {ds}");
    }
}

/// The undrained P-wave: the layer of `TERZAGHI` made impermeable (k = 0,
/// no drainage) and undamped, on `shape` with H/h = 40, loaded suddenly at
/// its top. The front reflects at the fixed base, where the pore pressure
/// then swings between 0 and 2 p_start with the column's period 4H/c; the
/// times the bottom row's mean pressure crosses p_start upward, twice,
/// give the period, so the speed 4H / period, against c = sqrt((M +
/// K_w/n)/ρ) (74.2 m/s) — a period and not a first arrival, which would
/// need where the load enters (the plate on the top nodes) and the front's shape.
/// Returns (measured, exact).
fn undrained_wave_speed(shape: &str) -> (f64, f64) {
    let text = TERZAGHI.replace("[drainage.top]\nmin = [-inf, 1.0]\nmax = [inf, inf]\n", "");
    let o: Vec<Override> = [
        "materials.clay.permeability=0.0",
        "solver.local_damping=0.0",
        "grid.h=0.025",
        &format!("solver.shape={shape}"),
    ]
    .iter()
    .map(|s| Override::parse(s).unwrap())
    .collect();
    let scene = Scene::from_str(&text, "wave", "wave", &o).unwrap();
    let layer = Terzaghi::from_scene(&scene);
    let rho = 2000.0;
    let c = ((layer.m + layer.fluid.undrained_modulus()) / rho).sqrt();
    let mut b = CpuBackend::new(Model::new(&scene).unwrap());
    let bottom: Vec<usize> = {
        let p = b.particles().unwrap();
        let y = (0..p.len()).map(|i| p.x0[i][1]).fold(f64::MAX, f64::min);
        (0..p.len()).filter(|&i| p.x0[i][1] == y).collect()
    };
    let (dt, stop) = (layer.height() / c / 400.0, AtomicBool::new(false));
    let (mut t, mut before, mut ups) = (0.0, 0.0, Vec::new());
    let half = layer.p_start();
    while ups.len() < 2 {
        t += dt;
        b.advance(t, &stop).unwrap();
        let p = b.particles().unwrap();
        let now = bottom.iter().map(|&i| p.pore_pressure[i]).sum::<f64>() / bottom.len() as f64;
        if before <= half && now > half {
            // Linear between the two readings.
            ups.push(t - dt * (now - half) / (now - before));
        }
        assert!(
            t < 8.0 * layer.height() / c,
            "{shape}: {} crossings by {t} s",
            ups.len()
        );
        before = now;
    }
    (4.0 * layer.height() / (ups[1] - ups[0]), c)
}

/// The issue's figure: the undrained P-wave speed within 2 %. Measured
/// 2026-12-03 (H/h = 40): linear −0.43 %, bspline2 −0.77 %, LME −0.44 %
/// (the skeleton's wave alone, sqrt(M/ρ) = 22.4 m/s, would be −70 %).
#[test]
fn the_undrained_wave_travels_at_the_mixtures_speed() {
    for shape in ["linear", "bspline2", "lme"] {
        let (c, exact) = undrained_wave_speed(shape);
        println!(
            "{shape}: undrained wave {c:.2} m/s, exact {exact:.2} ({:+.2} %)",
            100.0 * (c / exact - 1.0)
        );
        assert!(
            (c / exact - 1.0).abs() < 0.02,
            "{shape}: {c} m/s against {exact}"
        );
    }
}

/// Mandel's problem (`cases/mandel.toml`, a / h = 20) on `shape` with
/// the permeability `k` (m/s): the centre's pressure at each t c / a²,
/// scored against the closed form.
fn mandel(shape: &str, k: f64, tfs: &[f64]) -> Vec<lme_mpm::exact::mandel::MandelErrors> {
    use lme_mpm::exact::mandel::Mandel;
    let sets = [
        format!("solver.shape={shape}"),
        format!("materials.soil.permeability={k}"),
    ];
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let mut scene = Scene::load(&common::case("mandel.toml"), &o).unwrap();
    let m = Mandel::from_scene(&scene);
    scene.file.solver.t_end = tfs.last().unwrap() * m.time_scale();
    let mut b = CpuBackend::new(Model::new(&scene).unwrap());
    let stop = AtomicBool::new(false);
    tfs.iter()
        .map(|&tf| {
            let t = tf * m.time_scale();
            b.advance(t, &stop)
                .unwrap_or_else(|e| panic!("{shape}: {e:?}"));
            let e = m.score(b.particles().unwrap(), t);
            println!("{shape} k {k}: mandel t c/a² {tf}: {e:?}");
            e
        })
        .collect()
}

/// The issue's figure: the centre's pressure within 3 % of p_start of the
/// closed form at t c / a² = 0.01, 0.1, 0.5 and 1, with the Mandel–Cryer
/// rise (1.14 p_start at 0.1 here). The case's c = 0.1 m²/s reaches
/// t c / a² = 0.01 at 0.1 s, under half a period of the sudden load's
/// shear ringing (0.25 s): that point is scored on the same specimen with
/// k / 10 (c = 0.01 m²/s, 1 s, four periods). Measured 2026-12-03 (0.01
/// / 0.1 / 0.5 / 1, of p_start): linear −0.06 / −0.50 / +0.13 / +0.22 %;
/// LME −0.34 / −0.48 / +0.19 / +0.26 %; bspline2 +2.77 / +1.63 / +2.84 /
/// +2.13 % (it drains its side more slowly, as in Terzaghi's layer; before
/// the drained side's ghost nodes, `Drain::ghosts`, +3.54 % at 0.5).
fn check_mandel(shape: &str, bound: f64) {
    let slow = mandel(shape, 1.0791e-4, &[0.01]);
    let fast = mandel(shape, 1.0791e-3, &[0.1, 0.5, 1.0]);
    for e in slow.iter().chain(&fast) {
        assert!(e.centre_error.abs() <= bound, "{shape}: {e:?}");
    }
    assert!(fast[0].centre > 1.1, "{shape}: no rise: {:?}", fast[0]);
}

#[test]
fn mandel_linear_centre_pressure_rises_then_drains_as_the_closed_form() {
    check_mandel("linear", 0.03);
}

#[test]
fn mandel_lme_centre_pressure_rises_then_drains_as_the_closed_form() {
    check_mandel("lme", 0.03);
}

#[test]
fn mandel_bspline2_centre_pressure_rises_then_drains_as_the_closed_form() {
    check_mandel("bspline2", 0.03);
}
