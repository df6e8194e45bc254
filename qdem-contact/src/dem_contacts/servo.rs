//! The servo of stress-controlled plane walls (`servo_wall.rs`) inside the contact model:
//! after each evaluation, each servo wall's stress from its touching contacts, summed in list
//! order (by sphere), sets its velocity; its plane is re-based so that its position stays
//! continuous. Its place and velocity are saved with the contact lists.

use super::*;
use crate::servo_wall::Servo;
use crate::wall::WallShape;

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

    /// Sets each servo wall's velocity from this evaluation's contact forces (`dt` since the
    /// last evaluation), keeping its plane where it is at `time`.
    pub(super) fn drive_servos(&mut self, time: f64, dt: f64) {
        for w in 0..self.servos.len() {
            let Some(servo) = self.servos[w].map(|s| s.servo) else {
                continue;
            };
            let WallShape::Plane(plane) = &self.walls[w].shape else {
                continue;
            };
            let (force, response) = self.wall_load(w, &plane.normal, dt);
            let speed = servo.speed(force / servo.area, response);
            let WallShape::Plane(plane) = &mut self.walls[w].shape else {
                continue;
            };
            let velocity = speed * plane.normal;
            plane.point += (plane.velocity - velocity) * time;
            plane.velocity = velocity;
        }
    }

    /// The compressive normal force (N) the spheres put on wall `wall` of inward normal
    /// `normal`, and the response Σ (k_n `dt` + c_n) (N·s/m) of its touching contacts, c_n =
    /// 2ζ√(k_n m), in list order.
    fn wall_load(&self, wall: usize, normal: &Vec3, dt: f64) -> (f64, f64) {
        let law = &self.settings.law;
        let zeta = law.damping_ratio();
        let mut load = (0.0, 0.0);
        for c in &self.wall_contacts.items {
            if c.second as usize != wall || c.force == Vec3::zeros() {
                continue;
            }
            let s = c.first as usize;
            let sphere = &self.now[s];
            let e = &self.wall_elasticity[sphere.material as usize];
            let (kn, _) = law.stiffness(2.0 * c.half_overlap, self.radius[s], e);
            let damper = 2.0 * zeta * (kn * sphere.mass).sqrt();
            load = (load.0 + c.force.dot(normal), load.1 + kn * dt + damper);
        }
        load
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
