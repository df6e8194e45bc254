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
//! restarts at 0; contact lists are rebuilt at the first step, with the tangential springs of
//! the checkpoint's contacts between the same spheres (and walls, by their order in the scene):
//! a sphere is known by the particle that carries it, so a spring whose sphere or wall this
//! scene does not have is dropped, and counted in a line ([`carry_springs`]). Its walls begin
//! where the checkpoint's walls of the same order stood, a servo wall with the speed its servo
//! had set, unless a wall says `start = "scene"` ([`carry_walls`]). What the stage places is
//! checked for overlaps there, with the checkpoint's positions (`contact::check_start`): every
//! wall against the bodies, and the bodies whose kind changed against the others; two bodies
//! that both stand where the checkpoint left them are not, since their overlap is a contact
//! the previous stage loaded (a bed under a servo lid overlaps as its load asks), not a
//! placement ([`placed_anew`]).
//!
//! A body's kind may differ from the checkpoint's scene (`rigid` on a `[[body]]` or on the
//! `[ballast]`): the particles are then mapped and the bodies turned as `kind_change` says.

use crate::build::kind_change::{self, Unit};
use crate::build::BuildError;
use crate::checkpoint::read_checkpoint;
use crate::scene::{Scene, WallStart};
use qdem_contact::{DemContacts, PeriodicBox, SavedSprings, SavedWall, WrapGroup};
use qdem_core::checkpoint::CheckpointError;
use qdem_core::checkpoint::{model_histories, Decoder, SavedState};
use qdem_core::{step::State, Vec3};
use std::path::Path;

/// How far a reference position may differ from the checkpoint's (m): the same mesh placed the
/// same way gives equal bits; this only absorbs the rounding of a periodic shift.
const SAME_PLACE: f64 = 1e-9;

/// Replaces the positions, velocities and accelerations of `state` with those of the
/// checkpoint `file` (relative to the scene), with time 0, starts the walls of `contacts`
/// where the checkpoint's stood (those with `start = "checkpoint"`), checks the overlaps
/// there, and starts `contacts` with the checkpoint's tangential springs; the bodies of
/// `units` may have another kind there. Returns a line for each body whose kind changed, each
/// wall that moved, and springs that could not be carried.
pub(crate) fn restore_state(
    scene: &Scene,
    file: &Path,
    units: &[Unit],
    (state, contacts): (&mut State, Option<&mut DemContacts>),
    periodic: Option<&(PeriodicBox, Vec<WrapGroup>)>,
) -> Result<Vec<String>, BuildError> {
    let path = scene.resolve(file);
    let refused = |message: String| BuildError::StartFrom {
        scene: scene.path.clone(),
        checkpoint: path.clone(),
        message,
    };
    let body = read_checkpoint(&path, None).map_err(|e| refused(e.to_string()))?;
    let mut input = Decoder::new(&body);
    let saved = crate::run::run_record::skip_record(&mut input)
        .and_then(|()| SavedState::read(&mut input))
        .map_err(|e| {
            refused(format!(
                "{e}; the checkpoint must come from a scene with the same bodies, ballast and \
                 seeds"
            ))
        })?;
    let cell = periodic.map(|p| &p.0);
    let built = state.reference.clone();
    let mesh_nodes = units
        .iter()
        .flat_map(|u| u.pieces.iter().map(|p| p.nodes.end))
        .max()
        .unwrap_or(0);
    let common = mesh_nodes.min(saved.len());
    if let Some((i, d)) = first_misplaced(&built[..common], &saved.reference[..common], cell) {
        return Err(refused(misplaced(units, i, d)));
    }
    let same = |a: Vec3, b: Vec3| distance(a, b, cell) <= SAME_PLACE;
    let was_rigid = match saved.len() >= mesh_nodes {
        true => kind_change::saved_kinds(units, &saved, mesh_nodes, same),
        false => vec![false; units.len()],
    };
    let layout = Layout::new(units, &was_rigid, mesh_nodes, state);
    if let Some(why) = layout.misfit(&saved, state) {
        return Err(refused(why));
    }
    layout.copy(&saved, state);
    if let Some((i, d)) = first_misplaced(&built, &state.reference, cell) {
        return Err(refused(misplaced(units, i, d)));
    }
    let mut lines = turn(units, &was_rigid, &layout, &saved, state);
    // The scene's fixes hold from the first step, even in directions the checkpoint's
    // scene let move (else those would keep the checkpoint's velocity for the whole run).
    state.hold_fixed();
    state.time = 0.0;
    let (springs, walls) = saved_contacts(&mut input).map_err(|e| {
        refused(format!(
            "{e}; its contact springs and walls cannot be read: start from a checkpoint this \
             qdem wrote"
        ))
    })?;
    let mut contacts = contacts;
    if let Some(contacts) = contacts.as_deref_mut() {
        lines.extend(carry_walls(scene, &walls, saved.time, contacts).map_err(refused)?);
        // The overlaps where this stage starts, before the springs (the check builds the
        // lists, which the springs replace until the first evaluation rebuilds them).
        let placed = placed_anew(units, &was_rigid, state.len());
        super::contact::check_start(scene, contacts, state, |p| placed[p])?;
    }
    lines.extend(carry_springs(&springs, &layout, saved.len(), contacts));
    let from = path.display();
    Ok(lines
        .into_iter()
        .map(|t| format!("[run] start_from {from}: {t}"))
        .collect())
}

/// Whether each of `particles` is placed by this stage rather than left where the checkpoint
/// had it: those of the units whose kind changed (`was_rigid` in the checkpoint), turned to a
/// best-fit pose or placed unstressed at theirs.
fn placed_anew(units: &[Unit], was_rigid: &[bool], particles: usize) -> Vec<bool> {
    let mut placed = vec![false; particles];
    let turned = units
        .iter()
        .zip(was_rigid)
        .filter(|(u, &was)| u.rigid() != was);
    for piece in turned.flat_map(|(u, _)| &u.pieces) {
        piece.nodes.clone().for_each(|i| placed[i] = true);
        if let Some((_, center)) = piece.rigid {
            placed[center] = true;
        }
    }
    placed
}

/// The name of the contact model ([`DemContacts`]) in a checkpoint.
const CONTACT_MODEL: &str = "contact";

/// The stretched tangential springs and the walls of the checkpoint's contact model (none
/// without one), read after its state.
fn saved_contacts(
    input: &mut Decoder<'_>,
) -> Result<(SavedSprings, Vec<SavedWall>), CheckpointError> {
    let histories = model_histories(input)?;
    match histories.iter().find(|(name, _)| name == CONTACT_MODEL) {
        Some((_, history)) => Ok((SavedSprings::read(history)?, SavedWall::read(history)?)),
        None => Ok((SavedSprings::default(), Vec::new())),
    }
}

/// Starts each wall of the scene whose `start` is `"checkpoint"` where the same wall (by
/// order) of the checkpoint stood at its time `time`; a line for each that moved so, and one
/// for walls the checkpoint does not have. Refused when a wall is a plane in one scene and a
/// mesh in the other.
fn carry_walls(
    scene: &Scene,
    saved: &[SavedWall],
    time: f64,
    contacts: &mut DemContacts,
) -> Result<Vec<String>, String> {
    let mut lines = Vec::new();
    let carried = scene.walls.iter().enumerate().zip(saved);
    for ((w, wall), saved) in carried.filter(|((_, w), _)| w.start == WallStart::Checkpoint) {
        if !contacts.carry_wall(w, saved, time) {
            let (here, there) = match saved.plane {
                true => ("a mesh", "a plane"),
                false => ("a plane", "a mesh"),
            };
            return Err(format!(
                "[[wall]] #{}: {here} here but {there} in the checkpoint, so it cannot start \
                 where that one stood; give it `start = \"scene\"`, or list the walls in the \
                 checkpoint's order",
                w + 1
            ));
        }
        let at = saved.base + saved.velocity * time;
        let moved = match (wall.point, wall.normal) {
            (Some(p), Some(n)) => (at - Vec3::from(p)).dot(&Vec3::from(n).normalize()),
            _ => at.norm(),
        };
        if moved != 0.0 {
            lines.push(format!(
                "[[wall]] #{} starts where the checkpoint left it, {moved:.4e} m from this \
                 scene's place (along its normal for a plane); `start = \"scene\"` starts it \
                 there",
                w + 1
            ));
        }
    }
    let missing = scene.walls.len().saturating_sub(saved.len());
    let waiting = scene.walls[saved.len().min(scene.walls.len())..]
        .iter()
        .any(|w| w.start == WallStart::Checkpoint);
    if missing > 0 && waiting {
        lines.push(format!(
            "the checkpoint has {} walls: the last {missing} of this scene's start at their \
             own place",
            saved.len()
        ));
    }
    Ok(lines)
}

/// Puts the `saved` springs on the same spheres of `contacts` (a sphere is known by its
/// particle: `layout` maps the checkpoint's `old_particles` particles to this scene's); a line
/// when some could not be carried.
fn carry_springs(
    saved: &SavedSprings,
    layout: &Layout,
    old_particles: usize,
    contacts: Option<&mut DemContacts>,
) -> Option<String> {
    let mut new_of_old = vec![None; old_particles];
    for (new, old) in layout.particle.iter().enumerate() {
        if let Some(old) = *old {
            new_of_old[old] = Some(new);
        }
    }
    let total = saved.len();
    let Some(contacts) = contacts else {
        return (total > 0).then(|| {
            format!(
                "its {total} stretched tangential contact springs dropped: this scene has no \
                 contacts"
            )
        });
    };
    let carried = contacts.carry_springs(saved, |p| new_of_old.get(p as usize).copied().flatten());
    (carried.dropped > 0).then(|| {
        format!(
            "{} of its {total} stretched tangential contact springs dropped: a sphere or wall \
             of theirs is not in this scene (a body without `contact_radius` here, or fewer \
             [[wall]]s); the other {} carried",
            carried.dropped, carried.carried
        )
    })
}

/// Where each particle and rigid body of this scene comes from in the checkpoint's (`None`: a
/// centre the checkpoint's scene did not have), and where each piece's old centre and rigid
/// body were (`None`: it was deformable).
struct Layout {
    particle: Vec<Option<usize>>,
    rigid: Vec<Option<usize>>,
    old: Vec<Vec<Option<(usize, usize)>>>,
    /// The checkpoint's particle and rigid-body counts that this layout expects.
    expected: (usize, usize),
}

impl Layout {
    fn new(units: &[Unit], was_rigid: &[bool], mesh_nodes: usize, state: &State) -> Layout {
        let mut particle: Vec<Option<usize>> = vec![None; state.len()];
        let mut rigid: Vec<Option<usize>> = vec![None; state.rigid.len()];
        (0..mesh_nodes).for_each(|i| particle[i] = Some(i));
        let (mut old_center, mut old_body, mut here) = (mesh_nodes, 0, 0);
        let mut old = Vec::with_capacity(units.len());
        for (u, &was) in units.iter().zip(was_rigid) {
            let pieces = u.pieces.iter().map(|p| {
                let from = was.then(|| {
                    old_center += 1;
                    old_body += 1;
                    (old_center - 1, old_body - 1)
                });
                if let Some((b, c)) = p.rigid {
                    here += 1;
                    particle[c] = from.map(|f| f.0);
                    rigid[b] = from.map(|f| f.1);
                }
                from
            });
            old.push(pieces.collect());
        }
        // The rest (a [granular] sample) follows the centres in both scenes.
        let rest = mesh_nodes + here;
        for (k, p) in particle.iter_mut().enumerate().skip(rest) {
            *p = Some(old_center + k - rest);
        }
        for (k, b) in rigid.iter_mut().enumerate().skip(here) {
            *b = Some(old_body + k - here);
        }
        let expected = (
            old_center + state.len() - rest,
            old_body + state.rigid.len() - here,
        );
        Layout {
            particle,
            rigid,
            old,
            expected,
        }
    }

    /// Why the checkpoint does not fit this layout, if it does not.
    fn misfit(&self, saved: &SavedState, state: &State) -> Option<String> {
        let spins = if state.spin.is_empty() {
            0
        } else {
            self.expected.0
        };
        let found = (saved.len(), saved.orientation.len());
        (found != self.expected || saved.spin[0].len() != spins).then(|| {
            format!(
                "the checkpoint has {} particles and {} rigid bodies where this scene, with its \
                 bodies of the kinds the checkpoint shows, needs {} and {}: it was written by a \
                 scene with other bodies, a changed stone count or another [granular] sample; \
                 start from a checkpoint of a scene that builds the same bodies (only `rigid` \
                 may differ)",
                found.0, found.1, self.expected.0, self.expected.1
            )
        })
    }

    /// Every particle and rigid body the checkpoint has, copied to its place in `state`.
    fn copy(&self, saved: &SavedState, state: &mut State) {
        for (i, from) in self.particle.iter().enumerate() {
            let Some(o) = *from else { continue };
            state.reference[i] = saved.reference[o];
            state.position[i] = saved.position[o];
            state.velocity[i] = saved.velocity[o];
            state.acceleration[i] = saved.acceleration[o];
            if !state.spin.is_empty() {
                state.spin.angle[i] = saved.spin[0][o];
                state.spin.velocity[i] = saved.spin[1][o];
                state.spin.acceleration[i] = saved.spin[2][o];
            }
        }
        for (b, from) in self.rigid.iter().enumerate() {
            let Some(o) = *from else { continue };
            state.rigid.orientation[b] = saved.orientation[o];
            state.rigid.angular_momentum[b] = saved.angular_momentum[o];
            state.rigid.angular_velocity[b] = saved.angular_velocity[o];
        }
    }
}

/// Turns every unit whose kind changed, with a line saying what was done and dropped.
fn turn(
    units: &[Unit],
    was_rigid: &[bool],
    layout: &Layout,
    saved: &SavedState,
    state: &mut State,
) -> Vec<String> {
    let mut lines = Vec::new();
    for ((u, &was), old) in units.iter().zip(was_rigid).zip(&layout.old) {
        let count = u.pieces.len();
        let bodies = if count == 1 { "body" } else { "bodies" };
        match (was, u.rigid()) {
            (true, false) => {
                for (p, from) in u.pieces.iter().zip(old) {
                    let (center, body) = from.expect("a rigid unit has its centres");
                    kind_change::to_deformable(p, (center, body), saved, state);
                }
                lines.push(format!(
                    "{}: rigid in the checkpoint, deformable here: {count} {bodies} placed \
                     unstressed, each at its pose with its momentum and angular momentum",
                    u.what
                ));
            }
            (false, true) => {
                let density = u.material.density;
                let kinetic: f64 = (u.pieces.iter())
                    .map(|p| kind_change::to_rigid(p, density, saved, state))
                    .sum();
                let tets = u
                    .pieces
                    .iter()
                    .flat_map(|p| p.tets.iter().copied())
                    .collect();
                let strain = kind_change::strain_energy(&u.what, tets, u.material.clone(), saved);
                lines.push(format!(
                    "{}: deformable in the checkpoint, rigid here: {count} {bodies}, each at its \
                     centre of mass and best-fit rotation with its momentum and angular \
                     momentum; dropped: strain energy {strain:.4e} J, kinetic energy of the \
                     deformation {kinetic:.4e} J",
                    u.what
                ));
            }
            _ => {}
        }
    }
    lines
}

/// The refusal of a reference position that moved, naming the body (the stone) it is in.
fn misplaced(units: &[Unit], i: usize, d: f64) -> String {
    let name = units
        .iter()
        .find_map(|u| u.name_of(i))
        .unwrap_or_else(|| "a particle of no body".to_string());
    format!(
        "{name}: particle {i} has its reference position {d:.3e} m away from this scene's: the \
         checkpoint was written by a scene with another mesh, placement, stone count or seed \
         for it; start from a checkpoint of a scene that builds the same bodies (only `rigid` \
         may differ)"
    )
}

/// The distance between `a` and `b` after removing whole periods of `cell`.
fn distance(a: Vec3, b: Vec3, cell: Option<&PeriodicBox>) -> f64 {
    let mut d = b - a;
    if let Some(cell) = cell {
        for k in 0..3 {
            if let Some(l) = cell.length(k) {
                d[k] -= l * (d[k] / l).round();
            }
        }
    }
    d.norm()
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
            let distance = distance(*a, *b, cell);
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
