//! The binary encoding of checkpoints: a run's state and every model's history, so that a
//! resumed run continues bit for bit.
//!
//! Values are little-endian (`f64` by its bit pattern, so nothing is rounded); a slice is its
//! length and then its elements; every part starts with a named tag, so a checkpoint read
//! against a different scene fails at the first part that does not fit, naming it, rather
//! than giving a silently wrong run. [`State`] is encoded here; models and steppers encode
//! their own history through [`crate::step::Persistent::save`] and [`crate::step::Stepper::save`]. The file
//! around it (header, version, scene fingerprint) belongs to the caller.

use crate::step::rigid_body::RigidBodies;
use crate::step::state::{ParticleSpin, State};
use crate::Vec3;
use nalgebra::{Quaternion, UnitQuaternion};
use thiserror::Error;

/// Why a checkpoint could not be read back.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum CheckpointError {
    /// The bytes end before the value being read.
    #[error(
        "the checkpoint ends early (byte {at}, reading {what}): the file is truncated or not \
         a qdem checkpoint"
    )]
    Truncated {
        /// Byte offset of the value.
        at: usize,
        /// What was being read.
        what: &'static str,
    },
    /// A part other than the expected one.
    #[error(
        "the checkpoint has part `{found}` where `{expected}` belongs: it was written for a \
         different scene (or by a different version of the scene's models)"
    )]
    Part {
        /// The tag the reader expected.
        expected: String,
        /// The tag found.
        found: String,
    },
    /// A count that does not match the scene.
    #[error(
        "the checkpoint has {found} {what} where the scene has {expected}: it was written for a \
         different scene"
    )]
    Count {
        /// What is counted.
        what: &'static str,
        /// The scene's count.
        expected: usize,
        /// The checkpoint's count.
        found: usize,
    },
    /// A value that cannot be what the scene needs (an index out of range, a bad flag).
    #[error("the checkpoint's {what} is invalid: {detail}")]
    Invalid {
        /// Which value.
        what: &'static str,
        /// Why.
        detail: String,
    },
    /// A model or stepper without a checkpoint of its history.
    #[error(
        "{what} cannot be checkpointed yet (its history is not saved), so this scene cannot \
         be checkpointed or resumed: remove `checkpoint_every` and run it without --resume"
    )]
    Unsupported {
        /// The model or stepper.
        what: String,
    },
}

/// Writes values into a checkpoint buffer.
#[derive(Debug, Default)]
pub struct Encoder {
    bytes: Vec<u8>,
}

impl Encoder {
    /// An empty buffer.
    pub fn new() -> Encoder {
        Encoder::default()
    }

    /// The encoded bytes.
    pub fn into_bytes(self) -> Vec<u8> {
        self.bytes
    }

    /// The encoded bytes so far.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// A part's name; [`Decoder::tag`] checks it.
    pub fn tag(&mut self, name: &str) {
        self.u64(name.len() as u64);
        self.bytes.extend_from_slice(name.as_bytes());
    }

    /// An unsigned integer.
    pub fn u64(&mut self, x: u64) {
        self.bytes.extend_from_slice(&x.to_le_bytes());
    }

    /// A float, by its bit pattern.
    pub fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }

    /// A flag.
    pub fn bool(&mut self, x: bool) {
        self.bytes.push(x as u8);
    }

    /// A float that may be absent.
    pub fn option_f64(&mut self, x: Option<f64>) {
        self.bool(x.is_some());
        self.f64(x.unwrap_or(0.0));
    }

    /// A vector.
    pub fn vec3(&mut self, v: &Vec3) {
        for c in v.iter() {
            self.f64(*c);
        }
    }

    /// A slice of floats.
    pub fn f64s(&mut self, xs: &[f64]) {
        self.u64(xs.len() as u64);
        xs.iter().for_each(|x| self.f64(*x));
    }

    /// A slice of vectors.
    pub fn vec3s(&mut self, xs: &[Vec3]) {
        self.u64(xs.len() as u64);
        xs.iter().for_each(|x| self.vec3(x));
    }

    /// A slice of indices.
    pub fn u32s(&mut self, xs: &[u32]) {
        self.u64(xs.len() as u64);
        for x in xs {
            self.bytes.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// A slice of flags.
    pub fn bools(&mut self, xs: &[bool]) {
        self.u64(xs.len() as u64);
        xs.iter().for_each(|x| self.bool(*x));
    }

    /// A string.
    pub fn str(&mut self, s: &str) {
        self.tag(s);
    }

    /// A block of bytes (another encoder's output), which a reader may take whole or skip.
    pub fn block(&mut self, bytes: &[u8]) {
        self.u64(bytes.len() as u64);
        self.bytes.extend_from_slice(bytes);
    }
}

/// Reads values back, in the order they were written.
#[derive(Debug)]
pub struct Decoder<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Decoder<'a> {
    /// A reader over `bytes`.
    pub fn new(bytes: &'a [u8]) -> Decoder<'a> {
        Decoder { bytes, at: 0 }
    }

    /// Whether every byte has been read.
    pub fn is_done(&self) -> bool {
        self.at == self.bytes.len()
    }

    fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], CheckpointError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or(CheckpointError::Truncated { at: self.at, what })?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }

    /// Checks that the next part is `name`.
    pub fn tag(&mut self, name: &str) -> Result<(), CheckpointError> {
        let found = self.str("a part name")?;
        if found == name {
            Ok(())
        } else {
            Err(CheckpointError::Part {
                expected: name.to_string(),
                found,
            })
        }
    }

    /// A string.
    pub fn str(&mut self, what: &'static str) -> Result<String, CheckpointError> {
        let n = self.len(1, what)?;
        let bytes = self.take(n, what)?;
        String::from_utf8(bytes.to_vec()).map_err(|_| CheckpointError::Invalid {
            what,
            detail: "not UTF-8".to_string(),
        })
    }

    /// A block of bytes written by [`Encoder::block`].
    pub fn block(&mut self, what: &'static str) -> Result<&'a [u8], CheckpointError> {
        let n = self.len(1, what)?;
        self.take(n, what)
    }

    /// An unsigned integer.
    pub fn u64(&mut self, what: &'static str) -> Result<u64, CheckpointError> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    /// A float.
    pub fn f64(&mut self, what: &'static str) -> Result<f64, CheckpointError> {
        self.u64(what).map(f64::from_bits)
    }

    /// A flag.
    pub fn bool(&mut self, what: &'static str) -> Result<bool, CheckpointError> {
        match self.take(1, what)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            other => Err(CheckpointError::Invalid {
                what,
                detail: format!("flag byte {other}"),
            }),
        }
    }

    /// A float that may be absent.
    pub fn option_f64(&mut self, what: &'static str) -> Result<Option<f64>, CheckpointError> {
        let present = self.bool(what)?;
        let x = self.f64(what)?;
        Ok(present.then_some(x))
    }

    /// A vector.
    pub fn vec3(&mut self, what: &'static str) -> Result<Vec3, CheckpointError> {
        Ok(Vec3::new(self.f64(what)?, self.f64(what)?, self.f64(what)?))
    }

    /// A length whose elements take `size` bytes each, refused if the rest of the buffer is
    /// too short for it (so a corrupt length never allocates).
    fn len(&mut self, size: usize, what: &'static str) -> Result<usize, CheckpointError> {
        let at = self.at;
        let n = self.u64(what)?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.checked_mul(size as u64).is_none_or(|bytes| bytes > left) {
            return Err(CheckpointError::Truncated { at, what });
        }
        Ok(n as usize)
    }

    /// A slice of floats.
    pub fn f64s(&mut self, what: &'static str) -> Result<Vec<f64>, CheckpointError> {
        let n = self.len(8, what)?;
        (0..n).map(|_| self.f64(what)).collect()
    }

    /// A slice of vectors.
    pub fn vec3s(&mut self, what: &'static str) -> Result<Vec<Vec3>, CheckpointError> {
        let n = self.len(24, what)?;
        (0..n).map(|_| self.vec3(what)).collect()
    }

    /// A slice of indices.
    pub fn u32s(&mut self, what: &'static str) -> Result<Vec<u32>, CheckpointError> {
        let n = self.len(4, what)?;
        let bytes = self.take(4 * n, what)?;
        Ok(bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }

    /// A slice of flags.
    pub fn bools(&mut self, what: &'static str) -> Result<Vec<bool>, CheckpointError> {
        let n = self.len(1, what)?;
        (0..n).map(|_| self.bool(what)).collect()
    }

    /// A slice of vectors of exactly `expected` elements.
    pub fn vec3s_exact(
        &mut self,
        expected: usize,
        what: &'static str,
    ) -> Result<Vec<Vec3>, CheckpointError> {
        let xs = self.vec3s(what)?;
        same_count(what, expected, xs.len())?;
        Ok(xs)
    }
}

/// Fails unless `found` equals `expected`.
pub fn same_count(
    what: &'static str,
    expected: usize,
    found: usize,
) -> Result<(), CheckpointError> {
    if expected == found {
        Ok(())
    } else {
        Err(CheckpointError::Count {
            what,
            expected,
            found,
        })
    }
}

/// The tag before a model's history in a checkpoint ([`crate::world::World::save`]).
pub(crate) fn model_tag(name: &str) -> String {
    format!("model {name}")
}

/// Fails unless model `name`'s restore read its whole history `block`.
pub(crate) fn whole_block(name: &str, block: &Decoder<'_>) -> Result<(), CheckpointError> {
    match block.bytes.len() - block.at {
        0 => Ok(()),
        left => Err(CheckpointError::Invalid {
            what: "model history",
            detail: format!("model `{name}` left {left} bytes of its history unread"),
        }),
    }
}

/// Each model's name and saved history (empty for a model without one), as
/// [`crate::world::World::save`] wrote them after the [`State`], up to the stepper's part: what a
/// scene that starts from another scene's checkpoint reads of its models (their contact
/// springs) without the models that wrote them.
pub fn model_histories<'a>(
    input: &mut Decoder<'a>,
) -> Result<Vec<(String, &'a [u8])>, CheckpointError> {
    let mut histories = Vec::new();
    loop {
        let tag = input.str("a part name")?;
        let Some(name) = tag.strip_prefix("model ") else {
            return Ok(histories);
        };
        histories.push((name.to_string(), input.block("a model's history")?));
    }
}

impl State {
    /// Writes what evolves during a run: time, positions (current and the reference, which a
    /// periodic cell shifts), velocities, accelerations, the rigid bodies' orientations and
    /// momenta and the particles' rotations. Masses, fixity and the rigid bodies' members come
    /// from the scene.
    pub fn save(&self, out: &mut Encoder) {
        out.tag("state");
        out.f64(self.time);
        for v in [
            &self.reference,
            &self.position,
            &self.velocity,
            &self.acceleration,
        ] {
            out.vec3s(v);
        }
        save_rigid(&self.rigid, out);
        save_spin(&self.spin, out);
    }

    /// Reads back what [`State::save`] wrote into a state built from the same scene.
    pub fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        input.tag("state")?;
        self.time = input.f64("time")?;
        let n = self.len();
        self.reference = input.vec3s_exact(n, "reference positions")?;
        self.position = input.vec3s_exact(n, "positions")?;
        self.velocity = input.vec3s_exact(n, "velocities")?;
        self.acceleration = input.vec3s_exact(n, "accelerations")?;
        restore_rigid(&mut self.rigid, input)?;
        restore_spin(&mut self.spin, input)
    }
}

/// What [`State::save`] wrote, read without a state to fit it into: a scene that starts from
/// another scene's checkpoint but integrates some bodies differently (rigid or deformable)
/// lays its particles out differently and maps them itself.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedState {
    /// Simulated time (s).
    pub time: f64,
    /// Reference positions, one per particle of the saved scene (m).
    pub reference: Vec<Vec3>,
    /// Positions (m).
    pub position: Vec<Vec3>,
    /// Velocities (m/s).
    pub velocity: Vec<Vec3>,
    /// Accelerations (m/s²).
    pub acceleration: Vec<Vec3>,
    /// Each rigid body's orientation.
    pub orientation: Vec<UnitQuaternion<f64>>,
    /// Each rigid body's angular momentum (kg m²/s).
    pub angular_momentum: Vec<Vec3>,
    /// Each rigid body's angular velocity (rad/s).
    pub angular_velocity: Vec<Vec3>,
    /// The particles' rotations: angle, rate, acceleration (each empty or one per particle).
    pub spin: [Vec<Vec3>; 3],
}

impl SavedState {
    /// Reads what [`State::save`] wrote, checking only that its arrays agree with each other.
    pub fn read(input: &mut Decoder<'_>) -> Result<SavedState, CheckpointError> {
        input.tag("state")?;
        let time = input.f64("time")?;
        let reference = input.vec3s("reference positions")?;
        let n = reference.len();
        let position = input.vec3s_exact(n, "positions")?;
        let velocity = input.vec3s_exact(n, "velocities")?;
        let acceleration = input.vec3s_exact(n, "accelerations")?;
        input.tag("rigid bodies")?;
        let bodies = input.u64("rigid bodies")? as usize;
        let orientation = (0..bodies)
            .map(|_| {
                let c = input.f64s("an orientation")?;
                same_count("quaternion components", 4, c.len())?;
                Ok(UnitQuaternion::new_unchecked(Quaternion::new(
                    c[3], c[0], c[1], c[2],
                )))
            })
            .collect::<Result<Vec<_>, CheckpointError>>()?;
        let angular_momentum = input.vec3s_exact(bodies, "angular momenta")?;
        let angular_velocity = input.vec3s_exact(bodies, "angular velocities")?;
        input.tag("particle rotations")?;
        let angle = input.vec3s("particle angles")?;
        let m = angle.len();
        let spin = [
            angle,
            input.vec3s_exact(m, "particle angular velocities")?,
            input.vec3s_exact(m, "particle angular accelerations")?,
        ];
        Ok(SavedState {
            time,
            reference,
            position,
            velocity,
            acceleration,
            orientation,
            angular_momentum,
            angular_velocity,
            spin,
        })
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.reference.len()
    }

    /// Whether the saved scene had no particle.
    pub fn is_empty(&self) -> bool {
        self.reference.is_empty()
    }
}

fn save_rigid(rigid: &RigidBodies, out: &mut Encoder) {
    out.tag("rigid bodies");
    out.u64(rigid.len() as u64);
    for q in &rigid.orientation {
        out.f64s(q.as_ref().coords.as_slice());
    }
    out.vec3s(&rigid.angular_momentum);
    out.vec3s(&rigid.angular_velocity);
}

fn restore_rigid(rigid: &mut RigidBodies, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
    input.tag("rigid bodies")?;
    let n = rigid.len();
    same_count("rigid bodies", n, input.u64("rigid bodies")? as usize)?;
    for q in rigid.orientation.iter_mut() {
        let c = input.f64s("an orientation")?;
        same_count("quaternion components", 4, c.len())?;
        *q = UnitQuaternion::new_unchecked(Quaternion::new(c[3], c[0], c[1], c[2]));
    }
    rigid.angular_momentum = input.vec3s_exact(n, "angular momenta")?;
    rigid.angular_velocity = input.vec3s_exact(n, "angular velocities")?;
    Ok(())
}

fn save_spin(spin: &ParticleSpin, out: &mut Encoder) {
    out.tag("particle rotations");
    out.vec3s(&spin.angle);
    out.vec3s(&spin.velocity);
    out.vec3s(&spin.acceleration);
}

fn restore_spin(spin: &mut ParticleSpin, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
    input.tag("particle rotations")?;
    let n = spin.len();
    spin.angle = input.vec3s_exact(n, "particle angles")?;
    spin.velocity = input.vec3s_exact(n, "particle angular velocities")?;
    spin.acceleration = input.vec3s_exact(n, "particle angular accelerations")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_round_trip_bit_for_bit() {
        let mut e = Encoder::new();
        e.tag("part");
        e.f64(-0.0);
        e.f64(f64::NAN);
        e.option_f64(None);
        e.option_f64(Some(1.0 / 3.0));
        e.vec3s(&[Vec3::new(1e-300, -2.5, f64::INFINITY)]);
        e.u32s(&[7, u32::MAX]);
        e.bools(&[true, false]);
        let bytes = e.into_bytes();
        let mut d = Decoder::new(&bytes);
        d.tag("part").unwrap();
        assert_eq!(d.f64("x").unwrap().to_bits(), (-0.0f64).to_bits());
        assert!(d.f64("x").unwrap().is_nan());
        assert_eq!(d.option_f64("x").unwrap(), None);
        assert_eq!(d.option_f64("x").unwrap(), Some(1.0 / 3.0));
        assert_eq!(
            d.vec3s("x").unwrap(),
            vec![Vec3::new(1e-300, -2.5, f64::INFINITY)]
        );
        assert_eq!(d.u32s("x").unwrap(), vec![7, u32::MAX]);
        assert_eq!(d.bools("x").unwrap(), vec![true, false]);
        assert!(d.is_done());
    }

    #[test]
    fn a_wrong_part_or_a_short_buffer_is_named() {
        let mut e = Encoder::new();
        e.tag("contact");
        e.f64s(&[1.0, 2.0]);
        let bytes = e.into_bytes();
        let err = Decoder::new(&bytes).tag("state").unwrap_err();
        assert!(matches!(err, CheckpointError::Part { ref found, .. } if found == "contact"));
        let mut d = Decoder::new(&bytes[..bytes.len() - 3]);
        d.tag("contact").unwrap();
        assert!(matches!(
            d.f64s("springs"),
            Err(CheckpointError::Truncated {
                what: "springs",
                ..
            })
        ));
    }

    #[test]
    fn a_corrupt_length_does_not_allocate() {
        let mut e = Encoder::new();
        e.u64(u64::MAX / 2);
        let bytes = e.into_bytes();
        assert!(matches!(
            Decoder::new(&bytes).vec3s("positions"),
            Err(CheckpointError::Truncated { .. })
        ));
    }

    #[test]
    fn a_state_round_trips() {
        let mut s = State::at_rest(vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)]);
        s.time = 0.125;
        s.velocity[1] = Vec3::new(0.1, 0.2, 0.3);
        s.acceleration[0] = Vec3::new(-1.0, 0.0, 9.81);
        let mut e = Encoder::new();
        s.save(&mut e);
        let bytes = e.into_bytes();
        let mut back = State::at_rest(vec![Vec3::zeros(); 2]);
        back.restore(&mut Decoder::new(&bytes)).unwrap();
        assert_eq!(back, s);
        let saved = SavedState::read(&mut Decoder::new(&bytes)).unwrap();
        assert_eq!((saved.time, saved.len()), (0.125, 2));
        assert_eq!(
            (saved.velocity, saved.acceleration),
            (s.velocity.clone(), s.acceleration.clone())
        );
        let mut other = State::at_rest(vec![Vec3::zeros(); 3]);
        assert!(matches!(
            other.restore(&mut Decoder::new(&bytes)),
            Err(CheckpointError::Count {
                expected: 3,
                found: 2,
                ..
            })
        ));
    }
}
