//! The data types of a scene: what a scene file deserializes into, one module per table (as
//! `validate/`), each key declared once by `scene_table!`: its field with the serde
//! attributes, and its entry of the key reference ([`super::keys`]) with the key's type,
//! default and meaning, which is also the field's documentation.
//!
//! Most tables deserialize straight into their public type. `[[fix]]` and `[[load]]` go through
//! private raw forms first, because their `group`/`box` pair becomes a single [`Selection`] and
//! their `dofs`/`ramp` are checked and normalised; that happens during
//! validation ([`super::Scene::parse`]).

use serde::Deserialize;

/// Declares a table's struct and its keys at once: each field is written
///
/// ```text
/// #[serde(...)]                      // the field's serde attributes, as for any field
/// field [as "key"]: Type => "type", required | optional [= "default"], "meaning";
/// ```
///
/// and becomes `pub field: Type` documented by its meaning (renamed to `key` for serde when
/// given), and an entry of the table's `KEYS`: `[table] key`, `type, required` (or
/// `optional`), the default as a TOML value (what serde fills in when the key is absent;
/// `keys.rs`'s tests check it against serde), and the meaning. An optional key without a
/// default must be an `Option` (checked at compile time).
macro_rules! scene_table {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident in $table:literal {
            $(
                $(#[$field_meta:meta])*
                $field:ident $(as $key:literal)? : $ty:ty =>
                    $kind:literal, $presence:ident $(= $default:literal)?, $meaning:literal;
            )*
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $(
                #[doc = $meaning]
                $(#[$field_meta])*
                $(#[serde(rename = $key)])?
                pub $field: $ty,
            )*
        }

        impl $name {
            /// The scene keys of this table, in the order of its fields.
            pub(crate) const KEYS: &'static [$crate::scene::keys::SceneKey] = &[$(
                $crate::scene::keys::SceneKey {
                    table: $table,
                    key: scene_table!(@key $field $($key)?),
                    kind: concat!($kind, ", ", stringify!($presence)),
                    default: scene_table!(@default $($default)?),
                    meaning: $meaning,
                },
            )*];
        }

        $(scene_table!(@presence $ty, $presence $(, $default)?);)*
    };
    (@key $field:ident) => { stringify!($field) };
    (@key $field:ident $key:literal) => { $key };
    (@default) => { None };
    (@default $default:literal) => { Some($default) };
    (@presence $ty:ty, required) => {};
    (@presence $ty:ty, optional, $default:literal) => {};
    (@presence $ty:ty, optional) => {
        const _: fn(&$ty) -> bool = <$ty>::is_none;
    };
}

mod ballast;
mod body;
mod bonded;
mod contact;
mod fix_load;
mod granular;
mod material;
mod measure;
mod output;
mod periodic;
mod probe_section;
mod run;

pub use ballast::Ballast;
pub use body::Body;
pub use bonded::{Bonded, EventSolveName, PackingName, Supports};
pub use contact::{Contact, ContactLawName, Wall, WallServo, WallStart};
pub use fix_load::{AreaLoad, CyclicLoad, Fix, FixFrame, Load, Ramp, Selection, Series};
pub(crate) use fix_load::{FrameName, RawFix, RawFrame, RawLoad};
pub use granular::{ClumpShapeName, GradingBasisName, Granular};
pub use material::{Formulation, Material};
pub use measure::{Measure, MeasureRegion};
pub use output::Output;
pub use periodic::{Periodic, TimeDelay};
pub use probe_section::{Probe, Section};
pub(crate) use run::DT_MESSAGE;
pub use run::{Integrator, Run, TimeStep};

/// The whole file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub run: Run,
    #[serde(default, rename = "material")]
    pub materials: Vec<Material>,
    #[serde(default, rename = "body")]
    pub bodies: Vec<Body>,
    #[serde(default, rename = "fix")]
    pub fixes: Vec<RawFix>,
    #[serde(default, rename = "load")]
    pub loads: Vec<RawLoad>,
    #[serde(default, rename = "probe")]
    pub probes: Vec<Probe>,
    #[serde(default, rename = "section")]
    pub sections: Vec<Section>,
    #[serde(default, rename = "measure")]
    pub measures: Vec<Measure>,
    #[serde(default)]
    pub contact: Option<Contact>,
    #[serde(default, rename = "wall")]
    pub walls: Vec<Wall>,
    #[serde(default)]
    pub bonded: Option<Bonded>,
    #[serde(default)]
    pub periodic: Option<Periodic>,
    #[serde(default)]
    pub granular: Option<Granular>,
    #[serde(default)]
    pub ballast: Option<Ballast>,
    #[serde(default)]
    pub output: Output,
}

/// Top-level keys that are arrays of tables (`[[name]]`), for messages.
pub(crate) const ARRAY_TABLES: &[&str] = &[
    "material", "body", "fix", "load", "probe", "section", "wall",
];

/// `seed` of `[granular]` and `[ballast]` when the scene gives none.
fn default_seed() -> u64 {
    1
}
