//! `[[probe]]`s resolved against the built state: a particle of a body (the one nearest the
//! probe's point at the start of the run, after `start_from`), a stone of the `[granular]`
//! sample (its centre of mass: the stone nearest the point, or the `stone`-th), or a box over
//! the sample whose stones are averaged at every sample time.

use super::{BodyInfo, BodyKind, BuildError, GranularInfo, ProbePoint};
use crate::scene::{ProbeTarget, Scene};
use qdem_core::{step::State, Vec3};
use std::ops::Range;

/// A `[[probe]] box` over the `[granular]` sample: the stones whose centre of mass lies inside
/// are averaged (`probes.csv` columns `NAME.vx, NAME.vy, NAME.vz, NAME.ke, NAME.count`).
#[derive(Clone, Debug)]
pub struct RegionProbe {
    /// Probe name.
    pub name: String,
    /// Lower and upper corner (m).
    pub region: [Vec3; 2],
}

/// The scene's probes: on particles (bodies' and stones'), in scene order, then on boxes.
pub(super) fn resolve_probes(
    scene: &Scene,
    bodies: &[BodyInfo],
    granular: Option<&GranularInfo>,
    state: &State,
) -> Result<(Vec<ProbePoint>, Vec<RegionProbe>), BuildError> {
    let mut points = Vec::new();
    let mut regions = Vec::new();
    for (p, target) in scene.probes.iter().zip(&scene.refs().probe_targets) {
        let point = p.point.map(Vec3::from);
        match (target, granular) {
            (ProbeTarget::Body(body), _) => {
                let body = &bodies[*body];
                let center = match body.kind {
                    BodyKind::Rigid { center, .. } => Some(center),
                    BodyKind::Deformable { .. } | BodyKind::Stones { .. } => None,
                };
                let candidates = body.particles.clone().chain(center);
                let at = point.expect("validated: a probe on a body has a point");
                points.push(super::nearest_particle(state, candidates, at, &p.name));
            }
            (ProbeTarget::Granular, Some(info)) => {
                let centers = || info.stones.iter().map(|(c, _)| *c);
                if let Some([lo, hi]) = p.region {
                    regions.push(RegionProbe {
                        name: p.name.clone(),
                        region: [Vec3::from(lo), Vec3::from(hi)],
                    });
                } else if let Some(k) = p.stone {
                    let Some(&(center, _)) = info.stones.get(k - 1) else {
                        return Err(BuildError::ProbeStone {
                            scene: scene.path.clone(),
                            probe: p.name.clone(),
                            stone: k,
                            count: info.len(),
                        });
                    };
                    points.push(ProbePoint {
                        name: p.name.clone(),
                        particle: center,
                        distance: 0.0,
                    });
                } else if let Some(at) = point {
                    points.push(super::nearest_particle(state, centers(), at, &p.name));
                }
            }
            (ProbeTarget::Granular, None) => {}
        }
    }
    Ok((points, regions))
}

/// What a box probe reads: the mass-weighted mean velocity (m/s; NaN with no stone inside),
/// the kinetic energy, translational and rotational (J), and the number of the stones whose
/// centre of mass lies in the box, in sample order.
pub fn region_sample(region: &RegionProbe, info: &GranularInfo, state: &State) -> [f64; 5] {
    let [lo, hi] = region.region;
    let (mut mass, mut momentum, mut energy, mut count) = (0.0, Vec3::zeros(), 0.0, 0usize);
    for (center, members) in &info.stones {
        let x = state.position[*center];
        if (0..3).any(|k| x[k] < lo[k] || x[k] > hi[k]) {
            continue;
        }
        let (m, v) = (state.mass[*center], state.velocity[*center]);
        mass += m;
        momentum += m * v;
        energy += 0.5 * m * v.norm_squared() + spin_energy(state, *center, members);
        count += 1;
    }
    let mean = momentum / mass;
    [mean.x, mean.y, mean.z, energy, count as f64]
}

/// Rotational kinetic energy of the stone with centre particle `center` and sphere particles
/// `members`: a one-sphere stone's ½ J ω², a clump's rigid-body ½ ω·L.
fn spin_energy(state: &State, center: usize, members: &Range<usize>) -> f64 {
    match state.rigid.body_of_member(members.start) {
        Some(b) => state.rigid.body_kinetic_energy(b),
        None => 0.5 * state.spin.inertia[center] * state.spin.velocity[center].norm_squared(),
    }
}
