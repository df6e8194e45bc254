//! `[periodic]`: the periodic cell of a scene, the groups of particles that wrap together
//! (every body whole: paper 003's ghosts are copies of whole particles), and the time-delayed
//! boundary that follows a sleeper's cyclic load (paper 003 §5).

use super::ballast::BallastInfo;
use super::granular::GranularInfo;
use crate::build::{BodyInfo, BodyKind, BuildError};
use crate::scene::{Periodic, Scene};
use qdem_contact::boundaries::time_delayed_boundary::lag_from_spacing;
use qdem_contact::{DemContacts, LoadCycle, PeriodicBox, TimeDelayedBoundary, WrapGroup};
use qdem_core::{step::State, Vec3};

/// The axes named in `axes` ("y" → [1]).
fn axes(text: &str) -> Vec<usize> {
    text.chars().filter_map(|c| "xyz".find(c)).collect()
}

/// The periodic cell of `periodic`.
pub(crate) fn periodic_box(scene: &Scene, periodic: &Periodic) -> Result<PeriodicBox, BuildError> {
    let mut length = [None; 3];
    let origin = match (&periodic.length, &periodic.bbox) {
        (Some(l), _) => {
            for (&k, &v) in axes(&periodic.axes).iter().zip(l) {
                length[k] = Some(v);
            }
            Vec3::from(periodic.origin.unwrap_or_default())
        }
        (None, Some(b)) => {
            for k in axes(&periodic.axes) {
                length[k] = Some(b[1][k] - b[0][k]);
            }
            Vec3::from(b[0])
        }
        (None, None) => unreachable!("validated scene"),
    };
    PeriodicBox::new(origin, length).map_err(|source| BuildError::Contact {
        scene: scene.path.clone(),
        source: Box::new(source),
    })
}

/// One group per body: a deformable body's nodes anchored at the node nearest its centroid, a
/// rigid body's members anchored at its centre, each rigid stone at its centre and each ballast
/// stone (not the ballast as a whole) like a deformable body, or at its centre when rigid.
pub(crate) fn wrap_groups(
    state: &State,
    bodies: &[BodyInfo],
    granular: Option<&GranularInfo>,
    ballast: Option<&BallastInfo>,
) -> Vec<WrapGroup> {
    let mut groups = Vec::new();
    for body in bodies {
        if ballast.is_some_and(|b| b.name == body.name) {
            continue;
        }
        groups.push(match body.kind {
            BodyKind::Rigid { center, .. } => {
                let mut particles: Vec<usize> = body.particles.clone().collect();
                particles.push(center);
                WrapGroup {
                    anchor: center,
                    particles,
                }
            }
            BodyKind::Deformable { .. } | BodyKind::Stones { .. } => {
                deformable_group(state, body.particles.clone())
            }
        });
    }
    if let Some(g) = granular {
        for (center, members) in &g.stones {
            let mut particles: Vec<usize> = members.clone().collect();
            if !members.contains(center) {
                particles.push(*center);
            }
            groups.push(WrapGroup {
                anchor: *center,
                particles,
            });
        }
    }
    if let Some(b) = ballast {
        if b.centers.is_empty() {
            groups.extend(b.stones.iter().map(|s| deformable_group(state, s.clone())));
        } else {
            groups.extend(b.stones.iter().zip(&b.centers).map(|(s, &c)| WrapGroup {
                anchor: c,
                particles: s.clone().chain([c]).collect(),
            }));
        }
    }
    groups
}

/// The particles of a deformable body, anchored at the one nearest their centroid.
fn deformable_group(state: &State, range: std::ops::Range<usize>) -> WrapGroup {
    let particles: Vec<usize> = range.clone().collect();
    let n = particles.len().max(1) as f64;
    let centroid = particles
        .iter()
        .fold(Vec3::zeros(), |a, &p| a + state.position[p])
        / n;
    let anchor = *particles
        .iter()
        .min_by(|&&a, &&b| {
            let da = (state.position[a] - centroid).norm_squared();
            let db = (state.position[b] - centroid).norm_squared();
            da.total_cmp(&db)
        })
        .unwrap_or(&range.start);
    WrapGroup { anchor, particles }
}

/// Adds the periodic cell, and the time delay if asked, to the contact model.
pub(crate) fn periodic_contacts(
    scene: &Scene,
    periodic: &Periodic,
    cell: &PeriodicBox,
    contacts: DemContacts,
) -> Result<DemContacts, BuildError> {
    let refused = |source| BuildError::Contact {
        scene: scene.path.clone(),
        source: Box::new(source),
    };
    let contacts = contacts.with_periodic(cell.clone()).map_err(refused)?;
    let (Some(delay), Some(cyclic)) = (&periodic.time_delay, scene.refs().time_delay_cycle) else {
        return Ok(contacts);
    };
    let cyclic = cyclic.cycle();
    let axis = match &delay.axis {
        Some(a) => axes(a)[0],
        None => axes(&periodic.axes)[0],
    };
    let lag = match (delay.lag_deg, delay.sleeper_spacing, delay.speed) {
        (Some(deg), _, _) => deg.to_radians(),
        (None, Some(spacing), Some(speed)) => lag_from_spacing(cyclic.frequency, spacing, speed),
        _ => std::f64::consts::FRAC_PI_2,
    };
    // The controller's cycles are those of the sleeper's own load, each starting at its
    // minimum.
    let cycle = LoadCycle {
        frequency: cyclic.frequency,
        phase: 0.0,
        start: cyclic.first_cycle_start(),
    };
    // Rule 6 of the controller: no ghost pushes more than the load's max/min ratio harder.
    let limit = match cyclic.max / cyclic.min {
        r if r.is_finite() => r.abs(),
        _ => f64::INFINITY,
    };
    let mut boundary = TimeDelayedBoundary::new(cycle, lag).with_scale_limit(limit);
    if delay.shared_faces {
        boundary = boundary.with_shared_faces();
    }
    contacts.with_time_delay(axis, boundary).map_err(refused)
}
