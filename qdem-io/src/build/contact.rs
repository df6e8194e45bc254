//! Building the contact model of a scene: spheres at the surface vertices of every body with a
//! `contact_radius` (interior vertices never touch anything, paper 000 §4), the `[contact]`
//! law, and the `[[wall]]`s. A scene in which nothing can touch (no sphere, or the spheres of a
//! single body and no wall) gets no contact model, and the initial configuration is checked
//! for interpenetration before anything runs ([`check_start`]; for a `[run] start_from`
//! stage, once its state and walls are the checkpoint's).

use super::ballast::BallastInfo;
use crate::build::{BuildError, PlacedMesh};
use crate::scene::{Contact, ContactLawName, Scene};
use qdem_contact::dem::broad_phase::bounds;
use qdem_contact::dem::contacts::BodySurface;
use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, DemContacts, HertzMindlin, LinearSpring, MeshWall,
    PeriodicBox, PlaneWall, Wall, WallShape,
};
use qdem_core::{step::State, Vec3};
use qdem_mesh::read_msh;

/// Spheres that do not come from mesh bodies (the stones of `[granular]`), their bodies'
/// names, and the periodic cell.
#[derive(Default)]
pub(crate) struct ExtraSpheres {
    pub(crate) spheres: Vec<ContactSphere>,
    pub(crate) names: Vec<String>,
    pub(crate) periodic: Option<PeriodicBox>,
}

impl ExtraSpheres {
    /// The contact spheres of the `[ballast]` stones, each stone a body of its own named
    /// `<ballast> stone <k>`.
    pub(crate) fn of_ballast(ballast: Option<&BallastInfo>) -> ExtraSpheres {
        let mut extra = ExtraSpheres::default();
        if let Some(info) = ballast {
            extra.spheres.clone_from(&info.spheres);
            extra.names = (1..=info.stones.len())
                .map(|k| format!("{} stone {k}", info.name))
                .collect();
        }
        extra
    }
}

/// The contact model, or `None` when no body has contact spheres.
pub(crate) fn build_contacts(
    scene: &Scene,
    meshes: &[PlacedMesh],
    state: &State,
    extra: ExtraSpheres,
) -> Result<Option<DemContacts>, BuildError> {
    let Some(contact) = &scene.contact else {
        return Ok(None);
    };
    let (mut spheres, surfaces) = contact_spheres(scene, meshes)?;
    spheres.extend(extra.spheres);
    let single_body = spheres.windows(2).all(|w| w[0].body == w[1].body);
    if spheres.is_empty() || (single_body && scene.walls.is_empty()) {
        return Ok(None);
    }
    let materials: Vec<(f64, f64)> = scene
        .materials
        .iter()
        .map(|m| (m.young, m.poisson))
        .collect();
    let r_min = spheres
        .iter()
        .map(|s| s.radius)
        .fold(f64::INFINITY, f64::min);
    let settings = ContactSettings {
        law: law(contact),
        friction: contact.friction,
        skin: contact.skin.unwrap_or(0.25 * r_min),
    };
    let walls = walls(scene, contact)?;
    let names = scene
        .bodies
        .iter()
        .map(|b| b.name.clone())
        .chain(extra.names)
        .collect();
    let contact_error = |source| BuildError::Contact {
        scene: scene.path.clone(),
        source: Box::new(source),
    };
    let mut model = DemContacts::new(state, &spheres, names, &materials, settings, walls)
        .with_body_surfaces(surfaces)
        .with_rolling_friction(contact.rolling_friction)
        .map_err(contact_error)?;
    if let (Some(cell), Some(periodic)) = (extra.periodic, &scene.periodic) {
        model = super::periodic::periodic_contacts(scene, periodic, &cell, model)?;
    }
    for (w, wall) in scene.walls.iter().enumerate() {
        if let Some(servo) = &wall.servo {
            let servo = servo.servo().map_err(|source| BuildError::Core {
                scene: scene.path.clone(),
                source,
            })?;
            model.set_servo(w, servo).map_err(contact_error)?;
        }
    }
    // A stage's bodies and walls are where its checkpoint left them: checked once there.
    if scene.run.start_from.is_none() {
        check_start(scene, &mut model, state, |_| true)?;
    }
    Ok(Some(model))
}

/// Refuses bodies that start overlapping each other or a wall beyond `overlap_tolerance`, or
/// inside another body or a mesh wall, at the positions of `state` (a `start_from` stage's:
/// the checkpoint's, with its walls where they begin). Two bodies' overlap is checked only
/// when `placed` holds for a particle carrying one of them: a `start_from` stage places only
/// its walls and the bodies whose kind it changes; the rest overlap as the checkpoint's
/// contacts left them.
pub(crate) fn check_start(
    scene: &Scene,
    model: &mut DemContacts,
    state: &State,
    placed: impl Fn(usize) -> bool,
) -> Result<(), BuildError> {
    let start_error = |source| match super::overlap_advice::advice(scene, &source) {
        Some(fix) => BuildError::InitialOverlap {
            scene: scene.path.clone(),
            source: Box::new(source),
            fix,
        },
        None => BuildError::Contact {
            scene: scene.path.clone(),
            source: Box::new(source),
        },
    };
    let tolerance = scene.contact.as_ref().map_or(0.0, |c| c.overlap_tolerance);
    model
        .check_placed_overlaps(state, tolerance, placed)
        .map_err(start_error)?;
    model.check_initial_passage(state).map_err(start_error)
}

fn law(contact: &Contact) -> ContactLaw {
    match contact.law {
        ContactLawName::Linear => ContactLaw::Linear(LinearSpring {
            normal_stiffness: contact.normal_stiffness.expect("validated scene"),
            tangential_stiffness: contact.tangential_stiffness.expect("validated scene"),
            damping_ratio: contact.damping(),
        }),
        ContactLawName::HertzMindlin => ContactLaw::HertzMindlin(HertzMindlin {
            damping_ratio: contact.damping(),
        }),
    }
}

/// A sphere at every surface vertex of every body with a contact radius, and each such
/// body's surface as triangles of its spheres; refuses a radius larger than half the body's
/// smallest extent.
fn contact_spheres(
    scene: &Scene,
    meshes: &[PlacedMesh],
) -> Result<(Vec<ContactSphere>, Vec<BodySurface>), BuildError> {
    let (mut spheres, mut surfaces) = (Vec::new(), Vec::new());
    let materials = &scene.refs().body_materials;
    for (b, (body, &material)) in scene.bodies.iter().zip(materials).enumerate() {
        let Some(radius) = body.contact_radius else {
            continue;
        };
        let placed = &meshes[b];
        let extent = smallest_extent(&placed.mesh.nodes);
        if radius > 0.5 * extent {
            return Err(BuildError::ContactRadius {
                scene: scene.path.clone(),
                body: body.name.clone(),
                radius,
                extent,
                limit: 0.5 * extent,
            });
        }
        let nodes = placed.mesh.surface_nodes();
        surfaces.push(surface(
            b,
            spheres.len(),
            &nodes,
            &placed.mesh.surface_triangles(),
        ));
        spheres.extend(nodes.into_iter().map(|n| ContactSphere {
            particle: placed.particles.start + n as usize,
            radius,
            body: b,
            material,
        }));
    }
    Ok((spheres, surfaces))
}

/// Body `body`'s surface `triangles` (of mesh nodes) as triangles of its spheres, the first
/// of which is sphere `first`, one per node of `nodes` (sorted).
fn surface(body: usize, first: usize, nodes: &[u32], triangles: &[[u32; 3]]) -> BodySurface {
    let local = |n: u32| nodes.binary_search(&n).expect("a surface node") as u32;
    BodySurface {
        body,
        spheres: (first..first + nodes.len()).map(|s| s as u32).collect(),
        triangles: triangles.iter().map(|t| t.map(local)).collect(),
    }
}

fn smallest_extent(nodes: &[[f64; 3]]) -> f64 {
    let points: Vec<Vec3> = nodes.iter().map(|p| Vec3::from(*p)).collect();
    let (lower, upper) = bounds(&points);
    (upper - lower).min()
}

/// The scene's walls: planes, and meshes whose boundary triangles are the wall.
fn walls(scene: &Scene, contact: &Contact) -> Result<Vec<Wall>, BuildError> {
    scene
        .walls
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let velocity = Vec3::from(w.velocity);
            let shape = match (&w.point, &w.normal, &w.mesh) {
                (Some(p), Some(n), _) => {
                    WallShape::Plane(PlaneWall::new(Vec3::from(*p), Vec3::from(*n), velocity))
                }
                (_, _, Some(mesh)) => {
                    let path = scene.wall_mesh_path(mesh);
                    let (tets, _) = read_msh(&path)?;
                    let vertices: Vec<Vec3> = tets.nodes.iter().map(|p| Vec3::from(*p)).collect();
                    let name = format!("[[wall]] #{} ({})", i + 1, path.display());
                    let wall = MeshWall::new(&name, &vertices, &tets.surface_triangles(), velocity)
                        .map_err(|source| BuildError::Contact {
                            scene: scene.path.clone(),
                            source: Box::new(source),
                        })?;
                    WallShape::Mesh(Box::new(wall))
                }
                _ => unreachable!("validated scene: a wall is a plane or a mesh"),
            };
            Ok(Wall {
                shape,
                friction: w.friction.unwrap_or(contact.friction),
            })
        })
        .collect()
}
