//! The deformable bodies and their kernel: the QDEM tetrahedron of paper 000 (Eqs. 1–11) in
//! [`tet_kernel`] (across SIMD lanes in [`tet_lanes`]), its literal 12-triangle oracle in
//! [`tet_subdomain`], the deformable body ([`tet_body::TetBody`]) and its blocks
//! ([`tet_blocks`], the block pass's optional software [`prefetch`]), the linear-tet stiffness ([`linear_tet`]), [`material`]s and the rigorous
//! explicit step bound ([`stable_step`]); the locking-free average nodal pressure option in
//! [`averaged_pressure_tet`] (across SIMD lanes in [`averaged_pressure_lanes`]). Rigid bodies are part of the state
//! ([`crate::step::rigid_body`]).

pub mod averaged_pressure_lanes;
pub mod averaged_pressure_tet;
pub mod linear_tet;
pub mod material;
pub mod prefetch;
pub mod stable_step;
pub mod tet_blocks;
pub mod tet_body;
pub mod tet_kernel;
pub mod tet_lanes;
pub mod tet_subdomain;

pub use averaged_pressure_tet::Formulation;
pub use material::Material;
pub use tet_blocks::BlockLayout;
pub use tet_body::TetBody;
