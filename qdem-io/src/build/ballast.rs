//! `[ballast]`: deformable ballast stones (paper 000 §4: "each ballast particle had
//! approximately 100 tetrahedral elements, and its size was around 5 cm"; a contact sphere at
//! every surface vertex).
//!
//! Each stone is a copy of one of the scene's stone meshes (drawn at random), scaled so that its
//! sieve size (the middle extent of the mesh's bounding box) follows the grading curve by
//! number, laid out with its longest bounding-box extent along x and its shortest along y (the
//! track direction, across which the crib between sleepers is narrowest), turned half a turn
//! about a random axis or not at all, and put in its own cell of a lattice that
//! fills `region` from the bottom layer up. A cell is as large on each axis as the largest
//! stone's extent there plus its contact spheres (5% spare), so no two stones overlap; cells
//! that reach into `exclude` or through a plane `[[wall]]` stay empty, and each stone is
//! jittered inside its cell by what its own size leaves free. The stones are deposited by
//! running the scene under gravity (`velocity` starts them falling).
//!
//! All stones together form one deformable body (one [`qdem_core::continuum::TetBody`], so the kernel
//! runs over all their tetrahedra in parallel); in contact each stone is its own body, so its
//! spheres never touch each other, and a periodic cell wraps each stone whole. With
//! `rigid = true` each stone is instead a rigid body ([`qdem_core::step::rigid_body`]): a centre
//! particle at the centre of mass of its tetrahedra with their mass and inertia, its mesh nodes
//! massless members that carry its contact spheres ([`rigid_stones`]).

use crate::build::{read_mesh, BuildError, PlacedMesh};
use crate::scene::{Ballast, Scene};
use nalgebra::UnitQuaternion;
use qdem_contact::bonded::particle_packing::SplitMix64;
use qdem_contact::dem::broad_phase::bounds;
use qdem_contact::samples::clump_sample::Grading;
use qdem_contact::ContactSphere;
use qdem_core::step::rigid_body::tet_mass_properties;
use qdem_core::{error::CoreError, step::State, Mat3, Vec3};
use qdem_mesh::TetMesh;
use std::ops::Range;
use std::path::PathBuf;

/// Where the ballast's stones live in the state.
#[derive(Clone, Debug)]
pub struct BallastInfo {
    /// `[ballast] name`.
    pub name: String,
    /// Each stone's particles.
    pub stones: Vec<Range<usize>>,
    /// Each stone's shape: an index into `[ballast] meshes`.
    pub shapes: Vec<usize>,
    /// Each stone's sieve size (m).
    pub sizes: Vec<f64>,
    /// The contact spheres at the stones' surface vertices.
    pub spheres: Vec<ContactSphere>,
    /// Each stone's tetrahedra: a range of the ballast mesh's tetrahedra.
    pub tets: Vec<Range<usize>>,
    /// Each stone's centre particle when the stones are rigid (`rigid = true`); empty when
    /// they are one deformable body.
    pub centers: Vec<usize>,
}

/// A stone mesh laid out with its longest bounding-box extent along x, its shortest along y and
/// the middle one along z, centred on its bounding box, with what placing it needs.
struct Shape {
    mesh: TetMesh,
    /// Bounding-box extents along x, y, z: longest, shortest, middle (m).
    extents: Vec3,
    /// Surface nodes (the contact spheres).
    surface: Vec<u32>,
}

impl Shape {
    /// Middle extent of the bounding box (m).
    fn sieve(&self) -> f64 {
        self.extents.z
    }
}

/// One stone as drawn: its shape, scale and turn.
struct Draw {
    shape: usize,
    scale: f64,
    turn: UnitQuaternion<f64>,
}

/// The ballast as one placed mesh (all stones, one after another from particle `start`), its
/// stones with their contact spheres (stone `k` is contact body `first_body + k`, of material
/// `material`, the index validation resolved), and mesh warnings.
pub(crate) fn place_ballast(
    scene: &Scene,
    ballast: &Ballast,
    start: usize,
    first_body: usize,
    material: usize,
) -> Result<(PlacedMesh, BallastInfo, Vec<String>), BuildError> {
    let (shapes, warnings) = read_shapes(scene, ballast)?;
    let largest = |size: fn(&Shape) -> usize| shapes.iter().map(size).max().unwrap_or(0) as f64;
    let count = ballast.count as f64;
    super::memory::check(
        &scene.path,
        format!("[ballast] count = {} stones", ballast.count),
        (
            count * largest(|s| s.mesh.nodes.len()),
            count * largest(|s| s.mesh.tets.len()),
        ),
        "lower count",
    )?;
    let mut rng = SplitMix64(ballast.seed);
    let draws = draw_stones(scene, ballast, &shapes, &mut rng)?;
    let size =
        |d: &Draw| shapes[d.shape].extents * d.scale + Vec3::repeat(2.0 * ballast.contact_radius);
    let cell = draws.iter().map(size).fold(Vec3::zeros(), |a, b| a.sup(&b)) * 1.05;
    let cells = lattice(scene, ballast, cell)?;
    let mut mesh = TetMesh::default();
    let mut info = BallastInfo {
        name: ballast.name.clone(),
        stones: Vec::with_capacity(draws.len()),
        shapes: Vec::with_capacity(draws.len()),
        sizes: Vec::with_capacity(draws.len()),
        spheres: Vec::new(),
        tets: Vec::with_capacity(draws.len()),
        centers: Vec::new(),
    };
    for (draw, centre) in draws.iter().zip(cells) {
        let shape = &shapes[draw.shape];
        let slack = 0.5 * (cell - size(draw));
        let jitter = Vec3::from_fn(|k, _| (2.0 * rng.uniform() - 1.0) * slack[k].max(0.0));
        let first = mesh.nodes.len();
        let offset = first as u32;
        let first_tet = mesh.tets.len();
        mesh.tets
            .extend(shape.mesh.tets.iter().map(|t| t.map(|n| n + offset)));
        mesh.nodes.extend(shape.mesh.nodes.iter().map(|p| {
            let x = centre + jitter + draw.turn * (Vec3::from(*p) * draw.scale);
            [x.x, x.y, x.z]
        }));
        info.spheres
            .extend(shape.surface.iter().map(|&n| ContactSphere {
                particle: start + first + n as usize,
                radius: ballast.contact_radius,
                body: first_body + info.stones.len(),
                material,
            }));
        info.stones.push(start + first..start + mesh.nodes.len());
        info.tets.push(first_tet..mesh.tets.len());
        info.shapes.push(draw.shape);
        info.sizes.push(shape.sieve() * draw.scale);
    }
    let placed = PlacedMesh {
        particles: start..start + mesh.nodes.len(),
        mesh,
        path: ballast_path(scene, ballast),
        rotation: nalgebra::UnitQuaternion::identity(),
    };
    Ok((placed, info, warnings))
}

/// Turns every stone of `info` into a rigid body (module docs): `tets` are the ballast's
/// tetrahedra as state particle indices, `density` the material's; each stone starts with the
/// velocity `v` and the angular velocity `w` about its centre of mass. Returns the rigid-body
/// index of the first stone and records each stone's centre particle in `info.centers`.
pub(crate) fn rigid_stones(
    info: &mut BallastInfo,
    tets: &[[u32; 4]],
    density: f64,
    (v, w): (Vec3, Vec3),
    state: &mut State,
) -> Result<usize, CoreError> {
    let first = state.rigid.len();
    for (k, (nodes, own)) in info.stones.iter().zip(&info.tets).enumerate() {
        let (mass, center, inertia) =
            tet_mass_properties(&state.reference, &tets[own.clone()], density);
        let c = state.push_particle(center, v, mass);
        let members: Vec<usize> = nodes.clone().collect();
        let name = format!("{} stone {}", info.name, k + 1);
        let b = state.add_rigid_body(&name, c, &members, inertia)?;
        state.rigid.set_angular_velocity(b, w);
        info.centers.push(c);
    }
    qdem_core::step::rigid_body::place_members(state);
    Ok(first)
}

/// What the output shows as the ballast's mesh: the directory of its first stone mesh.
fn ballast_path(scene: &Scene, ballast: &Ballast) -> PathBuf {
    let first = scene.resolve(&ballast.meshes[0]);
    first.parent().map(PathBuf::from).unwrap_or(first)
}

/// Reads, reorders and centres every stone mesh.
fn read_shapes(scene: &Scene, ballast: &Ballast) -> Result<(Vec<Shape>, Vec<String>), BuildError> {
    let mut shapes = Vec::with_capacity(ballast.meshes.len());
    let mut warnings = Vec::new();
    for file in &ballast.meshes {
        let path = scene.resolve(file);
        let mut mesh = read_mesh(&path, &mut warnings)?;
        mesh.reorder_for_locality();
        let nodes: Vec<Vec3> = mesh.nodes.iter().map(|p| Vec3::from(*p)).collect();
        let (lo, hi) = bounds(&nodes);
        let extents = hi - lo;
        let mut axes = [0, 1, 2];
        axes.sort_by(|&a, &b| extents[b].total_cmp(&extents[a]));
        axes.swap(1, 2);
        let mid = 0.5 * (lo + hi);
        let mut flat = Mat3::from_fn(|r, c| f64::from(u8::from(axes[r] == c)));
        if flat.determinant() < 0.0 {
            flat.row_mut(2).neg_mut();
        }
        for p in &mut mesh.nodes {
            let x = flat * (Vec3::from(*p) - mid);
            *p = [x.x, x.y, x.z];
        }
        let surface = mesh.surface_nodes();
        shapes.push(Shape {
            mesh,
            extents: Vec3::from_fn(|k, _| extents[axes[k]]),
            surface,
        });
    }
    Ok((shapes, warnings))
}

/// No turn, or half a turn about x, y or z: each keeps a laid-out stone's bounding box.
fn half_turn(rng: &mut SplitMix64) -> UnitQuaternion<f64> {
    match rng.next_u64() % 4 {
        0 => UnitQuaternion::identity(),
        k => UnitQuaternion::from_axis_angle(
            &nalgebra::Unit::new_normalize(Vec3::from_fn(|i, _| {
                f64::from(u8::from(i as u64 + 1 == k))
            })),
            std::f64::consts::PI,
        ),
    }
}

/// Shape, scale (from the grading) and turn of every stone; refuses contact spheres that
/// stick out through a scaled stone.
fn draw_stones(
    scene: &Scene,
    ballast: &Ballast,
    shapes: &[Shape],
    rng: &mut SplitMix64,
) -> Result<Vec<Draw>, BuildError> {
    let grading = match &ballast.grading {
        Some(points) => Some(
            Grading::new(points.iter().map(|p| (p[0], p[1])).collect()).map_err(|source| {
                BuildError::Ballast {
                    scene: scene.path.clone(),
                    message: format!("grading: {source}"),
                }
            })?,
        ),
        None => None,
    };
    let mut draws = Vec::with_capacity(ballast.count);
    for _ in 0..ballast.count {
        let shape = (rng.next_u64() % shapes.len() as u64) as usize;
        let scale = grading
            .as_ref()
            .map_or(1.0, |g| g.size_at(rng.uniform()) / shapes[shape].sieve());
        let turn = half_turn(rng);
        let thinnest = shapes[shape].extents.y * scale;
        if ballast.contact_radius > 0.5 * thinnest {
            return Err(BuildError::Ballast {
                scene: scene.path.clone(),
                message: format!(
                    "contact_radius = {} m is more than half the thickness {thinnest:.4e} m of a \
                     stone of shape {} scaled to {:.4e} m, so its spheres stick out through the \
                     other side: use a radius of at most {:.4e} m or a grading of larger stones",
                    ballast.contact_radius,
                    ballast.meshes[shape].display(),
                    shapes[shape].sieve() * scale,
                    0.5 * thinnest
                ),
            });
        }
        draws.push(Draw { shape, scale, turn });
    }
    Ok(draws)
}

/// The `exclude` box and, in a periodic cell, its images one period away on each periodic
/// axis (so a lattice that starts off the cell keeps clear of the box's image too).
fn exclude_images(scene: &Scene, ballast: &Ballast) -> Result<Vec<[Vec3; 2]>, BuildError> {
    let Some([a, b]) = ballast.exclude.map(|e| e.map(Vec3::from)) else {
        return Ok(Vec::new());
    };
    let mut images = vec![[a, b]];
    if let Some(p) = &scene.periodic {
        let cell = super::periodic::periodic_box(scene, p)?;
        for k in 0..3 {
            let Some(length) = cell.length(k) else {
                continue;
            };
            let shift = Vec3::from_fn(|i, _| if i == k { length } else { 0.0 });
            let copies: Vec<[Vec3; 2]> = images
                .iter()
                .flat_map(|[a, b]| [[a - shift, b - shift], [a + shift, b + shift]])
                .collect();
            images.extend(copies);
        }
    }
    Ok(images)
}

/// Centres of the first `count` free lattice cells of size `cell` in `region`, bottom layer
/// first; refuses a region that holds fewer.
fn lattice(scene: &Scene, ballast: &Ballast, cell: Vec3) -> Result<Vec<Vec3>, BuildError> {
    let [lo, hi] = ballast.region.map(Vec3::from);
    let n = (hi - lo).component_div(&cell).map(|e| e.floor() as usize);
    let half = 0.5 * cell;
    let planes: Vec<(Vec3, Vec3)> = scene
        .walls
        .iter()
        .filter_map(|w| Some((Vec3::from(w.point?), Vec3::from(w.normal?).normalize())))
        .collect();
    let images = exclude_images(scene, ballast)?;
    let clear_of_exclude = |c: &Vec3| {
        images
            .iter()
            .all(|[a, b]| (0..3).any(|k| c[k] + half[k] <= a[k] || c[k] - half[k] >= b[k]))
    };
    let inside_walls = |c: &Vec3| {
        planes
            .iter()
            .all(|(p, nrm)| (c - p).dot(nrm) >= nrm.abs().dot(&half))
    };
    let free: Vec<Vec3> = (0..n.z)
        .flat_map(|k| (0..n.y).flat_map(move |j| (0..n.x).map(move |i| (i, j, k))))
        .map(|(i, j, k)| {
            lo + Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5).component_mul(&cell)
        })
        .filter(|c| clear_of_exclude(c) && inside_walls(c))
        .collect();
    if free.len() < ballast.count {
        let per_layer = free.len() as f64 / n.z.max(1) as f64;
        let needed = lo.z + (ballast.count as f64 / per_layer.max(1.0)).ceil() * cell.z;
        return Err(BuildError::Ballast {
            scene: scene.path.clone(),
            message: format!(
                "region holds only {} of the {} stones on a lattice of {:.3} x {:.3} x {:.3} m \
                 cells (the largest stone extents with their contact spheres, 5% spare) clear \
                 of `exclude` and the walls: make it taller (upper z about {needed:.3} m) or \
                 wider, or ask for fewer stones",
                free.len(),
                ballast.count,
                cell.x,
                cell.y,
                cell.z
            ),
        });
    }
    Ok(free.into_iter().take(ballast.count).collect())
}
