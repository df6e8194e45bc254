//! What a checkpoint keeps of a [`DemContacts`]: its spheres' particles, the candidate lists
//! with their tangential springs, where and when they were built, the time-delayed boundary's
//! estimates, every wall's place and velocity (a servo wall's plane as its servo left it),
//! and the rolling springs (none written without rolling friction: `rolling.rs`).
//!
//! A scene that starts from another scene's checkpoint (`[run] start_from`) takes the
//! stretched tangential springs out of it by stable identities ([`SavedSprings`]): a pair by
//! the particles that carry its spheres, a wall contact by its sphere's particle and the
//! wall's index. A body's contact spheres sit on its mesh nodes whether it is deformable or
//! rigid (a rigid body's nodes are its members), so a stone keeps its springs when its kind
//! changes; [`DemContacts::carry_springs`] puts them on the same spheres of the new stage and
//! counts those whose sphere or wall the new stage does not have. Its walls start where the
//! checkpoint's were ([`SavedWall`], [`DemContacts::carry_wall`]), unless the stage says
//! otherwise.

use super::*;
use std::collections::HashMap;

/// One stretched tangential spring of a saved contact, by stable identities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SavedSpring {
    /// The particle carrying the first sphere.
    pub first: u32,
    /// The particle carrying the second sphere (a pair), or the wall's index (a wall contact).
    pub second: u32,
    /// The spring's elongation ξ (m), as it acts on the first sphere.
    pub spring: Vec3,
}

/// The stretched tangential springs of the contacts a checkpoint holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SavedSprings {
    /// Between two spheres.
    pub pairs: Vec<SavedSpring>,
    /// Between a sphere and a wall.
    pub walls: Vec<SavedSpring>,
}

impl SavedSprings {
    /// Reads the springs out of the `history` a [`DemContacts`] wrote into a checkpoint (its
    /// block of [`qdem_core::checkpoint::model_histories`]), without the model that wrote it.
    ///
    /// # Errors
    /// [`CheckpointError`] when the history is not a contact model's.
    pub fn read(history: &[u8]) -> Result<SavedSprings, CheckpointError> {
        let mut input = Decoder::new(history);
        let (particle, pairs, walls) = read_lists(&mut input)?;
        let stretched = |list: &ContactList, second_is_sphere: bool| {
            list.springs()
                .map(|(a, b, spring)| SavedSpring {
                    first: particle[a as usize],
                    second: match second_is_sphere {
                        true => particle[b as usize],
                        false => b,
                    },
                    spring,
                })
                .collect()
        };
        Ok(SavedSprings {
            pairs: stretched(&pairs, true),
            walls: stretched(&walls, false),
        })
    }

    /// Number of springs.
    pub fn len(&self) -> usize {
        self.pairs.len() + self.walls.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The spheres' particles and the pair and wall lists at the start of a contact model's
/// `history`.
fn read_lists(
    input: &mut Decoder<'_>,
) -> Result<(Vec<u32>, ContactList, ContactList), CheckpointError> {
    input.tag("contact")?;
    let particle = input.u32s("contact sphere particles")?;
    input.option_f64("the last evaluation time")?;
    input.bool("the build flag")?;
    input.f64("the build time")?;
    input.vec3s("the build positions")?;
    input.u64("the rebuild count")?;
    let spheres = particle.len();
    let pairs = ContactList::restore(input, spheres, spheres)?;
    let walls = ContactList::restore(input, spheres, u32::MAX as usize)?;
    Ok((particle, pairs, walls))
}

/// A wall as a checkpoint keeps it: its shape, its place at t = 0 of that run and its
/// velocity (a servo wall's as its servo last set it), so that at the checkpoint's time T it
/// stood at `base` + `velocity` T.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SavedWall {
    /// A plane (else a mesh).
    pub plane: bool,
    /// A plane's point, a mesh's offset from its file's coordinates, at t = 0 (m).
    pub base: Vec3,
    /// Its velocity (m/s).
    pub velocity: Vec3,
}

impl SavedWall {
    /// The walls of the `history` a [`DemContacts`] wrote into a checkpoint, in scene order.
    ///
    /// # Errors
    /// [`CheckpointError`] when the history is not a contact model's.
    pub fn read(history: &[u8]) -> Result<Vec<SavedWall>, CheckpointError> {
        let mut input = Decoder::new(history);
        read_lists(&mut input)?;
        SavedWall::read_all(&mut input)
    }

    /// What [`Walls::save`] wrote.
    pub(super) fn read_all(input: &mut Decoder<'_>) -> Result<Vec<SavedWall>, CheckpointError> {
        let count = input.u64("the wall count")?;
        (0..count)
            .map(|_| {
                Ok(SavedWall {
                    plane: input.bool("a wall's shape")?,
                    base: input.vec3("a wall's place")?,
                    velocity: input.vec3("a wall's velocity")?,
                })
            })
            .collect()
    }
}

/// How many saved springs [`DemContacts::carry_springs`] carried, and how many it dropped
/// because this model has no sphere on one of their particles, or not their wall.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CarriedSprings {
    /// Put on the same spheres (and walls) here.
    pub carried: usize,
    /// Not matched.
    pub dropped: usize,
}

impl DemContacts {
    /// Starts this model's contacts with the `saved` springs of the same spheres, before its
    /// first evaluation: `particle_of` maps a particle of the saved scene to this scene's
    /// (`None`: it has none); walls keep their index. A pair whose spheres come in the other
    /// order here keeps its spring as it acts on the new first sphere, −ξ. The lists are
    /// rebuilt at the first evaluation, which keeps the springs of the candidates (a spring
    /// whose spheres are out of reach there was released anyway). With the time of the last
    /// evaluation unknown, that first evaluation leaves the springs as they are (no time has
    /// passed), so the new stage continues the old one's springs where they stood.
    pub fn carry_springs(
        &mut self,
        saved: &SavedSprings,
        particle_of: impl Fn(u32) -> Option<usize>,
    ) -> CarriedSprings {
        let sphere_of: HashMap<usize, u32> = (self.spheres.particle().iter().enumerate())
            .map(|(s, &p)| (p as usize, s as u32))
            .collect();
        let sphere = |p: u32| particle_of(p).and_then(|p| sphere_of.get(&p).copied());
        let mut pairs: Vec<(u32, u32, Vec3)> = (saved.pairs.iter())
            .filter_map(|c| match (sphere(c.first), sphere(c.second)) {
                (Some(a), Some(b)) if a < b => Some((a, b, c.spring)),
                (Some(a), Some(b)) if a > b => Some((b, a, -c.spring)),
                _ => None,
            })
            .collect();
        let walls = self.walls.len() as u32;
        let mut wall_contacts: Vec<(u32, u32, Vec3)> = (saved.walls.iter())
            .filter(|c| c.second < walls)
            .filter_map(|c| sphere(c.first).map(|a| (a, c.second, c.spring)))
            .collect();
        for list in [&mut pairs, &mut wall_contacts] {
            list.sort_by_key(|c| (c.0, c.1));
            list.dedup_by_key(|c| (c.0, c.1));
        }
        let carried = pairs.len() + wall_contacts.len();
        let lists = (
            ContactList::with_springs(pairs),
            ContactList::with_springs(wall_contacts),
        );
        self.candidates.set_lists(lists.0, lists.1);
        self.candidates.invalidate();
        self.index_partners();
        CarriedSprings {
            carried,
            dropped: saved.len() - carried,
        }
    }
}

impl DemContacts {
    /// Starts wall `wall` where the checkpoint's wall `saved` stood at the checkpoint's time
    /// `time`: a plane through its point there, a mesh at its offset there, a servo wall with
    /// its velocity there (its displacement counted from there); a wall without a servo moves
    /// on with its own velocity. False, and nothing changed, when `saved` has the other shape.
    pub fn carry_wall(&mut self, wall: usize, saved: &SavedWall, time: f64) -> bool {
        self.walls.carry(wall, saved, time)
    }
}

impl Persistent for DemContacts {
    /// The spheres' particles (their identities for [`SavedSprings`]), the candidate lists
    /// with their tangential springs by the spheres' stable ids (`spatial_order.rs`), where
    /// and when they were built, every wall's place and velocity, the time-delayed boundary's
    /// estimates and the rolling springs: everything but the sphere centres, which are read
    /// from the state.
    fn save(&self, out: &mut Encoder) {
        out.tag("contact");
        out.u32s(&self.stable_particles());
        out.option_f64(self.evaluation.last_time());
        self.candidates
            .save(out, &self.order, |k| self.image_as_written(k));
        self.walls.save(out);
        out.bool(self.time_delay.is_some());
        if let Some(delay) = &self.time_delay {
            delay.save(out);
        }
        self.save_rolling(out);
    }
    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        input.tag("contact")?;
        let spheres = self.spheres.len();
        // The checkpoint names the spheres by their stable ids: read in that numbering, then
        // renumbered in the order of the saved build (`spatial_order.rs`), which is the
        // order the saving run had.
        self.reorder((0..spheres as u32).collect());
        let particle = input.u32s("contact sphere particles")?;
        if particle != self.spheres.particle() {
            return Err(CheckpointError::Invalid {
                what: "contact spheres",
                detail: format!(
                    "the checkpoint's {} spheres sit on other particles than the scene's {}",
                    particle.len(),
                    spheres
                ),
            });
        }
        let last_time = input.option_f64("the last evaluation time")?;
        self.evaluation.set_last_time(last_time);
        self.candidates.restore(input, spheres, self.walls.len())?;
        self.walls.restore(input)?;
        let delayed = input.bool("the time-delay flag")?;
        same_count(
            "time-delayed boundaries",
            self.time_delay.is_some() as usize,
            delayed as usize,
        )?;
        if let Some(delay) = &mut self.time_delay {
            delay.restore(input)?;
        }
        // The rolling springs are in the saved lists' order: read before the lists are
        // sorted, so that they move with their records.
        self.restore_rolling(input)?;
        self.candidates.sort_lists(spheres);
        if self.lists_built() {
            let built_at = self.candidates.built_at().to_vec();
            self.sort_spheres_at(&built_at);
        }
        self.index_partners();
        if let Some(split) = &mut self.split {
            split.whole = true;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LinearSpring, PlaneWall, Servo, WallShape};

    /// Two spheres of bodies 0 and 1 overlapping by 1 mm, the second also 0.5 mm into a floor,
    /// listed in `order`, with `walls` floors.
    fn model(state: &State, order: [usize; 2], walls: usize) -> DemContacts {
        let spheres: Vec<ContactSphere> = order
            .iter()
            .map(|&i| ContactSphere {
                particle: i,
                radius: 0.01,
                body: i,
                material: 0,
            })
            .collect();
        let floor = || Wall {
            shape: WallShape::Plane(PlaneWall::new(Vec3::zeros(), Vec3::z(), Vec3::zeros())),
            friction: 0.5,
        };
        let law = ContactLaw::Linear(LinearSpring {
            normal_stiffness: 1e5,
            tangential_stiffness: 1e5,
            damping_ratio: 0.0,
        });
        let settings = ContactSettings {
            law,
            friction: 0.5,
            skin: 0.001,
        };
        let names = order.iter().map(|i| format!("body {i}")).collect();
        let walls = (0..walls).map(|_| floor()).collect();
        DemContacts::new(state, &spheres, names, &[(1e9, 0.25)], settings, walls)
    }

    fn forces(model: &mut DemContacts, state: &State) -> Vec<Vec3> {
        let mut force = vec![Vec3::zeros(); 2];
        model.add_forces(state, &mut force, &mut []);
        force
    }

    #[test]
    fn a_wall_starts_where_the_checkpoint_left_it_and_a_servo_with_its_speed() {
        let state = State::at_rest(vec![
            Vec3::new(0.0, 0.0, 0.0285),
            Vec3::new(0.0, 0.0, 0.0095),
        ]);
        // The checkpoint's floor moved down at 1 m/s for 2 ms: 2 mm below its point.
        let mut before = model(&state, [0, 1], 1);
        let moving = PlaneWall::new(Vec3::zeros(), Vec3::z(), Vec3::new(0.0, 0.0, -1.0));
        before.walls = Walls::new(
            vec![Wall {
                shape: WallShape::Plane(moving),
                friction: 0.5,
            }],
            &[(1e9, 0.25)],
        );
        let mut out = Encoder::new();
        before.save(&mut out);
        let saved = SavedWall::read(out.bytes()).unwrap();
        assert_eq!(saved.len(), 1);
        // A servo floor here: through the point it had reached, with its speed.
        let mut servo = model(&state, [0, 1], 1);
        let target = Servo {
            stress: 1e3,
            factor: qdem_core::loads::TimeFunction::constant(1.0),
            area: 1e-4,
            gain: None,
            max_velocity: 1.0,
        };
        servo.set_servo(0, target).unwrap();
        assert!(servo.carry_wall(0, &saved[0], 2e-3));
        let WallShape::Plane(plane) = &servo.walls.get(0).shape else {
            unreachable!()
        };
        assert_eq!(plane.point, Vec3::new(0.0, 0.0, -2e-3));
        assert_eq!(plane.velocity, Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(servo.walls.displacement(0, 0.0), Vec3::zeros());
        // A plain floor here: at the point, with its own (zero) velocity.
        let mut plain = model(&state, [0, 1], 1);
        assert!(plain.carry_wall(0, &saved[0], 2e-3));
        assert_eq!(plain.walls.get(0).velocity(), Vec3::zeros());
        // The sphere 0.5 mm into the floor at z = 0 is 1.5 mm clear of it at z = −2 mm: the
        // forces are the pair's alone.
        let pair_alone = forces(&mut model(&state, [0, 1], 0), &state);
        assert_eq!(forces(&mut plain, &state), pair_alone);
        // A mesh wall cannot start where a plane stood.
        let saved_mesh = SavedWall {
            plane: false,
            ..saved[0]
        };
        assert!(!plain.carry_wall(0, &saved_mesh, 2e-3));
    }

    #[test]
    fn springs_go_to_the_same_spheres_in_any_order_and_a_missing_wall_drops_its_own() {
        let mut state = State::at_rest(vec![
            Vec3::new(0.0, 0.0, 0.0285),
            Vec3::new(0.0, 0.0, 0.0095),
        ]);
        state.mass = vec![0.01, 0.01];
        let mut saved = model(&state, [0, 1], 1);
        forces(&mut saved, &state);
        // The lower sphere slides 2 µm along x (a stick well below μ f_n on both contacts).
        state.time = 1e-3;
        state.position[1].x = 2e-6;
        state.velocity[1].x = 2e-3;
        let before = forces(&mut saved, &state);
        assert!(before[1].x.abs() > 0.1, "stretched springs: {before:?}");
        let mut out = Encoder::new();
        saved.save(&mut out);
        let springs = SavedSprings::read(out.bytes()).unwrap();
        assert_eq!((springs.pairs.len(), springs.walls.len()), (1, 1));
        // The spheres listed the other way round: the pair's spring acts on the new first
        // sphere (the old second), −ξ; the same forces on the particles, no time elapsed.
        let mut carried = model(&state, [1, 0], 1);
        let count = carried.carry_springs(&springs, |p| Some(p as usize));
        assert_eq!(
            count,
            CarriedSprings {
                carried: 2,
                dropped: 0
            }
        );
        let after = forces(&mut carried, &state);
        for (b, a) in before.iter().zip(&after) {
            assert!((b - a).norm() < 1e-15, "{b:?} vs {a:?}");
        }
        let mut no_floor = model(&state, [0, 1], 0);
        let count = no_floor.carry_springs(&springs, |p| Some(p as usize));
        assert_eq!(
            count,
            CarriedSprings {
                carried: 1,
                dropped: 1
            }
        );
        let mut no_sphere = model(&state, [0, 1], 1);
        let count = no_sphere.carry_springs(&springs, |p| (p == 0).then_some(0));
        assert_eq!(
            count,
            CarriedSprings {
                carried: 0,
                dropped: 2
            }
        );
    }
}
