//! Rolling resistance in the pair kernel ([`crate::dem::laws::rolling_resistance`]): with
//! `[contact] rolling_friction` > 0 every candidate list keeps a rolling spring torque M_r
//! per record (its `roll` column; none without, so a scene without rolling friction steps,
//! saves and exchanges exactly as before). The law of a touching contact updates M_r from
//! the relative spin of its spheres (a wall does not turn) and the normal force and
//! tangential stiffness of this step; the first sphere then feels −M_r and the second +M_r,
//! scaled like the contact's force for a ghost beyond a time-delayed boundary. A contact
//! found apart releases its spring. The columns are saved after the rest of the model's
//! history, only with rolling friction, and travel in a decomposed run's merged records.

use super::*;
use crate::dem::laws::rolling_resistance::RollingResistance;

impl DemContacts {
    /// Adds rolling resistance of coefficient μ_r = `coefficient` to every contact, pairs and
    /// walls (none for μ_r = 0). Refused for a negative or non-finite coefficient.
    pub fn with_rolling_friction(mut self, coefficient: f64) -> Result<DemContacts, ContactError> {
        if !(coefficient.is_finite() && coefficient >= 0.0) {
            return Err(ContactError::RollingFriction { coefficient });
        }
        self.rolling = (coefficient > 0.0).then_some(RollingResistance { coefficient });
        Ok(self)
    }

    /// The rolling resistance, if any.
    pub(super) fn rolling(&self) -> Option<&RollingResistance> {
        self.rolling.as_ref()
    }

    /// Updates pair `contact`'s rolling spring `spring` from its geometry `g`, elasticity `e`
    /// and force on the first sphere `force`, over `dt`.
    #[inline]
    pub(super) fn roll_pair(
        &self,
        contact: &Contact,
        (g, e): (&PairGeometry, &PairElasticity),
        force: &Vec3,
        spring: &mut Vec3,
        dt: f64,
    ) {
        let (a, b) = (contact.first as usize, contact.second as usize);
        let spin = self.spheres.now(a).spin - self.spheres.now(b).spin;
        self.roll(g, e, &spin, force, spring, dt);
    }

    /// Updates wall contact `contact`'s rolling spring as [`DemContacts::roll_pair`] does; the
    /// wall does not turn.
    #[inline]
    pub(super) fn roll_wall(
        &self,
        contact: &Contact,
        (g, e): (&PairGeometry, &PairElasticity),
        force: &Vec3,
        spring: &mut Vec3,
        dt: f64,
    ) {
        let spin = self.spheres.now(contact.first as usize).spin;
        self.roll(g, e, &spin, force, spring, dt);
    }

    #[inline]
    fn roll(
        &self,
        g: &PairGeometry,
        e: &PairElasticity,
        spin: &Vec3,
        force: &Vec3,
        spring: &mut Vec3,
        dt: f64,
    ) {
        let Some(rolling) = &self.rolling else {
            return;
        };
        let (_, k_t) = self.settings.law.stiffness(g.overlap, g.radius, e);
        let normal_force = -force.dot(&g.normal);
        rolling.update(&g.normal, g.radius, spin, normal_force, k_t, spring, dt);
    }

    /// The elastic energy of the touching contacts' rolling springs, Σ |M_r|²/(2 k_r) (J);
    /// `None` without rolling friction.
    pub(super) fn rolling_energy(&self, time: f64) -> Option<f64> {
        self.rolling.as_ref()?;
        let law = &self.settings.law;
        let energy = |(g, e): (PairGeometry, PairElasticity), m: &Vec3| {
            let (_, k_t) = law.stiffness(g.overlap, g.radius, &e);
            let k_r = RollingResistance::stiffness(k_t, g.radius);
            match k_r > 0.0 {
                true => m.norm_squared() / (2.0 * k_r),
                false => 0.0,
            }
        };
        let pairs = self.candidates.pairs();
        let walls = self.candidates.wall_contacts();
        let pairs = pairs
            .with_shifts()
            .zip(&pairs.roll)
            .filter_map(|((c, mut shift), m)| {
                self.pair_contact(c, &mut shift)
                    .map(|contact| energy(contact, m))
            });
        let walls = walls.items.iter().zip(&walls.roll).filter_map(|(c, m)| {
            self.wall_contact(time, c.first as usize, c.second as usize)
                .map(|contact| energy(contact, m))
        });
        Some(pairs.chain(walls).sum())
    }

    /// Writes the rolling springs of both lists, with rolling friction only (module doc).
    pub(super) fn save_rolling(&self, out: &mut Encoder) {
        if self.rolling.is_none() {
            return;
        }
        out.tag("rolling");
        for list in [self.candidates.pairs(), self.candidates.wall_contacts()] {
            out.vec3s(&list.roll);
        }
    }

    /// Reads back what [`DemContacts::save_rolling`] wrote.
    pub(super) fn restore_rolling(
        &mut self,
        input: &mut Decoder<'_>,
    ) -> Result<(), CheckpointError> {
        if self.rolling.is_none() {
            return Ok(());
        }
        if input.is_done() {
            return Err(CheckpointError::Invalid {
                what: "contact history",
                detail: "it was written without `rolling_friction`; resume it with \
                         the scene that wrote it, or start a stage from it (`[run] start_from`)"
                    .to_string(),
            });
        }
        input.tag("rolling")?;
        let n = self.candidates.pairs().len();
        self.candidates.pairs_mut().roll = input.vec3s_exact(n, "rolling springs")?;
        let n = self.candidates.wall_contacts().len();
        self.candidates.wall_contacts_mut().roll = input.vec3s_exact(n, "rolling springs")?;
        Ok(())
    }
}

/// A pair's or wall contact's share `share` of its first sphere with its rolling spring
/// `roll` (if the list keeps one), scaled by `scale`: the moment less `scale` M_r.
#[inline(always)]
pub(super) fn first_rolls(share: (Vec3, Vec3), roll: Option<&Vec3>, scale: f64) -> (Vec3, Vec3) {
    match roll {
        Some(m) => (share.0, share.1 - scale * m),
        None => share,
    }
}

/// A pair's share `share` of its second sphere with its rolling spring `roll` (if the list
/// keeps one), scaled by `scale`: the moment plus `scale` M_r.
#[inline(always)]
pub(super) fn second_rolls(share: (Vec3, Vec3), roll: Option<&Vec3>, scale: f64) -> (Vec3, Vec3) {
    match roll {
        Some(m) => (share.0, share.1 + scale * m),
        None => share,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::laws::linear_spring::LinearSpring;
    use crate::{PlaneWall, WallShape};
    use qdem_core::Mat3;

    /// Two one-sphere rigid bodies pressed together (1 µm) and the lower one into a floor,
    /// spinning, with rolling friction `mu_r`.
    fn spinning_pair(mu_r: f64) -> (State, DemContacts) {
        let r = 0.01;
        let centers = vec![
            Vec3::new(0.0, 0.0, r - 1e-6),
            Vec3::new(0.0, 0.0, 3.0 * r - 2e-6),
        ];
        let mut state = State::at_rest(centers);
        state.mass = vec![0.01, 0.01];
        for b in 0..2 {
            let inertia = Mat3::identity() * (0.4 * 0.01 * r * r);
            state.add_rigid_body("sphere", b, &[], inertia).unwrap();
        }
        state
            .rigid
            .set_angular_velocity(0, Vec3::new(0.0, 5.0, 0.0));
        state
            .rigid
            .set_angular_velocity(1, Vec3::new(-2.0, 0.0, 1.0));
        let spheres: Vec<ContactSphere> = (0..2)
            .map(|b| ContactSphere {
                particle: b,
                radius: r,
                body: b,
                material: 0,
            })
            .collect();
        let floor = Wall {
            shape: WallShape::Plane(PlaneWall::new(Vec3::zeros(), Vec3::z(), Vec3::zeros())),
            friction: 0.5,
        };
        let settings = ContactSettings {
            law: ContactLaw::Linear(LinearSpring {
                normal_stiffness: 1e5,
                tangential_stiffness: 1e5,
                damping_ratio: 0.0,
            }),
            friction: 0.5,
            skin: 0.001,
        };
        let names = vec!["a".to_string(), "b".to_string()];
        let contacts = DemContacts::new(
            &state,
            &spheres,
            names,
            &[(1e9, 0.25)],
            settings,
            vec![floor],
        )
        .with_rolling_friction(mu_r)
        .unwrap();
        (state, contacts)
    }

    fn torques(model: &mut DemContacts, state: &State) -> Vec<Vec3> {
        let (mut force, mut torque) = (vec![Vec3::zeros(); 2], vec![Vec3::zeros(); 2]);
        model.add_forces(state, &mut force, &mut torque);
        torque
    }

    #[test]
    fn a_checkpoint_keeps_the_rolling_springs_and_one_without_them_is_refused() {
        let (mut state, mut saved) = spinning_pair(0.1);
        for k in 0..3 {
            state.time = 1e-6 * k as f64;
            torques(&mut saved, &state);
        }
        assert!(saved.candidates.pairs().roll[0].norm() > 0.0);
        assert!(saved.candidates.wall_contacts().roll[0].norm() > 0.0);
        let mut out = Encoder::new();
        saved.save(&mut out);
        let (_, mut restored) = spinning_pair(0.1);
        restored.restore(&mut Decoder::new(out.bytes())).unwrap();
        state.time = 3e-6;
        assert_eq!(torques(&mut restored, &state), torques(&mut saved, &state));
        // A checkpoint of the same scene without rolling friction has no springs to give.
        let (_, without) = spinning_pair(0.0);
        let mut out = Encoder::new();
        without.save(&mut out);
        let refused = restored
            .restore(&mut Decoder::new(out.bytes()))
            .unwrap_err();
        assert!(
            refused.to_string().contains("without `rolling_friction`"),
            "{refused}"
        );
    }
}
