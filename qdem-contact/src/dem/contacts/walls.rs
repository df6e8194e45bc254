//! The walls of the contact model as a part of their own: the walls, the elastic constants
//! of a sphere's material against a wall, the narrow phase of a sphere against a wall, and
//! the stress-controlled walls' servos (`servo_loads.rs`), which the stages drive from the
//! evaluation's reduction.

use super::persistence::SavedWall;
use super::servo_loads::{ServoContact, Servos};
use super::{ContactLaw, ContactList, PairElasticity, PairGeometry, SphereNow};
use crate::dem::walls::servo_wall::Servo;
use crate::dem::walls::wall::{Wall, WallShape};
use crate::error::ContactError;
use qdem_core::checkpoint::{same_count, CheckpointError, Decoder, Encoder};
use qdem_core::Vec3;

/// The walls, their elasticity per sphere material, and their servos.
pub(super) struct Walls {
    list: Vec<Wall>,
    /// Per sphere material, its elastic constants against a wall.
    elasticity: Vec<PairElasticity>,
    servos: Servos,
}

impl Walls {
    /// The walls `list`, touched by spheres of the materials (E, ν) `materials`; no servo.
    pub(super) fn new(list: Vec<Wall>, materials: &[(f64, f64)]) -> Walls {
        let elasticity = materials
            .iter()
            .map(|a| PairElasticity::new(*a, None))
            .collect();
        Walls {
            list,
            elasticity,
            servos: Servos::default(),
        }
    }

    /// Number of walls.
    #[inline]
    pub(super) fn len(&self) -> usize {
        self.list.len()
    }

    /// The walls.
    #[inline]
    pub(super) fn list(&self) -> &[Wall] {
        &self.list
    }

    /// Wall `w`.
    #[inline]
    pub(super) fn get(&self, w: usize) -> &Wall {
        &self.list[w]
    }

    /// The elastic constants of material `material` against a wall.
    #[inline]
    pub(super) fn elasticity(&self, material: u32) -> PairElasticity {
        self.elasticity[material as usize]
    }

    /// The geometry and elasticity of the contact of `sphere` with wall w: the contact point
    /// at x + (r − δ/2) n, its velocity v + (r − δ/2) ω × n against the wall's; `None` when
    /// apart.
    #[inline(always)]
    pub(super) fn contact(
        &self,
        time: f64,
        sphere: &SphereNow,
        w: usize,
    ) -> Option<(PairGeometry, PairElasticity)> {
        let wall = &self.list[w];
        let (overlap, normal) = wall.overlap(&sphere.center, sphere.radius, time);
        if overlap <= 0.0 || normal == Vec3::zeros() {
            return None;
        }
        let lever = sphere.radius - 0.5 * overlap;
        let geometry = PairGeometry {
            overlap,
            normal,
            velocity: sphere.velocity + lever * sphere.spin.cross(&normal) - wall.velocity(),
            radius: sphere.radius,
            mass: sphere.mass,
            friction: wall.friction,
        };
        Some((geometry, self.elasticity[sphere.material as usize]))
    }

    /// Makes plane wall `wall` stress-controlled by `servo`, from now on; refused for a mesh
    /// wall or a wall out of range.
    pub(super) fn set_servo(&mut self, wall: usize, servo: Servo) -> Result<(), ContactError> {
        self.servos.set(&self.list, wall, servo)
    }

    /// Whether some wall is stress-controlled.
    #[inline]
    pub(super) fn has_servo(&self) -> bool {
        self.servos.any()
    }

    /// The displacement (m) of wall `wall` at `time` from its place at t = 0.
    pub(super) fn displacement(&self, wall: usize, time: f64) -> Vec3 {
        self.servos.displacement(&self.list, wall, time)
    }

    /// The largest distance a wall may have moved in `elapsed` (s) (for a servo wall, at its
    /// greatest speed), for the neighbour lists' skin check.
    pub(super) fn moved_bound(&self, elapsed: f64) -> f64 {
        (0..self.list.len())
            .map(|w| self.servos.speed_bound(&self.list, w) * elapsed)
            .fold(0.0, f64::max)
    }

    /// The touching contacts of `wall_contacts` on servo walls in list order (by sphere,
    /// then wall): sphere, wall, the compressive normal force (N) the sphere (of radius
    /// `radius[s]`, read in `now[s]`) puts on the wall of inward normal n, f · n, and the two
    /// terms of the contact's response k_n `dt` + c_n (N·s/m) under `law`, k_n `dt` and
    /// c_n = 2ζ√(k_n m).
    pub(super) fn servo_contacts<'a>(
        &'a self,
        wall_contacts: &'a ContactList,
        (now, radius): (&'a [SphereNow], &'a [f64]),
        law: &'a ContactLaw,
        dt: f64,
    ) -> impl Iterator<Item = ServoContact> + 'a {
        let zeta = law.damping_ratio();
        wall_contacts.items.iter().filter_map(move |c| {
            let normal = self.servos.normal(&self.list, c.second as usize)?;
            if c.force == Vec3::zeros() {
                return None;
            }
            let s = c.first as usize;
            let sphere = &now[s];
            let e = &self.elasticity[sphere.material as usize];
            let (kn, _) = law.stiffness(2.0 * c.half_overlap, radius[s], e);
            let damper = 2.0 * zeta * (kn * sphere.mass).sqrt();
            Some(ServoContact {
                sphere: c.first,
                wall: c.second,
                load: c.force.dot(&normal),
                response: (kn * dt, damper),
            })
        })
    }

    /// Sets each servo wall's velocity from the summed `contacts` of every rank, keeping
    /// its plane where it is at `time` (`servo_loads.rs`).
    pub(super) fn drive_servos(&mut self, time: f64, contacts: &[ServoContact]) {
        self.servos.drive(&mut self.list, time, contacts);
    }

    /// Saves every wall's shape (plane or not), its place at t = 0 (a plane's point, a mesh's
    /// offset) and its velocity, in wall order: with a servo's, the whole state of a wall.
    pub(super) fn save(&self, out: &mut Encoder) {
        out.u64(self.list.len() as u64);
        for wall in &self.list {
            let (plane, base) = match &wall.shape {
                WallShape::Plane(p) => (true, p.point),
                WallShape::Mesh(m) => (false, m.offset),
            };
            out.bool(plane);
            out.vec3(&base);
            out.vec3(&wall.velocity());
        }
    }

    /// Restores what [`Walls::save`] saved (the same scene's walls).
    pub(super) fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        let saved = SavedWall::read_all(input)?;
        same_count("walls", self.list.len(), saved.len())?;
        for (wall, saved) in self.list.iter_mut().zip(saved) {
            match &mut wall.shape {
                WallShape::Plane(p) if saved.plane => {
                    (p.point, p.velocity) = (saved.base, saved.velocity);
                }
                WallShape::Mesh(m) if !saved.plane => {
                    (m.offset, m.velocity) = (saved.base, saved.velocity);
                }
                _ => {
                    return Err(CheckpointError::Invalid {
                        what: "walls",
                        detail: "a wall is a plane in the checkpoint and a mesh in the scene, \
                                 or the other way round"
                            .into(),
                    })
                }
            }
        }
        Ok(())
    }

    /// Starts wall `wall` where `saved` was at `time` (a plane through the same point, a mesh
    /// with the same offset), a servo wall with its velocity; false (and nothing done) when
    /// the saved wall has another shape.
    pub(super) fn carry(&mut self, wall: usize, saved: &SavedWall, time: f64) -> bool {
        let at = saved.base + saved.velocity * time;
        match &mut self.list[wall].shape {
            WallShape::Plane(_) if saved.plane => {
                self.servos.carry(&mut self.list, wall, at, saved.velocity);
                true
            }
            WallShape::Mesh(m) if !saved.plane => {
                m.offset = at;
                true
            }
            _ => false,
        }
    }
}
