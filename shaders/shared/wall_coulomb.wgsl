// Coulomb's law of a wall's contact, |f_t| <= mu f_n, for `wall_contact.wgsl`.
// CPU twin: `Wall::coulomb_mu` and `coulomb_slip` in src/model/walls.rs.

// Keep in sync with src/model/walls.rs.
const STICK_MU: f32 = 20.0;

// Coulomb's mu of the wall's law: STICK_MU on a stick wall, the wall's
// own mu on a friction wall, 0 on a slip wall. CPU twin: `Wall::coulomb_mu`.
fn coulomb_mu(w: Wall) -> f32 {
    if w.contact == CONTACT_STICK {
        return STICK_MU;
    }
    if w.contact == CONTACT_FRICTION {
        return w.mu;
    }
    return 0.0;
}

// Whether the tangential `trial` (the magnitude of the force that would
// hold the contact) exceeds mu times the normal force (slip), and the
// bound mu `normal` it is then capped at. CPU twin: `coulomb_slip` (an
// Option: `cap` is its value when `slips`).
struct CoulombSlip {
    slips: bool,
    cap: f32,
}

fn coulomb_slip(trial: f32, normal: f32, mu: f32) -> CoulombSlip {
    let cap = mu * normal;
    return CoulombSlip(trial > cap, cap);
}
