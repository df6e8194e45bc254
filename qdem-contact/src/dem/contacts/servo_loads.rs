//! The servo of stress-controlled plane walls (`servo_wall.rs`) inside the contact model, a
//! hook of the walls' part (`walls.rs`), not a branch of the force pass: after each
//! evaluation's law, each servo wall's stress from its touching contacts, summed in the order
//! of one process's list (by sphere) over every rank through the evaluation's reduction
//! (`stages.rs`), sets its velocity; its plane is re-based so that its position stays
//! continuous. Its place and velocity are saved with every wall's (`walls.rs`); a stage that
//! starts from a checkpoint may put it where it was there, with the velocity it had
//! ([`Servos::carry`]).

use crate::dem::walls::servo_wall::Servo;
use crate::dem::walls::wall::{Wall, WallShape};
use crate::error::ContactError;
use qdem_core::Vec3;

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
#[derive(Clone, Debug)]
struct ServoWall {
    servo: Servo,
    start: Vec3,
}

/// The servos of the walls, by wall; empty when none.
#[derive(Default)]
pub(super) struct Servos {
    by_wall: Vec<Option<ServoWall>>,
}

impl Servos {
    /// Makes plane wall `wall` of `walls` stress-controlled by `servo`, from now on; refused
    /// for a mesh wall or a wall out of range.
    pub(super) fn set(
        &mut self,
        walls: &[Wall],
        wall: usize,
        servo: Servo,
    ) -> Result<(), ContactError> {
        let Some(WallShape::Plane(plane)) = walls.get(wall).map(|w| &w.shape) else {
            return Err(ContactError::ServoNotPlane { wall: wall + 1 });
        };
        let start = plane.point;
        self.by_wall.resize(walls.len(), None);
        self.by_wall[wall] = Some(ServoWall { servo, start });
        Ok(())
    }

    /// Whether some wall is stress-controlled.
    pub(super) fn any(&self) -> bool {
        self.by_wall.iter().any(Option::is_some)
    }

    fn of(&self, wall: usize) -> Option<&ServoWall> {
        self.by_wall.get(wall).and_then(Option::as_ref)
    }

    /// The displacement (m) of wall `wall` (of `walls`) at `time` from its place at t = 0.
    pub(super) fn displacement(&self, walls: &[Wall], wall: usize, time: f64) -> Vec3 {
        match (&walls[wall].shape, self.of(wall)) {
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
    pub(super) fn speed_bound(&self, walls: &[Wall], wall: usize) -> f64 {
        match self.of(wall) {
            Some(s) => s.servo.max_velocity,
            None => walls[wall].velocity().norm(),
        }
    }

    /// The inward normal of wall `wall` (of `walls`) when it is a servo wall.
    pub(super) fn normal(&self, walls: &[Wall], wall: usize) -> Option<Vec3> {
        match (self.of(wall), &walls[wall].shape) {
            (Some(_), WallShape::Plane(plane)) => Some(plane.normal),
            _ => None,
        }
    }

    /// Sets each servo wall's velocity from its load, the sums over `contacts` (every
    /// touching contact on a servo wall, in the order of one process's list) of the normal
    /// forces and of the responses, keeping its plane where it is at `time`.
    pub(super) fn drive(&self, walls: &mut [Wall], time: f64, contacts: &[ServoContact]) {
        for (w, (entry, wall)) in self.by_wall.iter().zip(walls.iter_mut()).enumerate() {
            let Some(ServoWall { servo, .. }) = entry else {
                continue;
            };
            let (mut force, mut response) = (0.0, 0.0);
            for c in contacts.iter().filter(|c| c.wall as usize == w) {
                (force, response) = (force + c.load, response + c.response.0 + c.response.1);
            }
            let speed = servo.speed(time, force / servo.area, response);
            let WallShape::Plane(plane) = &mut wall.shape else {
                continue;
            };
            let velocity = speed * plane.normal;
            plane.point += (plane.velocity - velocity) * time;
            plane.velocity = velocity;
        }
    }

    /// Starts wall `wall` (a plane, of `walls`) through `point` at t = 0; a servo wall also
    /// with `velocity`, the speed its servo had set (the next evaluation sets it anew), and its
    /// displacement counted from there.
    pub(super) fn carry(&mut self, walls: &mut [Wall], wall: usize, point: Vec3, velocity: Vec3) {
        let servo = self.by_wall.get_mut(wall).and_then(Option::as_mut);
        if let WallShape::Plane(plane) = &mut walls[wall].shape {
            plane.point = point;
            if let Some(servo) = servo {
                plane.velocity = velocity;
                servo.start = point;
            }
        }
    }
}
