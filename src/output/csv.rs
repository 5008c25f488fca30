//! CSV tables: probes, energy, reactions (one row per sample) and the final
//! particle state. Numbers are written with Rust's shortest round-trip
//! formatting, so they read back exactly.

use crate::backend::Sample;
use crate::model::Particles;
use crate::output::state::StateLayout;
use std::fmt::Write;

/// `t,probe,x,y,vx,vy,sxx,syy,sxy` (s, m, m/s, Pa), in saturated soil
/// `,pore_pressure` (Pa; the stress is then the effective one), and for the implicit
/// integrator `newton_iterations,newton_residual,dt` of the step before
/// the sample (empty for samples read back from a checkpoint).
/// `names` in `Model::probes` order.
pub fn probes(names: &[String], samples: &[Sample]) -> String {
    let implicit = samples.iter().any(|s| s.newton.is_some());
    let saturated = samples
        .iter()
        .any(|s| s.probes.iter().any(|p| p.pore_pressure.is_some()));
    let mut s = String::from("t,probe,x,y,vx,vy,sxx,syy,sxy");
    if saturated {
        s.push_str(",pore_pressure");
    }
    s.push_str(if implicit {
        ",newton_iterations,newton_residual,dt\n"
    } else {
        "\n"
    });
    for smp in samples {
        for (name, st) in names.iter().zip(&smp.probes) {
            let _ = write!(
                s,
                "{},{},{},{},{},{},{},{},{}",
                smp.t,
                name,
                st.x[0],
                st.x[1],
                st.v[0],
                st.v[1],
                st.stress[0],
                st.stress[1],
                st.stress[2]
            );
            if saturated {
                let _ = write!(s, ",{}", st.pore_pressure.unwrap_or(0.0));
            }
            match (implicit, smp.newton) {
                (false, _) => {}
                (true, Some(n)) => {
                    let _ = write!(s, ",{},{},{}", n.iterations, n.residual, n.dt);
                }
                (true, None) => s.push_str(",,,"),
            }
            s.push('\n');
        }
    }
    s
}

/// `t,kinetic,strain,total` (s, J per metre of thickness).
pub fn energy(samples: &[Sample]) -> String {
    let mut s = String::from("t,kinetic,strain,total\n");
    for smp in samples {
        let e = &smp.energy;
        let _ = writeln!(
            s,
            "{},{},{},{}",
            smp.t,
            e.kinetic,
            e.strain,
            e.kinetic + e.strain
        );
    }
    s
}

/// `t,constraint,rx,ry` (s, N per metre of thickness): the force each
/// constraint and wall exerts on the body, and each contact pair's on its
/// first body. `names` as `Model::reaction_names` gives them (constraints,
/// walls, pairs), in the order of `Sample::reactions`.
pub fn reactions(names: &[String], samples: &[Sample]) -> String {
    let mut s = String::from("t,constraint,rx,ry\n");
    for smp in samples {
        for (name, r) in names.iter().zip(&smp.reactions) {
            let _ = writeln!(s, "{},{},{},{}", smp.t, name, r[0], r[1]);
        }
    }
    s
}

/// `id,body,x0,y0,x,y,vx,vy,sxx,syy,sxy,mass,volume` (m, m/s, Pa, kg/m, m²),
/// then with a plastic material `,szz,<state columns>,plastic`: σzz (Pa),
/// the columns the materials name (`StateLayout::columns`: `eps_p,eps_pv`
/// for Mohr–Coulomb and Drucker–Prager, `p_c,v` for modified Cam-clay),
/// and the surfaces active in the last step's return (bit mask, 0 =
/// elastic; docs/outputs.md); then in saturated soil `,pore_pressure`
/// (Pa, compression positive; the stress columns are the effective
/// stress σ' = σ + p I). `body_names` in scene order.
pub fn particles(body_names: &[String], state: &StateLayout, p: &Particles) -> String {
    let plastic = !p.plastic.is_empty();
    let mut s = String::with_capacity(p.len() * if plastic { 240 } else { 160 } + 64);
    s.push_str("id,body,x0,y0,x,y,vx,vy,sxx,syy,sxy,mass,volume");
    if plastic {
        s.push_str(",szz");
        for c in state.columns() {
            s.push(',');
            s.push_str(c.column);
        }
        s.push_str(",plastic");
    }
    let saturated = !p.pore_pressure.is_empty();
    if saturated {
        s.push_str(",pore_pressure");
    }
    s.push('\n');
    for i in 0..p.len() {
        let _ = write!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            i,
            body_names[p.body[i] as usize],
            p.x0[i][0],
            p.x0[i][1],
            p.x[i][0],
            p.x[i][1],
            p.v[i][0],
            p.v[i][1],
            p.stress[i][0],
            p.stress[i][1],
            p.stress[i][2],
            p.mass[i],
            p.volume(i)
        );
        if plastic {
            let q = &p.plastic[i];
            let _ = write!(s, ",{}", q[0]);
            for c in 0..state.columns().count() {
                let _ = write!(s, ",{}", state.value(c, p, i));
            }
            let _ = write!(s, ",{}", q[3] as u32);
        }
        if saturated {
            let _ = write!(s, ",{}", p.pore_pressure[i]);
        }
        s.push('\n');
    }
    s
}
