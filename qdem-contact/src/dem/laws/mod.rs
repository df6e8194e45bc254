//! The contact laws: what a law sees of a contact ([`contact_law`]), the linear Voigt spring
//! ([`linear_spring`], paper 000 §4), Hertz–Mindlin ([`hertz_mindlin`], paper 003 §3), the
//! tangential spring with its Coulomb slider both share ([`coulomb`]) and the rolling
//! resistance either may add ([`rolling_resistance`], Ai et al. 2011 model C). `law_lanes` runs
//! both laws with their Coulomb springs across SIMD lanes, to the same bits.

pub mod contact_law;
pub mod coulomb;
pub mod hertz_mindlin;
pub(crate) mod law_lanes;
pub mod linear_spring;
pub mod rolling_resistance;
