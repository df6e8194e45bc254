//! Box-test boundaries (paper 003): periodic cells with minimum-image contacts
//! ([`periodic_boundary`]), bodies wrapped back into the cell ([`periodic_wrap`]) and the
//! time-delayed boundary (Eqs. 2–7, [`time_delayed_boundary`]).

pub mod periodic_boundary;
pub mod periodic_wrap;
pub mod time_delayed_boundary;
