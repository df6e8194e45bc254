//! The touching contacts of a [`DemContacts`] as sticking springs for a modal analysis
//! (`spring_blocks.rs`): the stiffness [`qdem_core::step::Model::modal_stiffness`] gives.

use super::*;

impl DemContacts {
    /// Where sphere `s`'s side of a contact attaches, the contact point at `arm` from its
    /// centre.
    pub(super) fn attachment(&self, state: &State, s: usize, arm: Vec3) -> Attachment {
        let bodies = state.rigid.len();
        let node = match self.spheres.turn()[s] {
            NOT_RIGID => None,
            t if (t as usize) < bodies => Some(state.body_rotation_node(t as usize)),
            t => Some(state.len() + t as usize - bodies),
        };
        Attachment {
            particle: self.spheres.particle()[s] as usize,
            turn: node.map(|n| (n, arm)),
        }
    }
}

impl Linearized for DemContacts {
    /// The springs of the contacts touching at the last evaluation, at the geometry it saw.
    fn add_tangent(&self, state: &State, tangent: &mut Tangent) {
        let law = &self.settings.law;
        for c in &self.candidates.pairs().items {
            let (a, b) = (c.first as usize, c.second as usize);
            let (sa, sb) = (self.spheres.now(a), self.spheres.now(b));
            let shift = self.separation(a, b).1;
            let Some(g) = narrow_phase(sa, sb, shift, self.settings.friction) else {
                continue;
            };
            let e = self.spheres.pair_elasticity(sa, sb);
            let (kn, kt) = law.stiffness(g.overlap, g.radius, &e);
            let half = 0.5 * g.overlap;
            let pa = self.attachment(state, a, (sa.radius - half) * g.normal);
            let pb = self.attachment(state, b, -(sb.radius - half) * g.normal);
            add_spring(tangent, pa, Some(pb), &spring(&g.normal, kn, kt));
        }
        let time = self.evaluation.last_time().unwrap_or(0.0);
        for c in &self.candidates.wall_contacts().items {
            let (s, w) = (c.first as usize, c.second as usize);
            let Some((g, e)) = self.wall_contact(time, s, w) else {
                continue;
            };
            let (kn, kt) = law.stiffness(g.overlap, g.radius, &e);
            let arm = (self.spheres.now(s).radius - 0.5 * g.overlap) * g.normal;
            let side = self.attachment(state, s, arm);
            add_spring(tangent, side, None, &spring(&g.normal, kn, kt));
        }
    }
}
