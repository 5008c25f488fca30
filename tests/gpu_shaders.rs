//! WGSL checks that need no GPU: every file is embedded in the binary, every
//! pass expands and validates with naga in every variant a scene can ask
//! for, every struct shared with Rust has the same layout on both sides, and
//! every Rust file a file's header names (its CPU twin) exists.

use lme_mpm::gpu::constraint_points::PointCounts;
use lme_mpm::gpu::context::AtomicMode;
use lme_mpm::gpu::layout::{GpuConstraint, GpuContactPair, GpuMaterial, GpuWall, Params, Sim};
use lme_mpm::gpu::pipelines::{self, Pass, Variant};
use lme_mpm::gpu::preprocess::SOURCES;
use lme_mpm::model::Integrator;
use lme_mpm::model::material::StateKind;
use lme_mpm::scene::{NpcPosition, ShapeKind};
use std::mem::{offset_of, size_of};
use std::path::Path;

fn wgsl_files(dir: &Path, base: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            wgsl_files(&p, base, out);
        } else if p.extension().is_some_and(|x| x == "wgsl") {
            out.push(
                p.strip_prefix(base)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/"),
            );
        }
    }
}

#[test]
fn every_wgsl_file_is_embedded() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut on_disk = Vec::new();
    wgsl_files(&base, &base, &mut on_disk);
    on_disk.sort();
    let mut embedded: Vec<String> = SOURCES.iter().map(|(p, _)| p.to_string()).collect();
    embedded.sort();
    assert_eq!(on_disk, embedded, "shaders/ and preprocess::SOURCES differ");
}

/// The comment block a WGSL file opens with: its leading `//` lines, blank
/// lines before the first one skipped.
fn header(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines().map(str::trim) {
        if let Some(rest) = line.strip_prefix("//") {
            out.push_str(rest);
            out.push('\n');
        } else if !(line.is_empty() && out.is_empty()) {
            break;
        }
    }
    out
}

/// Every `src/...rs` path in `text`, one brace group (`src/a/{b,c}.rs`)
/// expanded.
fn rust_paths(text: &str) -> Vec<String> {
    let is_path = |c: char| c.is_ascii_alphanumeric() || "_/.{},-".contains(c);
    let mut out = Vec::new();
    for (at, _) in text.match_indices("src/") {
        if at > 0 && is_path(text[..at].chars().next_back().unwrap()) {
            continue; // inside a longer path, e.g. `tests/src/`.
        }
        let token: String = text[at..].chars().take_while(|&c| is_path(c)).collect();
        let Some(end) = token.find(".rs") else {
            continue;
        };
        let token = &token[..end + 3];
        match (token.find('{'), token.find('}')) {
            (Some(open), Some(close)) if open < close => {
                for alt in token[open + 1..close].split(',') {
                    out.push(format!("{}{alt}{}", &token[..open], &token[close + 1..]));
                }
            }
            _ => out.push(token.to_string()),
        }
    }
    out
}

#[test]
fn every_wgsl_header_names_rust_files_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = root.join("shaders");
    let mut files = Vec::new();
    wgsl_files(&base, &base, &mut files);
    files.sort();
    let mut named = 0;
    let mut missing = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(base.join(file)).unwrap();
        let header = header(&text);
        let paths = rust_paths(&header);
        if header.contains("CPU twin") && paths.is_empty() {
            missing.push(format!("shaders/{file}: a CPU twin without a src/ path"));
        }
        for path in paths {
            named += 1;
            if !root.join(&path).is_file() {
                missing.push(format!("shaders/{file}: {path}"));
            }
        }
    }
    assert!(named > 40, "only {named} src/ paths found in WGSL headers");
    assert!(
        missing.is_empty(),
        "WGSL headers name files that do not exist:\n{}",
        missing.join("\n")
    );
}

fn variants() -> Vec<Variant> {
    let integrators = [
        Integrator::Fe,
        Integrator::Npc {
            gamma: 0.5,
            position: NpcPosition::Newmark,
        },
        Integrator::Npc {
            gamma: 0.5,
            position: NpcPosition::Predicted,
        },
        Integrator::Npc {
            gamma: 0.5,
            position: NpcPosition::Corrected,
        },
        Integrator::Musl,
    ];
    let mut out = Vec::new();
    for shape in [
        ShapeKind::Linear,
        ShapeKind::Ugimp,
        ShapeKind::Lme,
        ShapeKind::Bspline2,
        ShapeKind::Bspline3,
    ] {
        for integrator in integrators {
            for perturbed in [false, true] {
                if perturbed && matches!(shape, ShapeKind::Bspline2 | ShapeKind::Bspline3) {
                    continue; // B-splines need a regular grid.
                }
                for multi_material in [false, true] {
                    for atomics in [AtomicMode::Float, AtomicMode::CompareExchange] {
                        for lme_stored in [false, true] {
                            if lme_stored && shape != ShapeKind::Lme {
                                continue;
                            }
                            // Every registered model alone, linear elastic with
                            // Neo-Hookean, and all of them (with several materials).
                            let registry = lme_mpm::model::material::registry();
                            let code = |name: &str| {
                                1u32 << registry.iter().find(|e| e.name == name).unwrap().code
                            };
                            let all = registry.iter().fold(0, |b, e| b | 1 << e.code);
                            let sets = registry
                                .iter()
                                .map(|e| 1u32 << e.code)
                                .chain([code("linear_elastic") | code("neo_hookean"), all]);
                            for materials in sets {
                                let has = |state: StateKind| {
                                    registry
                                        .iter()
                                        .any(|e| materials & 1 << e.code != 0 && e.state == state)
                                };
                                let neo_hookean = materials == code("neo_hookean");
                                if materials.count_ones() > 1 && !multi_material {
                                    continue;
                                }
                                // MLS (linear and B-splines on regular grids), and the
                                // manufactured body force (one Neo-Hookean material).
                                for (mls, mms) in
                                    [(false, false), (true, false), (false, true), (true, true)]
                                {
                                    let mls_ok = !perturbed
                                        && matches!(
                                            shape,
                                            ShapeKind::Linear
                                                | ShapeKind::Bspline2
                                                | ShapeKind::Bspline3
                                        );
                                    if (mls && !mls_ok) || (mms && (!neo_hookean || multi_material))
                                    {
                                        continue;
                                    }
                                    out.push(Variant {
                                        shape,
                                        integrator,
                                        perturbed,
                                        multi_material,
                                        atomics,
                                        lme_side: if shape == ShapeKind::Lme { 5 } else { 1 },
                                        lme_stored,
                                        materials,
                                        def_grad: has(StateKind::DefGrad),
                                        plastic: has(StateKind::Plastic),
                                        mms,
                                        mls,
                                        // The force correction with the
                                        // manufactured solution, the paper's
                                        // step without it.
                                        mls_force: mls && mms,
                                        // Walls and loads in every shape and
                                        // integrator, with one atomic mode.
                                        walls: atomics == AtomicMode::CompareExchange && !mls,
                                        // Gates, the PIC blend and local damping
                                        // where the walls are.
                                        gates: atomics == AtomicMode::CompareExchange && !mls,
                                        // The walls' preload (a geostatic body
                                        // against them) where the walls are.
                                        wall_preload: atomics == AtomicMode::CompareExchange
                                            && !mls,
                                        // Its fit to the discrete reaction
                                        // with it.
                                        wall_pre_fit: atomics == AtomicMode::CompareExchange
                                            && !mls,
                                        pic: atomics == AtomicMode::CompareExchange && !mls,
                                        local_damping: atomics == AtomicMode::CompareExchange
                                            && !mls,
                                        ext_force: atomics == AtomicMode::CompareExchange && !mls,
                                        // Gather where it can, except with several
                                        // materials and float atomics (the scatter).
                                        gather: !mls
                                            && integrator != Integrator::Musl
                                            && !(multi_material && atomics == AtomicMode::Float),
                                        // The recursion B-splines take on small grids.
                                        bspline_small_grid: multi_material,
                                        // The knots on the grid lines, with the
                                        // manufactured solution (the paper's
                                        // layout for its study).
                                        bspline_cells: mms,
                                        // Per-bin scatter where it applies and
                                        // the variant does not gather.
                                        // (LME on any grid.)
                                        patch: !mls
                                            && integrator != Integrator::Musl
                                            && multi_material
                                            && atomics == AtomicMode::Float
                                            && (shape == ShapeKind::Lme
                                                || !perturbed
                                                    && matches!(
                                                        shape,
                                                        ShapeKind::Linear
                                                            | ShapeKind::Bspline2
                                                            | ShapeKind::Bspline3
                                                    )),
                                        contact: None,
                                        points: None,
                                        cell_average_bodies: 0,
                                    });
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    // Contact pairs (four fields, three pairs) on every variant they
    // allow (no MLS; they scatter per particle), with several materials.
    let contact: Vec<Variant> = out
        .iter()
        .filter(|v| !v.mls && v.multi_material)
        .map(|v| Variant {
            gather: false,
            patch: false,
            contact: Some([4, 3]),
            ..*v
        })
        .collect();
    out.extend(contact);
    // The cell-averaged volumetric strain rate (three bodies) on every
    // variant it allows (no MLS), with several materials, with and
    // without contact pairs.
    let cell_average: Vec<Variant> = out
        .iter()
        .filter(|v| !v.mls && v.multi_material && !v.lme_stored)
        .map(|v| Variant {
            cell_average_bodies: 3,
            ..*v
        })
        .collect();
    out.extend(cell_average);
    // Constraint points on every shape, integrator and grid without MLS
    // (linear elastic, one atomic mode), and with contact pairs (two lanes
    // per field).
    let points = PointCounts {
        n_points: 22,
        slots: 9,
        n_held: 40,
        n_list: 180,
        env: 120,
        n_fields: 1,
    };
    let with_points: Vec<Variant> = out
        .iter()
        .filter(|v| {
            !v.mls
                && v.atomics == AtomicMode::CompareExchange
                && !v.lme_stored
                && (v.contact.is_some() || v.materials == 1)
        })
        .map(|v| Variant {
            points: Some(PointCounts {
                n_fields: v.contact.map_or(1, |[f, _]| f),
                ..points
            }),
            ..*v
        })
        .collect();
    out.extend(with_points);
    out
}

#[test]
fn every_pass_validates_in_every_variant() {
    let mut checked = 0;
    // Many variants expand a pass to the same source (a define that pass
    // does not read): naga parses and validates each distinct source once
    // per atomic mode, and every variant's bindings are checked against it.
    let mut validated: std::collections::HashMap<(String, bool), Vec<pipelines::Binding>> =
        std::collections::HashMap::new();
    for v in variants() {
        let d = v.defines();
        for pass in Pass::ALL {
            if !v.plan().gpu_uses(pass) {
                continue;
            }
            let src = pipelines::expand(pass, &d).unwrap_or_else(|e| panic!("{pass:?} {v:?}: {e}"));
            let key = (src, v.atomics == AtomicMode::Float);
            if !validated.contains_key(&key) {
                let module = pipelines::validate(&key.0, pass.file().unwrap(), v.atomics)
                    .unwrap_or_else(|e| panic!("{pass:?} {v:?}: {e}"));
                validated.insert(key.clone(), pipelines::bindings(&module));
            }
            // Only what the variant needs is declared.
            let binds = &validated[&key];
            use lme_mpm::gpu::buffers::Buf;
            let has = |b: Buf| binds.iter().any(|x| x.buf == b);
            assert_eq!(
                has(Buf::NodePos),
                v.perturbed
                    && (pass_uses_shape(pass)
                        || (pass == Pass::BinCount
                            && (v.gather || v.patch || v.contact.is_some()))),
                "{pass:?} {v:?}: node_pos"
            );
            assert!(
                !has(Buf::A) || matches!(v.integrator, Integrator::Npc { .. }),
                "{pass:?} {v:?}: a without NPC"
            );
            assert!(
                !has(Buf::XStart) || v.integrator == Integrator::Musl,
                "{pass:?} {v:?}: step-start positions without MUSL"
            );
            assert!(
                !has(Buf::Lambda) || v.shape == ShapeKind::Lme,
                "{pass:?} {v:?}: λ without LME"
            );
            assert!(
                !has(Buf::Mat) || v.multi_material,
                "{pass:?} {v:?}: material index with one material"
            );
            assert!(
                !has(Buf::Plastic) || v.plastic,
                "{pass:?} {v:?}: plastic state without a plastic material"
            );
            if matches!(pass, Pass::Stress | Pass::StressForces) {
                assert_eq!(
                    binds.iter().any(|x| x.buf == Buf::Plastic && x.writable),
                    v.plastic,
                    "{pass:?} {v:?}: the stress stage updates the plastic state"
                );
            }
            assert!(
                !has(Buf::MlsCoef) || v.mls,
                "{pass:?} {v:?}: MLS buffers without MLS"
            );
            assert!(
                !(has(Buf::CellCount) || has(Buf::CellOrder))
                    || v.mls
                    || v.gather
                    || v.patch
                    || v.contact.is_some(),
                "{pass:?} {v:?}: cell bins without MLS, gather, patch or contact pairs"
            );
            assert!(
                !(has(Buf::Field)
                    || has(Buf::ContactPairs)
                    || has(Buf::ContactGrad)
                    || has(Buf::ContactNormal))
                    || v.contact.is_some(),
                "{pass:?} {v:?}: contact buffers without contact pairs"
            );
            // Every pass that walks a particle's nodes offsets them by its field.
            if v.contact.is_some() && pass_uses_shape(pass) && pass != Pass::LmeNewton {
                assert!(has(Buf::Field), "{pass:?} {v:?}: nodes not offset by field");
            }
            assert_eq!(
                has(Buf::Body) || has(Buf::CellAvg),
                v.cell_average_bodies > 0
                    && matches!(
                        pass,
                        Pass::CellAverageClear | Pass::CellAverage | Pass::Stress
                    ),
                "{pass:?} {v:?}: the cell average's buffers where it is read"
            );
            assert!(
                !(has(Buf::Walls) || has(Buf::WallForce) || has(Buf::WallTouch)) || v.walls,
                "{pass:?} {v:?}: wall buffers without walls"
            );
            assert!(
                !has(Buf::ExtForce) || v.ext_force,
                "{pass:?} {v:?}: external forces without loads"
            );
            if v.walls && matches!(pass, Pass::GridCorrect) {
                assert!(has(Buf::WallForce), "{pass:?} {v:?}: walls' forces unread");
            }
            if v.walls && matches!(pass, Pass::WallContact) {
                assert!(
                    has(Buf::WallTouch),
                    "{pass:?} {v:?}: contact weights unread"
                );
            }
            assert!(
                !(has(Buf::PointTable) || has(Buf::PointWork)) || v.points.is_some(),
                "{pass:?} {v:?}: constraint points' tables without points"
            );
            if v.points.is_some() && matches!(pass, Pass::GridPredict | Pass::GridCorrect) {
                assert!(has(Buf::PointTable), "{pass:?} {v:?}: freed nodes unread");
            }
            if v.ext_force && matches!(pass, Pass::Forces | Pass::ForcesGather) {
                assert!(has(Buf::ExtForce), "{pass:?} {v:?}: loads unread");
            }
            checked += 1;
        }
    }
    println!(
        "{checked} expanded passes checked, {} distinct sources validated",
        validated.len()
    );
    assert!(checked > 500);
}

fn pass_uses_shape(pass: Pass) -> bool {
    matches!(
        pass,
        Pass::LmeNewton
            | Pass::P2g
            | Pass::P2gGather
            | Pass::P2gPatch
            | Pass::Stress
            | Pass::StressForces
            | Pass::StressForcesPatch
            | Pass::Forces
            | Pass::ForcesGather
            | Pass::ForcesPatch
            | Pass::G2p
            | Pass::MlsP2g
            | Pass::MlsForces
            | Pass::Remap
            | Pass::MlsRemap
            | Pass::MlsForceGauss
            | Pass::WallTouch
            | Pass::WallContact
            | Pass::ContactGrad
            | Pass::ContactDetect
            | Pass::CellAverage
    )
}

/// (name, offset) of every non-padding field of a WGSL struct, and its size.
fn wgsl_struct(module: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
    for (_, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let naga::TypeInner::Struct { members, span } = &ty.inner {
                let fields = members
                    .iter()
                    .filter_map(|m| {
                        let n = m.name.clone()?;
                        (!n.starts_with('_')).then_some((n, m.offset))
                    })
                    .collect();
                return (fields, *span);
            }
        }
    }
    panic!("struct {name} not found");
}

macro_rules! rust_fields {
    ($t:ty; $($f:ident),* $(,)?) => {
        (vec![$((stringify!($f).to_string(), offset_of!($t, $f) as u32)),*], size_of::<$t>() as u32)
    };
}

#[test]
fn shared_structs_match_rust_layouts() {
    let v = variants()[0];
    let src = pipelines::expand(Pass::Cfl, &v.defines()).unwrap();
    let module = pipelines::validate(&src, "cfl.wgsl", v.atomics).unwrap();
    let params = rust_fields!(Params; n_particles, n_nodes, nx, ny, h, inv_h, cfl_h, mass_eps, t_end_ticks,
        gravity, ramp_period, npc_gamma, p2g_accel, edge_margin, grid_w, grid_hgt, lme_beta, lme_r2, lme_tol,
        lme_reach, lme_side, lme_max_iter, ugimp_lp, n_groups, n_probes, n_materials, fixed_dt, mms_amp, mms_origin,
        mms_k, mms_omega, mms_lame, mms_shear, mms_c2, mls_spans_x, mls_spans_y, mls_break_off,
        mls_weight_scale, pic_fraction, local_damping, tick_exp, fixed_dt_ticks, opaque_zero);
    assert_eq!(wgsl_struct(&module, "Params"), params);
    let sim = rust_fields!(Sim; t, t_lo, ticks, t_stop_ticks, dt, steps, running, final_step, cmax_bits, fault);
    assert_eq!(wgsl_struct(&module, "Sim"), sim);
    let mat = rust_fields!(GpuMaterial; lame, shear, p_modulus, youngs, nu, model, bulk, p);
    assert_eq!(wgsl_struct(&module, "Material"), mat);
    let con = rust_fields!(GpuConstraint; i0, i1, j0, j1, fix, vx, vy, ramp_time);
    assert_eq!(wgsl_struct(&module, "Constraint"), con);
    let wall =
        rust_fields!(GpuWall; point, normal, mu, contact, stiffness, offset, appear_at, remove_at);
    assert_eq!(wgsl_struct(&module, "Wall"), wall);
    let v = *variants().iter().find(|v| v.contact.is_some()).unwrap();
    let src = pipelines::expand(Pass::ContactExchange, &v.defines()).unwrap();
    let module = pipelines::validate(&src, "contact_exchange.wgsl", v.atomics).unwrap();
    let pair = rust_fields!(GpuContactPair; fields, law, mu, reaction);
    assert_eq!(wgsl_struct(&module, "ContactPair"), pair);
}

/// A WGSL constant's value as naga's front end evaluated it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Value {
    U32(u32),
    F32(f32),
}

/// Every named `const` of a module with a scalar literal value.
fn wgsl_constants(module: &naga::Module) -> Vec<(String, Value)> {
    module
        .constants
        .iter()
        .filter_map(|(_, c)| {
            let v = match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => Value::U32(v),
                naga::Expression::Literal(naga::Literal::F32(v)) => Value::F32(v),
                _ => return None,
            };
            Some((c.name.clone()?, v))
        })
        .collect()
}

/// The constants of every pass in variants that together include every
/// shared file (MLS B-splines with two materials; stored-weight LME with the
/// manufactured load; MUSL; walls), with the passes' entry-point workgroup
/// sizes.
fn every_pass_module() -> Vec<(Pass, naga::Module)> {
    let all = variants();
    let mls = all
        .iter()
        .find(|v| v.mls && v.multi_material && v.plastic && v.shape == ShapeKind::Bspline2)
        .unwrap();
    let lme = all
        .iter()
        .find(|v| v.lme_stored && v.mms && v.perturbed)
        .unwrap();
    // MUSL's remap passes, with and without MLS.
    let musl = |mls: bool| {
        all.iter()
            .find(|v| v.integrator == Integrator::Musl && v.mls == mls)
            .unwrap()
    };
    let walls = all.iter().find(|v| v.walls).unwrap();
    let contact = all.iter().find(|v| v.contact.is_some()).unwrap();
    let points = all.iter().find(|v| v.points.is_some()).unwrap();
    let mut out = Vec::new();
    for v in [mls, lme, musl(true), musl(false), walls, contact, points] {
        let d = v.defines();
        for pass in Pass::ALL {
            if v.plan().gpu_uses(pass) {
                let src = pipelines::expand(pass, &d).unwrap();
                out.push((
                    pass,
                    pipelines::validate(&src, pass.file().unwrap(), v.atomics).unwrap(),
                ));
            }
        }
    }
    out
}

/// Every constant written in both Rust and WGSL holds the same value in
/// both, as naga parses the expanded shaders. A constant that appears in
/// several passes must agree in every one, and must appear at least once.
#[test]
fn constants_mirrored_in_wgsl_match_rust() {
    use lme_mpm::gpu::layout as l;
    use lme_mpm::model::material::plastic;
    let f = |v: f64| Value::F32(v as f32);
    let u = Value::U32;
    let expected: Vec<(&str, Value)> = vec![
        ("FAULT_NONE", u(l::FAULT_NONE)),
        ("FAULT_LEFT_GRID", u(l::FAULT_LEFT_GRID)),
        ("FAULT_NON_FINITE_STRAIN", u(l::FAULT_NON_FINITE_STRAIN)),
        ("FAULT_NON_FINITE_STRESS", u(l::FAULT_NON_FINITE_STRESS)),
        ("FAULT_NON_FINITE_MOTION", u(l::FAULT_NON_FINITE_MOTION)),
        ("FAULT_DENSITY", u(l::FAULT_DENSITY)),
        ("FAULT_LME_FEW_NODES", u(l::FAULT_LME_FEW_NODES)),
        ("FAULT_LME_NOT_CONVERGED", u(l::FAULT_LME_NOT_CONVERGED)),
        ("FAULT_LME_SINGULAR", u(l::FAULT_LME_SINGULAR)),
        ("FAULT_MLS_SINGULAR", u(l::FAULT_MLS_SINGULAR)),
        ("FAULT_MATERIAL", u(l::FAULT_MATERIAL)),
        ("CONTACT_STICK", u(lme_mpm::model::walls::CONTACT_STICK)),
        ("CONTACT_SLIP", u(lme_mpm::model::walls::CONTACT_SLIP)),
        (
            "CONTACT_FRICTION",
            u(lme_mpm::model::walls::CONTACT_FRICTION),
        ),
        ("ACTIVE_MAIN", u(plastic::ACTIVE_MAIN)),
        ("ACTIVE_EDGE_12", u(plastic::ACTIVE_EDGE_12)),
        ("ACTIVE_EDGE_23", u(plastic::ACTIVE_EDGE_23)),
        ("ACTIVE_T1", u(plastic::ACTIVE_T1)),
        ("ACTIVE_T2", u(plastic::ACTIVE_T2)),
        ("ACTIVE_T3", u(plastic::ACTIVE_T3)),
        ("NODE_STRIDE", u(l::NODE_STRIDE as u32)),
        ("PROBE_STRIDE", u(l::PROBE_STRIDE as u32)),
        ("WG", u(l::WG)),
        ("LAST_STEP_REL", f(lme_mpm::model::time_step::LAST_STEP_REL)),
        ("MLS_SUPPORT", f(lme_mpm::cpu::mls::SUPPORT_CELLS)),
        ("WALL_DAMPING", f(lme_mpm::model::walls::WALL_DAMPING)),
        ("PRELOAD_HOLD", f(lme_mpm::model::walls::PRELOAD_HOLD)),
        ("STICK_MU", f(lme_mpm::model::walls::STICK_MU)),
        (
            "LINE_WEIGHT_EPS",
            f(lme_mpm::cpu::wall_touch::LINE_WEIGHT_EPS),
        ),
        (
            "CONTACT_GAP_SLACK",
            f(lme_mpm::cpu::contact_detect::CONTACT_GAP_SLACK),
        ),
        ("LR_RIDGE", f(lme_mpm::cpu::contact_detect::LR_RIDGE)),
        (
            "LR_ITERATIONS",
            u(lme_mpm::cpu::contact_detect::LR_ITERATIONS as u32),
        ),
        ("LR_MAX_STEP", f(lme_mpm::cpu::contact_detect::LR_MAX_STEP)),
        (
            "LR_MIN_SCALE",
            f(lme_mpm::cpu::contact_detect::LR_MIN_SCALE),
        ),
        ("LR_FLAT_COS", f(lme_mpm::cpu::contact_detect::LR_FLAT_COS)),
        (
            "CONTACT_PIC_FRACTION",
            f(lme_mpm::model::contact::CONTACT_PIC_FRACTION),
        ),
    ];
    let modules = every_pass_module();
    // Every model's code, generated from the registry.
    let registry = lme_mpm::model::material::registry();
    let models: Vec<(String, Value)> = registry
        .iter()
        .map(|e| (e.model_const(), u(e.code)))
        .collect();
    let expected: Vec<(&str, Value)> = expected
        .into_iter()
        .chain(models.iter().map(|(n, v)| (n.as_str(), *v)))
        .collect();
    for (name, want) in &expected {
        let mut seen = 0;
        for (pass, m) in &modules {
            for (n, v) in wgsl_constants(m) {
                if n == *name {
                    assert_eq!(v, *want, "{name} in {pass:?}: WGSL {v:?}, Rust {want:?}");
                    seen += 1;
                }
            }
        }
        assert!(seen > 0, "{name} is declared in no pass");
    }
    // No FAULT_* or MODEL_* code in WGSL that Rust does not know.
    for (pass, m) in &modules {
        for (n, _) in wgsl_constants(m) {
            if n.starts_with("FAULT_") || n.starts_with("MODEL_") {
                assert!(
                    expected.iter().any(|(e, _)| *e == n),
                    "{n} in {pass:?} has no Rust twin in this test"
                );
            }
        }
    }
}

/// Each pass's workgroup size is what its dispatch divides by: `WG` for the
/// per-particle, per-node, per-cell and per-Gauss-point passes (and the
/// one-workgroup scan), `PROBES_WG` for the probe gather, 1 for the
/// one-invocation step passes.
#[test]
fn workgroup_sizes_match_the_dispatch() {
    use lme_mpm::gpu::layout::{PROBES_WG, WG};
    for (pass, m) in every_pass_module() {
        let want = match pass {
            Pass::StepBegin | Pass::StepEnd => 1,
            // One invocation per lane (field × component), a workgroup each.
            Pass::ConstraintPoints | Pass::ConstraintPointsForce => 1,
            Pass::Probes => PROBES_WG,
            _ => WG,
        };
        assert_eq!(m.entry_points.len(), 1, "{pass:?}");
        assert_eq!(
            m.entry_points[0].workgroup_size,
            [want, 1, 1],
            "{pass:?} workgroup size"
        );
    }
}

/// The GPU fixes whole boxes of nodes: a constraint group that is not a box
/// of the lattice is refused with the scene key, in release builds too.
#[test]
fn constraint_groups_must_be_boxes_of_nodes() {
    use lme_mpm::gpu::buffers::constraint_boxes;
    let scene = lme_mpm::scene::Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/elastic_block.toml"),
        &[],
    )
    .unwrap();
    let mut model = lme_mpm::model::Model::new(&scene).unwrap();
    let boxes = constraint_boxes(&model).unwrap();
    assert_eq!(boxes.len(), model.constraints.groups.len());
    for (b, grp) in boxes.iter().zip(&model.constraints.groups) {
        let area = (b.i1 - b.i0 + 1) * (b.j1 - b.j0 + 1);
        assert_eq!(area as usize, grp.nodes.len(), "{}", grp.name);
    }
    // Drop one node from the middle of the longest group: its box has a hole.
    let grp = model
        .constraints
        .groups
        .iter_mut()
        .max_by_key(|g| g.nodes.len())
        .unwrap();
    assert!(grp.nodes.len() >= 3);
    let name = grp.name.clone();
    let mid = grp.nodes.len() / 2;
    grp.nodes.remove(mid);
    let err = constraint_boxes(&model).unwrap_err().to_string();
    assert!(
        err.contains(&format!("constraints.{name}")) && err.contains("box"),
        "{err}"
    );
    // A duplicated node does not pass for the missing one.
    let grp = &mut model
        .constraints
        .groups
        .iter_mut()
        .find(|g| g.name == name)
        .unwrap();
    let first = grp.nodes[0];
    grp.nodes.insert(mid, first);
    assert!(constraint_boxes(&model).is_err());
}

/// The GPU's compensated sums (`shared/kahan.wgsl`, the displacement in
/// g2p) on the adapter the suite runs on: 10 000 steps of 1e-7 onto 1.0.
/// A plain f32 sum rounds each step to an ulp of 1 (1.19e-7) and ends
/// 1.2e-3 too far; a working compensation ends within a few ulp. Written as
/// `lo = ((s + y) − s) − y`, llvmpipe folds the compensation away (in a
/// kernel of that sum alone it ended exactly where the plain sum does; in
/// this one, which runs both and prints both, 1.9e-4 off).
#[test]
fn compensated_sums_survive_the_driver() {
    use lme_mpm::gpu::preprocess::{Defines, expand_text};
    const KERNEL: &str = r#"
#include "shared/kahan.wgsl"
@group(0) @binding(0) var<storage, read_write> buf: array<f32>;
@group(0) @binding(1) var<storage, read> zero: array<u32>;
@compute @workgroup_size(1)
fn main() {
    let du = vec2<f32>(buf[2]);
    var naive = vec2<f32>(buf[0]);
    var naive_lo = vec2<f32>(0.0);
    var s = vec2<f32>(buf[0]);
    var lo = vec2<f32>(0.0);
    for (var k = 0u; k < 10000u; k++) {
        let y = du - naive_lo;
        let t = naive + y;
        naive_lo = (t - naive) - y;
        naive = t;
        let r = kahan_add2(s, lo, du, zero[0]);
        s = r.sum;
        lo = r.lo;
    }
    buf[0] = s.x;
    buf[1] = lo.x;
    buf[3] = naive.x;
    buf[4] = naive_lo.x;
}
"#;
    let Some(ctx) = crate::common::gpu::open("compensated sums", false) else {
        return;
    };
    let src = expand_text(KERNEL, "kahan_test", &Defines::default()).unwrap();
    let dev = &ctx.device;
    let module = dev.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("kahan_test"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = dev.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("kahan_test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let make = |bytes: &[u8], usage| {
        let b = dev.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: bytes.len() as u64,
            usage: usage | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&b, 0, bytes);
        b
    };
    let data: [f32; 8] = [1.0, 0.0, 1e-7, 0.0, 0.0, 0.0, 0.0, 0.0];
    let buf = make(bytemuck::cast_slice(&data), wgpu::BufferUsages::COPY_SRC);
    let zero = make(
        bytemuck::cast_slice(&[0u32; 4]),
        wgpu::BufferUsages::empty(),
    );
    let v = crate::common::gpu::dispatch_and_read(
        &ctx,
        &pipeline,
        &[(0, &buf), (1, &zero)],
        1,
        &buf,
        32,
    );
    let exact = 1.0 + 10_000.0 * 1e-7f32 as f64;
    let kahan = v[0] as f64 - v[1] as f64;
    let naive = v[3] as f64 - v[4] as f64;
    println!(
        "10 000 × 1e-7 onto 1: kahan_add2 off by {:.2e}; the plain-written compensation off by {:.2e}",
        kahan - exact,
        naive - exact
    );
    assert!(
        (kahan - exact).abs() < 1e-6,
        "the compensation was lost: {kahan} against {exact}"
    );
}
