//! The servo of stress-controlled plane walls (`servo_wall.rs`) inside the contact model:
//! after each evaluation's law, each servo wall's stress from its touching contacts, summed
//! in the order of one process's list (by sphere) over every rank through the evaluation's
//! reduction (`stages.rs`), sets its velocity; its plane is re-based so that its position
//! stays continuous. Its place and velocity are saved with the contact lists.

use super::*;
use crate::servo_wall::Servo;
use crate::wall::WallShape;

/// A touching contact on a servo wall, what its load and response take of it.
#[derive(Clone, Copy, Debug)]
pub(super) struct ServoContact {
    /// The sphere.
    pub(super) sphere: u32,
    /// The wall.
    pub(super) wall: u32,
    /// f · n (N), n the wall's inward normal.
    pub(super) load: f64,
    /// k_n dt (N·s/m) and c_n = 2ζ√(k_n m) (N·s/m).
    pub(super) response: (f64, f64),
}

/// A servo wall's settings and its plane's point at t = 0.
#[derive(Clone, Copy, Debug)]
pub(super) struct ServoWall {
    servo: Servo,
    start: Vec3,
}

impl DemContacts {
    /// Makes plane wall `wall` stress-controlled by `servo`, from now on; refused for a mesh
    /// wall or a wall out of range.
    pub fn set_servo(&mut self, wall: usize, servo: Servo) -> Result<(), ContactError> {
        let Some(WallShape::Plane(plane)) = self.walls.get(wall).map(|w| &w.shape) else {
            return Err(ContactError::ServoNotPlane { wall: wall + 1 });
        };
        let start = plane.point;
        self.servos.resize(self.walls.len(), None);
        self.servos[wall] = Some(ServoWall { servo, start });
        Ok(())
    }

    /// Whether some wall is stress-controlled.
    pub fn has_servo(&self) -> bool {
        self.servos.iter().any(Option::is_some)
    }

    /// The displacement (m) of wall `wall` at `time` from its place at t = 0.
    pub fn wall_displacement(&self, wall: usize, time: f64) -> Vec3 {
        match (&self.walls[wall].shape, self.servo_of(wall)) {
            (WallShape::Plane(p), Some(s)) => p.point + p.velocity * time - s.start,
            (shape, _) => {
                let velocity = match shape {
                    WallShape::Plane(p) => p.velocity,
                    WallShape::Mesh(m) => m.velocity,
                };
                velocity * time
            }
        }
    }

    /// The bound on wall `wall`'s speed (m/s) the neighbour lists' skin check uses: v_max for
    /// a servo wall, its constant speed otherwise.
    pub(super) fn wall_speed_bound(&self, wall: usize) -> f64 {
        match self.servo_of(wall) {
            Some(s) => s.servo.max_velocity,
            None => self.walls[wall].velocity().norm(),
        }
    }

    fn servo_of(&self, wall: usize) -> Option<&ServoWall> {
        self.servos.get(wall).and_then(Option::as_ref)
    }

    /// The touching contacts on servo walls in list order (by sphere, then wall): sphere,
    /// wall, the compressive normal force (N) the sphere puts on the wall of inward normal n,
    /// f · n, and the two terms of the contact's response k_n `dt` + c_n (N·s/m), k_n `dt`
    /// and c_n = 2ζ√(k_n m).
    pub(super) fn servo_contacts(&self, dt: f64) -> impl Iterator<Item = ServoContact> + '_ {
        let law = &self.settings.law;
        let zeta = law.damping_ratio();
        self.wall_contacts.items.iter().filter_map(move |c| {
            let w = c.second as usize;
            let (Some(_), WallShape::Plane(plane)) = (self.servo_of(w), &self.walls[w].shape)
            else {
                return None;
            };
            if c.force == Vec3::zeros() {
                return None;
            }
            let s = c.first as usize;
            let sphere = &self.now[s];
            let e = &self.wall_elasticity[sphere.material as usize];
            let (kn, _) = law.stiffness(2.0 * c.half_overlap, self.radius[s], e);
            let damper = 2.0 * zeta * (kn * sphere.mass).sqrt();
            Some(ServoContact {
                sphere: c.first,
                wall: c.second,
                load: c.force.dot(&plane.normal),
                response: (kn * dt, damper),
            })
        })
    }

    /// Sets each servo wall's velocity from its load, the sums over `contacts` (every
    /// touching contact on a servo wall, as [`DemContacts::servo_contacts`] gives them, in
    /// the order of one process's list) of the normal forces and of the responses, keeping
    /// its plane where it is at `time`.
    pub(super) fn drive_servos(&mut self, time: f64, contacts: &[ServoContact]) {
        for w in 0..self.servos.len() {
            let Some(servo) = self.servos[w].map(|s| s.servo) else {
                continue;
            };
            let (mut force, mut response) = (0.0, 0.0);
            for c in contacts.iter().filter(|c| c.wall as usize == w) {
                (force, response) = (force + c.load, response + c.response.0 + c.response.1);
            }
            let speed = servo.speed(force / servo.area, response);
            let WallShape::Plane(plane) = &mut self.walls[w].shape else {
                continue;
            };
            let velocity = speed * plane.normal;
            plane.point += (plane.velocity - velocity) * time;
            plane.velocity = velocity;
        }
    }

    /// Saves each servo wall's plane (point and velocity), in wall order.
    pub(super) fn save_servos(&self, out: &mut Encoder) {
        for (w, wall) in self.walls.iter().enumerate() {
            if let (Some(_), WallShape::Plane(p)) = (self.servo_of(w), &wall.shape) {
                out.vec3(&p.point);
                out.vec3(&p.velocity);
            }
        }
    }

    /// Restores what [`DemContacts::save_servos`] saved.
    pub(super) fn restore_servos(
        &mut self,
        input: &mut Decoder<'_>,
    ) -> Result<(), CheckpointError> {
        for w in 0..self.walls.len() {
            if self.servo_of(w).is_none() {
                continue;
            }
            let point = input.vec3("a servo wall's point")?;
            let velocity = input.vec3("a servo wall's velocity")?;
            if let WallShape::Plane(p) = &mut self.walls[w].shape {
                (p.point, p.velocity) = (point, velocity);
            }
        }
        Ok(())
    }
}
