//! `[granular]`: a sample of rigid stones, each a clump of spheres (paper 003 §3), added to a
//! simulation after its mesh bodies.
//!
//! The stones come from a generation ([`qdem_contact::samples::clump_sample::generate_stones`]: a grading
//! curve sampled by number or by mass (`grading_basis`), stones elongated or angular (`shape`),
//! a loose lattice in a region, a seed), to be deposited under gravity, or from a stones
//! file: CSV with the header `stone,x,y,z,radius` and one row per sphere, the rows of a stone
//! together. A run with `[granular]` writes the stones' final spheres to `stones.csv` in that
//! format ([`write_stones_csv`]), so a deposition run's output is the next run's sample.
//! `copies` places the sample once per translation: a sample deposited in a periodic cell,
//! repeated by whole periods, is the packing of a box several cells long whose every cell holds
//! the same stones (the three-sleeper box test built around the single-sleeper cell's sample,
//! so that both load the same ballast). `crop` then keeps the stones whose spheres all lie
//! inside a box, as paper 003 §3 cuts its single-sleeper samples out of the middle of its
//! three-sleeper one. A sphere may cross a face of the box by [`CROP_TOLERANCE`] of its
//! radius: a stone resting on a wall overlaps it by its contact overlap (up to 0.3% of the
//! radius in the box-test deposits), and a crop box drawn on the walls must keep it — refusing
//! it took the whole bottom layer and the stones along the side walls out of every cropped
//! sample, and the sample collapsed into the gap. A sample and a generation together give the
//! sample's stones then new ones (deposition in stages: a bed, then the sleepers laid on it,
//! then the crib ballast poured around them). `refill` ([`super::refill`]) keeps a walled
//! box's whole sample: the stones astride its sides, which a crop would drop, are moved
//! inside and stacked above the sample, to be poured back.
//!
//! A stone of several spheres becomes a rigid body: a centre particle at its centre of mass
//! with its mass (the union of its spheres at the material's density,
//! [`clump_mass_properties`]) plus one massless member per sphere, which carries the sphere's
//! contact radius. A one-sphere stone is one particle at the sphere's centre with that mass,
//! which rotates ([`State::let_turn`]) with the moment of inertia J = tr(I)/3 (the sphere's
//! isotropic I): it needs no orientation, and integrating it as a rigid body would carry a
//! centre, a member and their passes for nothing.

use crate::build::BuildError;
use crate::csv_rows::{finite, read_text, rows};
use crate::output::{write_atomic, OutputError};
use crate::scene::{ClumpShapeName, GradingBasisName, Granular, Scene};
use qdem_contact::samples::clump_sample::{
    clump_mass_properties, generate_stones, ClumpShape, Grading, GradingBasis, MassProperties,
    SampleError, SampleSpec, Stone,
};
use qdem_contact::ContactSphere;
use qdem_core::{step::State, Vec3};
use std::ops::Range;
use std::path::Path;

/// The stones of a simulation: where they live in the state.
#[derive(Clone, Debug)]
pub struct GranularInfo {
    /// `[granular] name`.
    pub name: String,
    /// Per stone: its centre particle and its member particles (one per sphere); a one-sphere
    /// stone is its own centre and only member.
    pub stones: Vec<(usize, Range<usize>)>,
    /// Radius of every member particle's sphere, in member order.
    pub radii: Vec<f64>,
    /// The first member particle (members are contiguous, stone after stone).
    pub first_member: usize,
}

impl GranularInfo {
    /// Number of stones.
    pub fn len(&self) -> usize {
        self.stones.len()
    }

    /// Whether the sample is empty.
    pub fn is_empty(&self) -> bool {
        self.stones.is_empty()
    }
}

/// How far, as a fraction of its radius, a sphere may cross a face of the `crop` box and still
/// count as inside (module docs): three times the largest wall overlap of a deposit.
pub const CROP_TOLERANCE: f64 = 0.01;

/// Whether a sphere (centre `c`, radius `r`) lies inside the box `lo`–`hi` up to
/// [`CROP_TOLERANCE`].
fn inside_crop(lo: &[f64; 3], hi: &[f64; 3], c: &Vec3, r: f64) -> bool {
    let slack = CROP_TOLERANCE * r;
    (0..3).all(|k| c[k] - r >= lo[k] - slack && c[k] + r <= hi[k] + slack)
}

/// `stones` placed once per translation of `copies`, copy after copy.
fn copied(stones: &[Stone], copies: &[[f64; 3]]) -> Vec<Stone> {
    copies
        .iter()
        .flat_map(|&t| {
            stones.iter().map(move |s| Stone {
                centers: s.centers.iter().map(|c| c + Vec3::from(t)).collect(),
                radii: s.radii.clone(),
            })
        })
        .collect()
}

/// The stones of `granular`: its sample file's, copied, cropped and refilled, then the
/// generated ones;
/// with the number of the sample's.
pub(crate) fn stones(
    scene: &Scene,
    granular: &Granular,
) -> Result<(Vec<Stone>, usize), BuildError> {
    let refused = |source: SampleError| BuildError::Granular {
        scene: scene.path.clone(),
        source,
    };
    let mut stones = match scene.sample_path() {
        Some(path) => copied(&read_stones_csv(&path)?, &granular.copies),
        None => Vec::new(),
    };
    if let Some([lo, hi]) = granular.crop {
        stones.retain(|s| {
            s.centers
                .iter()
                .zip(&s.radii)
                .all(|(c, &r)| inside_crop(&lo, &hi, c, r))
        });
    }
    if let Some(area) = granular.refill {
        stones = super::refill::refill(stones, area)
            .map_err(|source| BuildError::Refill {
                scene: scene.path.clone(),
                source,
            })?
            .0;
    }
    let sampled = stones.len();
    if let (Some([lo, hi]), Some(count), Some(grading)) =
        (granular.region, granular.count, &granular.grading)
    {
        let spheres = granular.spheres_per_stone[1];
        super::memory::check(
            &scene.path,
            format!("[granular] count = {count} stones of up to {spheres} spheres"),
            (count as f64 * spheres as f64, 0.0),
            "lower count (or spheres_per_stone)",
        )?;
        let spec = SampleSpec {
            region: [Vec3::from(lo), Vec3::from(hi)],
            count,
            grading: Grading::new(grading.iter().map(|p| (p[0], p[1])).collect())
                .map_err(refused)?,
            basis: match granular.grading_basis {
                GradingBasisName::Number => GradingBasis::Number,
                GradingBasisName::Mass => GradingBasis::Mass,
            },
            spheres_per_stone: granular.spheres_per_stone,
            shape: match granular.shape {
                ClumpShapeName::Elongated => ClumpShape::Elongated,
                ClumpShapeName::Angular => ClumpShape::Angular,
            },
            seed: granular.seed,
        };
        stones.extend(generate_stones(&spec).map_err(refused)?);
    }
    Ok((stones, sampled))
}

/// Appends `stones` to `state` as rigid bodies (a one-sphere stone as a rotating particle),
/// moving with the `[granular]` initial velocity and angular velocity (the first `sampled`
/// stones the sample's, the others the generated ones'), and returns where they went and their
/// contact spheres (bodies numbered from `first_body`; `(material, density)`: the index of the
/// `[granular]` material and its density). `scene` is the scene file, for messages.
pub(crate) fn add_stones(
    scene: &Path,
    granular: &Granular,
    (stones, sampled): (&[Stone], usize),
    state: &mut State,
    first_body: usize,
    (material, density): (usize, f64),
) -> Result<(GranularInfo, Vec<ContactSphere>), BuildError> {
    let first_member = state.len();
    let mut radii = Vec::new();
    for stone in stones {
        for (c, &r) in stone.centers.iter().zip(&stone.radii) {
            state.push_particle(*c, Vec3::zeros(), 0.0);
            radii.push(r);
        }
    }
    let mut spinning = false;
    let mut info = GranularInfo {
        name: granular.name.clone(),
        stones: Vec::with_capacity(stones.len()),
        radii,
        first_member,
    };
    let mut spheres = Vec::with_capacity(info.radii.len());
    let mut member = first_member;
    for (k, stone) in stones.iter().enumerate() {
        let props =
            clump_mass_properties(stone, density).map_err(|source| BuildError::Granular {
                scene: scene.to_path_buf(),
                source,
            })?;
        let members: Range<usize> = member..member + stone.centers.len();
        let (v, w) = granular.motion(k >= sampled);
        let (v, w) = (Vec3::from(v), Vec3::from(w));
        let center = if members.len() == 1 {
            state.mass[member] = props.mass;
            state.let_turn(member, props.inertia.trace() / 3.0);
            state.spin.velocity[member] = w;
            member
        } else {
            let center = add_clump(scene, state, &props, &members, &granular.name, k)?;
            let b = state.rigid.len() - 1;
            state.rigid.set_angular_velocity(b, w);
            spinning |= w != Vec3::zeros();
            center
        };
        state.velocity[center] = v;
        state.velocity[members.clone()].fill(v);
        for p in members.clone() {
            spheres.push(ContactSphere {
                particle: p,
                radius: info.radii[p - first_member],
                body: first_body + k,
                material,
            });
        }
        member = members.end;
        info.stones.push((center, members));
    }
    if spinning {
        qdem_core::step::rigid_body::place_members(state);
    }
    Ok((info, spheres))
}

/// Stone `k` of several spheres, on the particles `members`, as a rigid body: its centre
/// particle, whose index is returned.
fn add_clump(
    scene: &Path,
    state: &mut State,
    props: &MassProperties,
    members: &Range<usize>,
    sample: &str,
    k: usize,
) -> Result<usize, BuildError> {
    let center = state.push_particle(props.center, Vec3::zeros(), props.mass);
    let name = format!("{} stone {}", sample, k + 1);
    let ids: Vec<usize> = members.clone().collect();
    state
        .add_rigid_body(&name, center, &ids, props.inertia)
        .map_err(|source| BuildError::Core {
            scene: scene.to_path_buf(),
            source,
        })?;
    Ok(center)
}

/// The header of a stones file.
pub const STONES_HEADER: &str = "stone,x,y,z,radius";

/// Reads a stones file (see the module docs); every malformed line is refused with its number.
pub fn read_stones_csv(path: &Path) -> Result<Vec<Stone>, BuildError> {
    let bad = |line: usize, message: String| BuildError::Sample {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = read_text(path, STONES_HEADER, &bad)?;
    let mut stones: Vec<Stone> = Vec::new();
    let mut last_id: Option<u64> = None;
    for (n, fields) in rows(&text, 5, &bad)? {
        let id: u64 = fields[0]
            .parse()
            .map_err(|_| bad(n, format!("stone {:?} is not a whole number", fields[0])))?;
        let v: [f64; 4] = finite(&fields[1..], n, &bad)?;
        if v[3] <= 0.0 {
            return Err(bad(n, format!("radius {} must be positive", v[3])));
        }
        if last_id != Some(id) {
            if last_id.is_some_and(|l| id < l) {
                return Err(bad(
                    n,
                    format!("stone {id} after stone {}: keep the rows of a stone together, in ascending order", last_id.unwrap_or(0)),
                ));
            }
            stones.push(Stone {
                centers: Vec::new(),
                radii: Vec::new(),
            });
            last_id = Some(id);
        }
        let stone = stones.last_mut().expect("pushed above");
        stone.centers.push(Vec3::new(v[0], v[1], v[2]));
        stone.radii.push(v[3]);
    }
    if stones.is_empty() {
        return Err(bad(1, "the file holds no stone".into()));
    }
    Ok(stones)
}

/// Writes the current spheres of every stone to `path` (atomically), in the format
/// [`read_stones_csv`] reads.
pub fn write_stones_csv(
    path: &Path,
    info: &GranularInfo,
    state: &State,
) -> Result<(), OutputError> {
    write_atomic(path, |w| {
        writeln!(w, "{STONES_HEADER}")?;
        for (k, (_, members)) in info.stones.iter().enumerate() {
            for p in members.clone() {
                let x = state.position[p];
                let r = info.radii[p - info.first_member];
                writeln!(
                    w,
                    "{},{:.17e},{:.17e},{:.17e},{:.17e}",
                    k + 1,
                    x.x,
                    x.y,
                    x.z,
                    r
                )?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const LO: [f64; 3] = [0.0, 0.0, 0.0];
    const HI: [f64; 3] = [1.0, 1.0, 1.0];

    #[test]
    fn a_stone_resting_on_a_wall_of_the_crop_box_is_kept() {
        // r = 0.1 pressed 0.3% of r into the floor, as the deposits' stones rest on it.
        let r = 0.1;
        assert!(inside_crop(
            &LO,
            &HI,
            &Vec3::new(0.5, 0.5, r - 0.003 * r),
            r
        ));
        assert!(inside_crop(
            &LO,
            &HI,
            &Vec3::new(1.0 - r + 0.003 * r, 0.5, 0.5),
            r
        ));
    }

    #[test]
    fn copies_repeat_a_periodic_cell_and_the_crop_drops_the_stones_astride_the_ends() {
        // A cell y in [0.7, 1.4): one stone inside, one astride its upper face (its image
        // astride the lower face belongs to the cell too). Three copies a period apart fill
        // y in [0, 2.1); the crop keeps the astride stone at the two inner faces only.
        let inside = Stone {
            centers: vec![Vec3::new(0.1, 1.0, 0.1), Vec3::new(0.15, 1.0, 0.1)],
            radii: vec![0.05, 0.04],
        };
        let astride = Stone {
            centers: vec![Vec3::new(0.1, 1.39, 0.1)],
            radii: vec![0.05],
        };
        let copies = [[0.0, -0.7, 0.0], [0.0, 0.0, 0.0], [0.0, 0.7, 0.0]];
        let all = copied(&[inside.clone(), astride], &copies);
        let ys: Vec<f64> = all.iter().map(|s| s.centers[0].y).collect();
        let want = [0.3, 0.69, 1.0, 1.39, 1.7, 2.09];
        assert!(
            ys.iter().zip(want).all(|(y, w)| (y - w).abs() < 1e-12),
            "{ys:?}"
        );
        assert_eq!(all[4].radii, inside.radii);
        let d = all[4].centers[1] - all[4].centers[0];
        assert!((d - Vec3::new(0.05, 0.0, 0.0)).norm() < 1e-12, "{d:?}");
        let (lo, hi) = ([0.0, 0.0, 0.0], [0.3, 2.1, 0.45]);
        let kept = all
            .iter()
            .filter(|s| {
                s.centers
                    .iter()
                    .zip(&s.radii)
                    .all(|(c, &r)| inside_crop(&lo, &hi, c, r))
            })
            .count();
        assert_eq!(kept, 5);
    }

    #[test]
    fn a_stone_across_a_face_of_the_crop_box_is_dropped() {
        // Crossing by 5% of r is no contact overlap, and a stone astride a cut is outside.
        let r = 0.1;
        assert!(!inside_crop(
            &LO,
            &HI,
            &Vec3::new(0.5, 0.5, r - 0.05 * r),
            r
        ));
        assert!(!inside_crop(&LO, &HI, &Vec3::new(0.5, 1.0, 0.5), r));
        assert!(!inside_crop(
            &LO,
            &HI,
            &Vec3::new(0.5, 0.5, 1.0 - 0.5 * r),
            r
        ));
    }
}
