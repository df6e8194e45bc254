//! DEM contacts: the contact model ([`contacts::DemContacts`]), its broad phase, candidate
//! lists and output views, the contact laws ([`laws`]) and the walls ([`walls`]).

pub mod broad_phase;
pub(crate) mod contact_list;
pub mod contact_view;
pub mod contacts;
pub mod laws;
pub(crate) mod spring_blocks;
pub mod walls;
