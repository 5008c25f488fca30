//! Contact between bodies (`[contact.NAME]`): each body of a declared pair
//! moves on its own copy of the grid's nodal fields (a *field*); bodies in
//! no pair share field 0, as every body did before. The fields are stacked:
//! node `i` of field `f` is entry `f · n_nodes + i` of every nodal array,
//! so the stages that scatter and gather through the particles' node lists
//! run unchanged once `shape_eval` has offset each particle's nodes into
//! its field (`cpu::contact_grad::offset_nodes`). Where two fields of a declared
//! pair both have mass and their particles' domains meet, the pair's law
//! acts on their relative velocity (`cpu::contact_exchange`); where two fields that
//! are not a declared pair meet, they move together (their centre of mass
//! velocity), which is what one shared field does.

use crate::model::walls::{CONTACT_FRICTION, CONTACT_SLIP, CONTACT_STICK};
use crate::scene::{Contact, Scene};

/// Share of PIC in the velocity update of every particle that reaches a
/// node where one of its body's pairs with a tangential force (stick,
/// friction) is in contact (g2p, both backends; the momentum it changes
/// is given back to the body by `contact_conserve`):
/// the blend `solver.pic_fraction` gives the whole scene, here at least
/// 0.05 and only at the interface. Pure FLIP keeps the interface nodes'
/// noise: two elastic bodies in contact ring there at about a kilohertz,
/// so the Coulomb cap is met at some nodes in every cycle and a soft block
/// (E = 1 MPa, μ = 0.7) creeps down a 30° slope where μ > tan 30° means
/// rest (0.083 m/s and 50 mm by 0.95 s, 2026-12-01). With 5 % PIC at the
/// interface it holds (docs/methods.md, "Contact between bodies"); the
/// sliding rate with μ = 0.2 moves by 0.1 %.
pub const CONTACT_PIC_FRACTION: f64 = 0.05;

/// One declared pair.
#[derive(Debug, Clone, PartialEq)]
pub struct Pair {
    pub name: String,
    /// The fields of the pair's first and second body.
    pub fields: [u32; 2],
    /// `CONTACT_*` (as for walls).
    pub law: u32,
    /// Coulomb μ (friction only; 0 otherwise).
    pub mu: f64,
}

/// The scene's contact pairs and the field of each body.
#[derive(Debug, Clone, PartialEq)]
pub struct Contacts {
    pub pairs: Vec<Pair>,
    /// Per body (scene order): its field.
    pub field_of_body: Vec<u32>,
    /// Fields in all: 1 + the bodies in some pair (the bodies in no pair
    /// share field 0, which may then hold no particle).
    pub n_fields: usize,
}

impl Contacts {
    /// The scene's pairs; None without any (the scene runs on one field).
    pub fn from_scene(scene: &Scene) -> Option<Contacts> {
        let f = &scene.file;
        if f.contact.is_empty() {
            return None;
        }
        let names: Vec<&String> = scene.bodies().map(|(n, _)| n).collect();
        let mut field_of_body = vec![0u32; names.len()];
        let mut n_fields = 1;
        // Fields in body order, so they do not depend on the pairs' names.
        for (b, name) in names.iter().enumerate() {
            if f.contact.values().any(|c| c.bodies.contains(name)) {
                field_of_body[b] = n_fields as u32;
                n_fields += 1;
            }
        }
        let field = |name: &String| {
            let b = names.iter().position(|n| *n == name).expect("validated");
            field_of_body[b]
        };
        let pairs = f
            .contact
            .iter()
            .map(|(name, c)| {
                let (law, mu) = match c.law {
                    Contact::Stick => (CONTACT_STICK, 0.0),
                    Contact::Slip => (CONTACT_SLIP, 0.0),
                    Contact::Friction => (CONTACT_FRICTION, c.friction.unwrap_or(0.0)),
                };
                Pair {
                    name: name.clone(),
                    fields: [field(&c.bodies[0]), field(&c.bodies[1])],
                    law,
                    mu,
                }
            })
            .collect();
        Some(Contacts {
            pairs,
            field_of_body,
            n_fields,
        })
    }

    /// The declared pair of fields `a` and `b` (either order), if any.
    pub fn pair_of(&self, a: u32, b: u32) -> Option<&Pair> {
        self.pairs
            .iter()
            .find(|p| p.fields == [a, b] || p.fields == [b, a])
    }
}
