//! Post-processing: what is made of a run's outputs — the dominant frequency of a probe record
//! ([`spectrum`]), Parzen-smoothed linear spectra and mobility of a run's sensors ([`analyze`],
//! [`linear_spectrum`], paper 000 §4.2, `qdem analyze`), the SVG line plots beside the CSVs
//! ([`plot`]) with the natural frequencies of `qdem modes` marked on them ([`mode_marks`]),
//! and a bonded body's crack picture ([`crack_svg`]).

pub mod analyze;
pub mod contact_stress;
pub mod crack_svg;
pub mod linear_spectrum;
pub mod mode_marks;
pub mod modes;
pub mod plot;
pub mod sieve;
pub mod spectrum;
