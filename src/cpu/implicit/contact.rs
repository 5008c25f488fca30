//! Wall contact in the implicit step: a penalty on the nodes behind a
//! `slip` or `friction` wall, written per contact state so that Newton can
//! hold the state of every wall node fixed while it converges (an active
//! set), and the rule that revises a held state from the law's own.
//!
//! A node is in contact when its gap to the wall's contact line at the
//! step's end is closed, g = g₀ + Δu·n ≤ 0, g₀ the gap at the step's start
//! (`ContactPair::gap`): 0 for a grid node behind the wall (implicit MPM:
//! the node holds where it is, its increment may not move it further
//! behind), the node's distance to the line for a GMM cloud node, which
//! moves with the body (`gmm::GmmNodes::wall_pairs`). The normal force is
//! then −k g n. Coulomb's
//! law on the tangential increment s = Δu·t (t = n rotated a quarter turn)
//! is a return map: the trial (stick) force −k s t if |k s| ≤ μ k |g|,
//! else μ k |g| against the slip (the test: `model::walls::coulomb_slip`
//! with the μ of `Wall::coulomb_mu`, as in the explicit step). Within one
//! state the force is linear in Δu, so its derivative is exact there; the
//! law as a whole is only piecewise smooth, which is why Newton holds the
//! states (`mod.rs`).

use crate::model::walls::{CONTACT_FRICTION, CONTACT_STICK, Wall, coulomb_slip};

/// A wall node's contact state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactState {
    /// Separating (g > 0): no force.
    Open,
    /// In contact, held tangentially: f = −k Δu.
    Stick,
    /// In contact, sliding along +t (`1.0`) or −t (`-1.0`):
    /// f = −k g n + μ k g σ t (μ = 0 on a `slip` wall).
    Slip(f64),
}

/// A state as one byte, for checkpoints: 0 open, 1 stick, 2 slip along
/// +t, 3 slip along −t.
pub fn code(state: ContactState) -> u8 {
    match state {
        ContactState::Open => 0,
        ContactState::Stick => 1,
        ContactState::Slip(s) if s >= 0.0 => 2,
        ContactState::Slip(_) => 3,
    }
}

/// The state of `code` (None for a byte no state has).
pub fn from_code(code: u8) -> Option<ContactState> {
    match code {
        0 => Some(ContactState::Open),
        1 => Some(ContactState::Stick),
        2 => Some(ContactState::Slip(1.0)),
        3 => Some(ContactState::Slip(-1.0)),
        _ => None,
    }
}

/// A node that may touch a wall in this step, with mass: one contact of
/// the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPair {
    pub node: u32,
    /// Index into the model's wall list.
    pub wall: u32,
    /// The gap g₀ (m) between the node and the wall's contact line at the
    /// step's start, positive on the material's side: 0 for a grid node
    /// behind the line, the cloud node's distance for GMM.
    pub gap: f64,
}

/// Normal and tangential components of the gap at the increment `du` of
/// a node `gap` (m) from the line at the step's start: (g₀ + Δu·n, Δu·t).
#[inline]
fn components(wall: &Wall, gap: f64, du: [f64; 2]) -> (f64, f64) {
    let n = wall.normal;
    (
        gap + du[0] * n[0] + du[1] * n[1],
        -du[0] * n[1] + du[1] * n[0],
    )
}

/// The state Coulomb's law gives at `du` for a node `gap` (m) from the
/// line at the step's start. g = 0 counts as contact (zero force, full
/// stiffness): a node resting on the wall starts each step in contact, so
/// Newton does not begin by letting it fall through. A `stick` wall's
/// contacts (GMM's cloud nodes only: the grid holds a stick wall's nodes
/// as fixed components instead) stick while closed, as friction with no
/// bound on μ (not `STICK_MU`: the explicit step's bound), and let go
/// when the node lifts off. A `slip` wall's slip without a test. On a
/// `friction` wall, Coulomb's test (`coulomb_slip`) of |s| against μ |g|
/// (both forces' k cancels).
pub fn natural_state(wall: &Wall, gap: f64, du: [f64; 2]) -> ContactState {
    let (g, s) = components(wall, gap, du);
    if g > 0.0 {
        ContactState::Open
    } else if wall.contact == CONTACT_STICK {
        ContactState::Stick
    } else if wall.contact != CONTACT_FRICTION {
        ContactState::Slip(1.0)
    } else if coulomb_slip(s.abs(), -g, wall.coulomb_mu()).is_none() {
        ContactState::Stick
    } else {
        ContactState::Slip(s.signum())
    }
}

/// The force on a node `gap` (m) from the line at the step's start and
/// displaced by `du` under `state`, and its derivative
/// −∂f/∂Δu (2 × 2, row-major). Linear in Δu: exact for any `du`, also one
/// outside the state (a held state then gives a tensile normal force, or
/// friction along the slip, which the state revision removes).
pub fn force(
    wall: &Wall,
    gap: f64,
    du: [f64; 2],
    k: f64,
    state: ContactState,
) -> ([f64; 2], [f64; 4]) {
    let n = wall.normal;
    let t = [-n[1], n[0]];
    let (g, s) = components(wall, gap, du);
    let outer = |a: [f64; 2], b: [f64; 2], c: f64| {
        [
            c * a[0] * b[0],
            c * a[0] * b[1],
            c * a[1] * b[0],
            c * a[1] * b[1],
        ]
    };
    match state {
        ContactState::Open => ([0.0; 2], [0.0; 4]),
        ContactState::Stick => {
            let f = [-k * (g * n[0] + s * t[0]), -k * (g * n[1] + s * t[1])];
            (f, [k, 0.0, 0.0, k])
        }
        ContactState::Slip(sigma) => {
            // μ of the wall's law: `natural_state` gives a slip state
            // only on `slip` (0) and `friction` (μ) walls.
            let mu = wall.coulomb_mu();
            // f = −k g n + μ k g σ t (g ≤ 0: friction −μ k |g| σ t).
            let f = [
                -k * g * n[0] + mu * k * g * sigma * t[0],
                -k * g * n[1] + mu * k * g * sigma * t[1],
            ];
            let nn = outer(n, n, k);
            let tn = outer(t, n, -mu * k * sigma);
            (f, std::array::from_fn(|i| nn[i] + tn[i]))
        }
    }
}

/// Coulomb's law itself: the force under the state it gives at `du`.
pub fn contact(wall: &Wall, gap: f64, du: [f64; 2], k: f64) -> ([f64; 2], [f64; 4]) {
    force(wall, gap, du, k, natural_state(wall, gap, du))
}

/// The state to hold next, from the held one and the law's at Newton's
/// solution under the held one. A slip that came out reversed means the
/// node is held between the two directions: stick. Otherwise the law's.
pub fn revise(held: ContactState, natural: ContactState) -> ContactState {
    match (held, natural) {
        (ContactState::Slip(a), ContactState::Slip(b)) if a != b => ContactState::Stick,
        (_, b) => b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::walls::CONTACT_SLIP;

    fn wall(contact: u32) -> Wall {
        let n = [0.6, 0.8];
        Wall {
            name: "w".into(),
            point: [0.0; 2],
            normal: n,
            contact,
            mu: 0.5,
            nodes: Vec::new(),
            stiffness: 0.0,
            offset: 0.0,
            appear_at: 0.0,
            remove_at: f64::INFINITY,
        }
    }

    /// Δu from normal and tangential parts.
    fn du(w: &Wall, g: f64, s: f64) -> [f64; 2] {
        let n = w.normal;
        [g * n[0] - s * n[1], g * n[1] + s * n[0]]
    }

    #[test]
    fn states_follow_coulomb() {
        let w = wall(CONTACT_FRICTION);
        assert_eq!(
            natural_state(&w, 0.0, du(&w, 1e-6, 0.0)),
            ContactState::Open
        );
        assert_eq!(
            natural_state(&w, 0.0, du(&w, 0.0, 0.0)),
            ContactState::Stick
        );
        assert_eq!(
            natural_state(&w, 0.0, du(&w, -1e-6, 4e-7)),
            ContactState::Stick
        );
        assert_eq!(
            natural_state(&w, 0.0, du(&w, -1e-6, -6e-7)),
            ContactState::Slip(-1.0)
        );
        let s = wall(CONTACT_SLIP);
        assert_eq!(
            natural_state(&s, 0.0, du(&s, -1e-6, 0.0)),
            ContactState::Slip(1.0)
        );
    }

    #[test]
    fn slip_force_is_mu_times_the_normal_one_against_the_slip() {
        let w = wall(CONTACT_FRICTION);
        let k = 1e9;
        let (f, _) = contact(&w, 0.0, du(&w, -1e-6, 5e-6), k);
        let n = w.normal;
        let t = [-n[1], n[0]];
        let fn_ = f[0] * n[0] + f[1] * n[1];
        let ft = f[0] * t[0] + f[1] * t[1];
        assert!((fn_ - 1e3).abs() < 1e-9, "{fn_}");
        assert!((ft + 0.5e3).abs() < 1e-9, "{ft}");
    }

    #[test]
    fn the_law_is_continuous_across_stick_and_slip() {
        let w = wall(CONTACT_FRICTION);
        let k = 1e9;
        // At |s| = μ|g| both states give the same force.
        let d = du(&w, -1e-6, 0.5e-6);
        let (a, _) = force(&w, 0.0, d, k, ContactState::Stick);
        let (b, _) = force(&w, 0.0, d, k, ContactState::Slip(1.0));
        for i in 0..2 {
            assert!((a[i] - b[i]).abs() < 1e-9 * k * 1e-6, "{a:?} {b:?}");
        }
    }

    #[test]
    fn the_derivative_is_exact_within_a_state() {
        let w = wall(CONTACT_FRICTION);
        let k = 1e9;
        let d = du(&w, -1e-6, 3e-6);
        for state in [
            ContactState::Open,
            ContactState::Stick,
            ContactState::Slip(1.0),
            ContactState::Slip(-1.0),
        ] {
            let (_, kt) = force(&w, 2e-7, d, k, state);
            let eps = 1e-9;
            for c in 0..2 {
                let (mut p, mut m) = (d, d);
                p[c] += eps;
                m[c] -= eps;
                let (fp, _) = force(&w, 2e-7, p, k, state);
                let (fm, _) = force(&w, 2e-7, m, k, state);
                for r in 0..2 {
                    let fd = -(fp[r] - fm[r]) / (2.0 * eps);
                    assert!((kt[2 * r + c] - fd).abs() < 1e-6 * k, "{state:?}");
                }
            }
        }
    }

    #[test]
    fn a_gap_shifts_the_contact_line() {
        let w = wall(CONTACT_FRICTION);
        let k = 1e9;
        // A node 2e-6 m off the line closes it only past Δu·n = −2e-6 m,
        // and presses with what is left beyond.
        assert_eq!(
            natural_state(&w, 2e-6, du(&w, -1.5e-6, 0.0)),
            ContactState::Open
        );
        let (f, _) = contact(&w, 2e-6, du(&w, -3e-6, 0.0), k);
        let fn_ = f[0] * w.normal[0] + f[1] * w.normal[1];
        assert!((fn_ - 1e3).abs() < 1e-6, "{fn_}");
        // One pressed in 1e-6 m at the start pushes back before it moves.
        let (f, _) = contact(&w, -1e-6, [0.0; 2], k);
        let fn_ = f[0] * w.normal[0] + f[1] * w.normal[1];
        assert!((fn_ - 1e3).abs() < 1e-6, "{fn_}");
    }

    #[test]
    fn a_stick_wall_holds_a_closed_contact_and_lets_an_open_one_go() {
        let w = wall(CONTACT_STICK);
        assert_eq!(
            natural_state(&w, 0.0, du(&w, -1e-6, 1e-3)),
            ContactState::Stick
        );
        assert_eq!(
            natural_state(&w, -1e-6, du(&w, 2e-6, 0.0)),
            ContactState::Open
        );
    }

    #[test]
    fn states_round_trip_through_their_codes() {
        use ContactState::*;
        for s in [Open, Stick, Slip(1.0), Slip(-1.0)] {
            assert_eq!(from_code(code(s)), Some(s));
        }
        assert_eq!(from_code(4), None);
    }

    #[test]
    fn a_reversed_slip_becomes_stick() {
        use ContactState::*;
        assert_eq!(revise(Slip(1.0), Slip(-1.0)), Stick);
        assert_eq!(revise(Stick, Slip(-1.0)), Slip(-1.0));
        assert_eq!(revise(Slip(1.0), Open), Open);
        assert_eq!(revise(Open, Stick), Stick);
    }
}
