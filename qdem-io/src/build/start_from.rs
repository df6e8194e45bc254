//! `[run] start_from`: a run that begins from the state another scene left in its checkpoint,
//! as paper 000 §4 loads a ballast layer that was first formed by free fall.
//!
//! Unlike `--resume` (the same scene continued bit for bit), the scene may differ in anything
//! that is not a particle: loads, friction, damping, probes, outputs, `t_end`. Its bodies must
//! be built the same way (the same meshes, `[ballast]` and seeds), which is checked: the
//! particle count must match and every particle's reference position must equal the one in the
//! checkpoint up to whole periods of the periodic cell (a periodic cell wraps reference and
//! current positions together). Positions, velocities, accelerations and rigid-body motion are
//! taken from the checkpoint, except that the directions this scene fixes start at rest; time
//! restarts at 0; contact lists are rebuilt at the first step and tangential springs start
//! unstretched.

use crate::build::BuildError;
use crate::checkpoint::read_checkpoint;
use crate::scene::Scene;
use qdem_contact::PeriodicBox;
use qdem_contact::WrapGroup;
use qdem_core::checkpoint::Decoder;
use qdem_core::{State, Vec3};
use std::path::Path;

/// How far a reference position may differ from the checkpoint's (m): the same mesh placed the
/// same way gives equal bits; this only absorbs the rounding of a periodic shift.
const SAME_PLACE: f64 = 1e-9;

/// Replaces the positions, velocities and accelerations of `state` with those of the
/// checkpoint `file` (relative to the scene), with time 0.
pub(crate) fn restore_state(
    scene: &Scene,
    file: &Path,
    state: &mut State,
    periodic: Option<&(PeriodicBox, Vec<WrapGroup>)>,
) -> Result<(), BuildError> {
    let path = scene.resolve(file);
    let refused = |message: String| BuildError::StartFrom {
        scene: scene.path.clone(),
        checkpoint: path.clone(),
        message,
    };
    let body = read_checkpoint(&path, None).map_err(|e| refused(e.to_string()))?;
    let built = state.reference.clone();
    let mut input = Decoder::new(&body);
    crate::run::run_record::skip_record(&mut input)
        .and_then(|()| state.restore(&mut input))
        .map_err(|e| {
            refused(format!(
                "{e}; the checkpoint must come from a scene with the same bodies, ballast and \
                 seeds"
            ))
        })?;
    let cell = periodic.map(|p| &p.0);
    if let Some((i, d)) = first_misplaced(&built, &state.reference, cell) {
        return Err(refused(format!(
            "particle {i} has its reference position {d:.3e} m away from this scene's: the \
             checkpoint was written by a scene with other meshes, placements, ballast or seeds; \
             start from a checkpoint of a scene that builds the same bodies"
        )));
    }
    // The scene's fixes hold from the first step, even in directions the checkpoint's
    // scene let move (else those would keep the checkpoint's velocity for the whole run).
    state.hold_fixed();
    state.time = 0.0;
    Ok(())
}

/// The first particle whose reference positions differ by more than [`SAME_PLACE`] after
/// removing whole periods, with the distance.
fn first_misplaced(
    built: &[Vec3],
    restored: &[Vec3],
    cell: Option<&PeriodicBox>,
) -> Option<(usize, f64)> {
    built
        .iter()
        .zip(restored)
        .enumerate()
        .find_map(|(i, (a, b))| {
            let mut d = b - a;
            if let Some(cell) = cell {
                for k in 0..3 {
                    if let Some(l) = cell.length(k) {
                        d[k] -= l * (d[k] / l).round();
                    }
                }
            }
            let distance = d.norm();
            (distance.is_nan() || distance > SAME_PLACE).then_some((i, distance))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_periods_are_the_same_place_and_anything_else_is_not() {
        let cell = PeriodicBox::new(Vec3::zeros(), [None, Some(0.6), None]).unwrap();
        let built = vec![Vec3::new(0.1, 0.2, 0.3); 2];
        let shifted = vec![built[0], built[1] + Vec3::new(0.0, -1.2, 0.0)];
        assert_eq!(first_misplaced(&built, &shifted, Some(&cell)), None);
        assert!(first_misplaced(&built, &shifted, None).is_some());
        let moved = vec![built[0], built[1] + Vec3::new(0.0, 0.0, 1e-6)];
        let (i, d) = first_misplaced(&built, &moved, Some(&cell)).unwrap();
        assert_eq!(i, 1);
        assert!((d - 1e-6).abs() < 1e-12);
    }
}
