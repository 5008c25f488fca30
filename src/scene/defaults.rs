//! Defaults chosen from what a scene models, not fixed in the schema.

use super::schema::{IntegratorKind, SceneFile};

/// The PIC share of the explicit integrators' velocity update used where a
/// cohesionless granular material flows: `study granular` (docs/methods.md,
/// "Granular collapse") measured every gate-released collapse of a = 0.5–2
/// within −25 % to +16 % of the experiments' run-out with 1 % PIC, against
/// +8 % to +97 % with pure FLIP, whose grid noise keeps the deposit moving.
pub const GRANULAR_PIC: f64 = 0.01;

/// Models whose strength is cohesion and friction (`cohesion`,
/// `friction_angle` in degrees).
const FRICTIONAL: [&str; 2] = ["mohr_coulomb", "drucker_prager"];

/// `solver.pic_fraction` when the scene does not set it: `GRANULAR_PIC`
/// for an explicit run where gravity acts on a body of a frictional
/// material (friction angle above 0) with a cohesion below the weight of
/// one cell of it, ρ |g| h: such soil flows as a granular material, with
/// the reason in words; None (pure FLIP) for every other scene, where FLIP
/// keeps the energy PIC would take.
pub fn pic_fraction(file: &SceneFile) -> Option<(f64, String)> {
    if file.solver.pic_fraction.is_some() || file.solver.integrator == IntegratorKind::Implicit {
        return None;
    }
    let g = file.gravity.as_ref().map_or(0.0, |g| g.g[0].hypot(g.g[1]));
    let h = file.grid.h;
    file.bodies.iter().find_map(|(body, b)| {
        let m = file.materials.get(&b.material)?;
        let phi = m.get("friction_angle").unwrap_or(0.0);
        let c = m.get("cohesion").unwrap_or(0.0);
        let weight = m.density * g * h;
        (FRICTIONAL.contains(&m.model.as_str()) && phi > 0.0 && c < weight).then(|| {
            (
                GRANULAR_PIC,
                format!(
                    "solver.pic_fraction = {GRANULAR_PIC} by default: body '{body}' is of \
                     material '{}', frictional (friction angle {phi} degrees) and cohesionless \
                     at the grid's scale (cohesion {c} Pa below the weight of one cell of it, \
                     rho |g| h = {weight:.1} Pa), and pure FLIP's grid noise keeps such a deposit \
                     flowing; set solver.pic_fraction = 0 for pure FLIP",
                    b.material
                ),
            )
        })
    })
}

#[cfg(test)]
mod tests {
    use crate::scene::{Override, Scene};

    fn scene(text: &str, sets: &[&str]) -> Scene {
        let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        Scene::from_str(text, "t", "t", &o).unwrap()
    }

    #[test]
    fn a_cohesionless_granular_scene_gets_one_percent_pic_and_nothing_else_does() {
        let granular = crate::cases::GRANULAR_COLLAPSE;
        let s = scene(granular, &[]);
        assert_eq!(s.solver().pic_fraction, Some(0.01));
        assert!(
            s.chosen[0].contains("'column'") && s.chosen[0].contains("'sand'"),
            "{:?}",
            s.chosen
        );
        // The choice is the scene's to override, pure FLIP included.
        let s = scene(granular, &["solver.pic_fraction=0"]);
        assert_eq!((s.solver().pic_fraction, s.chosen.len()), (Some(0.0), 0));
        // Cohesive at the grid's scale (5 kPa against rho g h = 454 Pa), no
        // friction, no gravity: pure FLIP as before. (Without gravity the
        // case's exact run-out does not apply: its line goes.)
        let unscored: String = granular
            .lines()
            .filter(|l| !l.starts_with("exact"))
            .collect::<Vec<_>>()
            .join("\n");
        for sets in [
            &["materials.sand.cohesion=5e3"][..],
            &["materials.sand.friction_angle=0"],
            &[
                "gravity.g=[0.0, 0.0]",
                "bodies.column.initial_stress=\"none\"",
            ],
        ] {
            let s = scene(&unscored, sets);
            assert_eq!(s.solver().pic_fraction, None, "{sets:?}");
        }
        // The cohesive column of the implicit-MPM paper stays FLIP.
        let s = scene(crate::cases::COLUMN_COLLAPSE, &[]);
        assert_eq!(s.solver().pic_fraction, None);
    }
}
