//! Rigid-body poses carried from one run to the next: a run's `poses.csv` and
//! `[[body]] pose_from`.
//!
//! Paper 003 §3 lays its sleepers in a deposited sample and loads them where the deposition
//! left them. Here the deposition is one run and the loading another, so the sleeper's place
//! must travel between them: every run with rigid `[[body]]`s writes `poses.csv`
//! ([`write_poses_csv`]), one row per rigid body, `body,x,y,z,qw,qx,qy,qz`: its centre of
//! mass c (m) and the rotation Q (unit quaternion) that takes the body from its *design
//! placement* (its mesh after `rotate_deg` and `translate`) to where it is now. A later scene
//! whose body of the same name has `pose_from = "…/poses.csv"` is placed there exactly: each
//! node x of the design placement goes to
//!
//! x′ = c + Q (x − c_d),
//!
//! c_d the design placement's centre of mass. `pose_body` takes another body's row instead
//! and `pose_shift` s moves its centre, x′ = c + s + Q (x − c_d): the three sleepers of a box
//! three cells long placed from the one sleeper of a periodic cell, a period apart (the body
//! turns by Q from its *own* design placement, so the two bodies must share a mesh and design
//! orientation for the copy to be exact). Q is kept against the design
//! placement, not the run's start, so poses chain through any number of runs: a run whose
//! body started at pose Q_p and whose principal frame has turned from q(0) to q(t) writes
//! Q = q(t) q(0)⁻¹ Q_p ([`crate::build::BodyKind::Rigid`] keeps Q_p⁻¹ q(0) as its design
//! frame).
//!
//! `rest_on` cannot do this: it lowers a body until its first contact sphere touches a stone,
//! and a sleeper that settled during the deposition has crib stones nestled against its sides
//! that stop it before it reaches the bed again.

use crate::build::{BodyKind, BuildError, PlacedMesh, Simulation};
use crate::csv_rows::{finite, read_text, rows};
use crate::output::{write_atomic, OutputError};
use crate::scene::Scene;
use nalgebra::{Quaternion, UnitQuaternion};
use qdem_core::step::rigid_body::tet_mass_properties;
use qdem_core::Vec3;
use std::path::Path;

/// The header of a poses file.
pub const POSES_HEADER: &str = "body,x,y,z,qw,qx,qy,qz";

/// One row of a poses file: a body's centre of mass and its rotation from its design placement.
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    /// Body name.
    pub body: String,
    /// Centre of mass (m).
    pub center: Vec3,
    /// Rotation from the design placement.
    pub rotation: UnitQuaternion<f64>,
}

/// Moves every body with `pose_from` to its pose in that file (module docs) and records, per
/// body, the rotation it was given (identity for the others).
pub(crate) fn pose_bodies(scene: &Scene, meshes: &mut [PlacedMesh]) -> Result<(), BuildError> {
    for (body, placed) in scene.bodies.iter().zip(meshes.iter_mut()) {
        let Some(file) = &body.pose_from else {
            continue;
        };
        let path = scene.resolve(file);
        let source = body.pose_body.as_ref().unwrap_or(&body.name);
        let pose = read_poses_csv(&path)?
            .into_iter()
            .find(|p| &p.body == source)
            .ok_or_else(|| BuildError::PoseMissing {
                scene: scene.path.clone(),
                body: source.clone(),
                path: path.clone(),
            })?;
        let center = pose.center + Vec3::from(body.pose_shift);
        let nodes: Vec<Vec3> = placed.mesh.nodes.iter().map(|&p| Vec3::from(p)).collect();
        let (_, design_center, _) = tet_mass_properties(&nodes, &placed.mesh.tets, 1.0);
        for (p, x) in placed.mesh.nodes.iter_mut().zip(&nodes) {
            *p = (center + pose.rotation * (x - design_center)).into();
        }
        placed.rotation = pose.rotation;
    }
    Ok(())
}

/// Reads a poses file; every malformed line is refused with its number.
pub fn read_poses_csv(path: &Path) -> Result<Vec<Pose>, BuildError> {
    let bad = |line: usize, message: String| BuildError::Poses {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = read_text(path, POSES_HEADER, &bad)?;
    let mut poses = Vec::new();
    for (n, fields) in rows(&text, 8, &bad)? {
        let v: [f64; 7] = finite(&fields[1..], n, &bad)?;
        let q = Quaternion::new(v[3], v[4], v[5], v[6]);
        if (q.norm() - 1.0).abs() > 1e-9 {
            return Err(bad(
                n,
                format!(
                    "the rotation ({}, {}, {}, {}) is no unit quaternion",
                    v[3], v[4], v[5], v[6]
                ),
            ));
        }
        poses.push(Pose {
            body: fields[0].to_string(),
            center: Vec3::new(v[0], v[1], v[2]),
            rotation: UnitQuaternion::new_normalize(q),
        });
    }
    Ok(poses)
}

/// The pose of every rigid `[[body]]` of `sim` now (module docs).
pub fn poses(sim: &Simulation) -> Vec<Pose> {
    let rigid = &sim.world.state.rigid;
    sim.bodies
        .iter()
        .filter_map(|b| match &b.kind {
            BodyKind::Rigid {
                body,
                center,
                design_frame,
                ..
            } => Some(Pose {
                body: b.name.clone(),
                center: sim.world.state.position[*center],
                rotation: rigid.orientation[*body] * design_frame.inverse(),
            }),
            BodyKind::Deformable { .. } | BodyKind::Stones { .. } => None,
        })
        .collect()
}

/// Writes `poses` to `path` (atomically), in the format [`read_poses_csv`] reads.
pub fn write_poses_csv(path: &Path, poses: &[Pose]) -> Result<(), OutputError> {
    write_atomic(path, |w| {
        writeln!(w, "{POSES_HEADER}")?;
        for p in poses {
            let (c, q) = (p.center, p.rotation.quaternion());
            writeln!(
                w,
                "{},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e}",
                p.body, c.x, c.y, c.z, q.w, q.i, q.j, q.k
            )?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_poses_file_reads_back_what_was_written() {
        let dir = std::env::temp_dir().join(format!("qdem_poses_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("poses.csv");
        let pose = Pose {
            body: "sleeper2".into(),
            center: Vec3::new(0.15, 1.05, 0.3193801485389452),
            rotation: UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3),
        };
        write_poses_csv(&path, std::slice::from_ref(&pose)).unwrap();
        let back = read_poses_csv(&path).unwrap();
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].body, pose.body);
        assert_eq!(back[0].center, pose.center);
        assert!(back[0].rotation.angle_to(&pose.rotation) < 1e-15);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_malformed_poses_line_is_refused_with_its_number() {
        let dir = std::env::temp_dir().join(format!("qdem_poses_bad_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("poses.csv");
        std::fs::write(
            &path,
            format!("{POSES_HEADER}\na,0,0,0,1,0,0,0\nb,0,0,0,2,0,0,0\n"),
        )
        .unwrap();
        let err = read_poses_csv(&path).unwrap_err().to_string();
        assert!(
            err.contains("poses.csv:3:") && err.contains("unit quaternion"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
