//! Rigid walls: planes ([`plane_wall`]), triangulated meshes ([`mesh_wall`]), the wall of a
//! scene ([`wall`]) and the stress-controlled servo that drives one ([`servo_wall`]).

pub mod mesh_wall;
pub mod plane_wall;
pub mod servo_wall;
pub mod wall;
