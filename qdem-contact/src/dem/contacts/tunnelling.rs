//! The pass-through check: a contact sphere whose centre has gone through a wall or into
//! another body. A contact holds two surfaces apart only while the sphere's centre stays on
//! its side: a centre beyond a plane wall's plane, inside a mesh wall's solid, or deeper than
//! its own radius inside another body's mesh (between that body's spheres, which sit at its
//! surface vertices only and leave gaps), is pushed on through, or feels nothing at all. A
//! block dropped at 40 and 200 m/s on `fixtures/contact/ramp.msh` (a slab 5 cm thick) ended
//! 0.25–0.30 m below it, and a small body fell through the gaps between a block's spheres at
//! an unchanged speed, both silently.
//!
//! When: at every rebuild of the candidate lists, before it, where every sphere's centre is
//! current (on a rank of a decomposed run, for the spheres it owns); the lists are rebuilt as
//! soon as some sphere has moved half the skin since the last build, so between two checks a
//! sphere moves at most half the skin (a quarter of the smallest radius by default) plus one
//! step. A centre that goes into a wall or a body therefore shows up at a check while it is
//! inside, unless it crosses the whole wall in that last step: for walls the straight path
//! since the last build is tested against the mesh too (for a plane, a centre beyond it is
//! beyond it however fast it went). The check reads the positions only, so results stay
//! bit-identical; its cost is that of a broad phase's wall test again at each rebuild, plus a
//! point query per sphere inside a body's bounding box, and a pass over the lists' pairs for
//! a stone's sphere overlapping another body's by more than the smaller radius (which no
//! surface sees: a clump's volume is its spheres), on one process and over ranks alike. What it leaves: a body thinner
//! than twice a sphere radius plus a step's motion, crossed between two checks.
//!
//! The first finding is kept and reported by [`qdem_core::step::Model::failure`] after the step, so
//! the world stops the run (in a decomposed run every rank agrees on it).

use super::*;
use crate::dem::broad_phase::bounds;
use crate::dem::walls::mesh_wall::oriented;
use crate::dem::walls::wall::WallShape;
use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;

/// Above this motion per step, as a fraction of the sphere radius, a smaller dt is the fix
/// (as for the interpenetration watch of `qdem-io`).
const STEP_FRACTION: f64 = 0.5;

/// The closed surface of a body's mesh as triangles of its contact spheres, whose centres
/// are the mesh's surface vertices.
#[derive(Clone, Debug)]
pub struct BodySurface {
    /// The body (index into the body names).
    pub body: usize,
    /// The spheres at its surface vertices.
    pub spheres: Vec<u32>,
    /// Its surface triangles, as indices into `spheres`.
    pub triangles: Vec<[u32; 3]>,
}

/// Where a sphere's centre went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Passage {
    /// Beyond a plane wall (by `depth`), inside a mesh wall (by `depth`), or across a mesh
    /// wall's surface since the last check (`depth` zero).
    Wall {
        /// The sphere.
        sphere: usize,
        /// The wall.
        wall: usize,
        /// How far inside (m).
        depth: f64,
    },
    /// Inside another body's mesh by more than its radius.
    Body {
        /// The sphere.
        sphere: usize,
        /// The other body (index into the body names).
        other: usize,
        /// How far inside (m).
        depth: f64,
    },
}

/// Two spheres of different bodies overlapping by more than the smaller radius: the centre
/// of `sphere` is inside `other`, and once the centres cross the contact pulls the two
/// through each other.
#[derive(Clone, Copy, Debug)]
struct DeepPair {
    sphere: usize,
    other: usize,
    /// The overlap (m).
    depth: f64,
}

/// The check for spheres gone through a wall or into another body: the bodies' surfaces,
/// the first pass-through found, and the run's step for its report.
#[derive(Default)]
pub(super) struct PassageCheck {
    /// The closed surfaces of the bodies built from meshes.
    surfaces: Vec<BodySurface>,
    /// The report of the first sphere found through a wall or inside another body: what
    /// happened, and the fix.
    pass_through: Option<(String, String)>,
    /// The run's step (s), for that report's fix; 0 until [`qdem_core::step::Model::prepare`].
    step: f64,
}

impl PassageCheck {
    /// The run's step (s), for the report's fix.
    pub(super) fn set_step(&mut self, step: f64) {
        self.step = step;
    }

    /// The run's step (s); 0 until [`qdem_core::step::Model::prepare`].
    pub(super) fn step(&self) -> f64 {
        self.step
    }

    /// Renumbers the spheres (`spatial_order.rs`): the sphere of slot `t` goes to `to[t]`.
    pub(super) fn renumber(&mut self, to: &[u32]) {
        for s in self
            .surfaces
            .iter_mut()
            .flat_map(|surface| &mut surface.spheres)
        {
            *s = to[*s as usize];
        }
    }
}

impl DemContacts {
    /// The surfaces of the bodies built from meshes, for the check of a centre inside
    /// another body.
    pub fn with_body_surfaces(mut self, mut surfaces: Vec<BodySurface>) -> DemContacts {
        for s in surfaces.iter_mut().flat_map(|surface| &mut surface.spheres) {
            *s = self.slot_of(*s as usize) as u32;
        }
        self.passage.surfaces = surfaces;
        self
    }

    /// Before a rebuild at `time` (every centre current, the last build's at `built_at`):
    /// keeps the first sphere of `own` (all spheres when `None`) found through a wall or
    /// inside another body, else the first pair of the lists overlapping past a radius
    /// ([`DemContacts::deep_pair`]), with the report [`qdem_core::step::Model::failure`] gives.
    pub(super) fn check_passage(&mut self, time: f64, own: Option<&[u32]>) {
        if self.passage.pass_through.is_some() {
            return;
        }
        let all: Vec<u32>;
        let spheres = match own {
            Some(own) => own,
            None => {
                all = (0..self.spheres.len() as u32).collect();
                &all
            }
        };
        let since = self.lists_built().then_some(self.candidates.built_time());
        self.passage.pass_through = match self.find_passage(spheres, time, since) {
            Some(passage) => Some(self.describe(passage, time)),
            None => self.deep_pair().map(|pair| self.describe_deep(pair, time)),
        };
    }

    /// The first of `spheres` whose centre is through a wall or inside another body at
    /// `time`; with `since`, the time of the last build, also one whose path since then
    /// crossed a mesh wall.
    pub(crate) fn find_passage(
        &self,
        spheres: &[u32],
        time: f64,
        since: Option<f64>,
    ) -> Option<Passage> {
        let walls = spheres
            .par_iter()
            .with_min_len(CONTACT_CHUNK)
            .find_map_first(|&s| self.through_wall(s as usize, time, since));
        walls.or_else(|| {
            self.passage
                .surfaces
                .iter()
                .find_map(|surface| self.inside_body(surface, spheres))
        })
    }

    /// The first pair of the lists (a rank's, in a decomposed run, whose centres are all
    /// current before a rebuild) whose spheres overlap by more than the smaller radius. Between
    /// two rebuilds a sphere moves at most half the skin (a quarter of the smallest radius by
    /// default), so a pair found at one rebuild under that depth cannot have crossed its
    /// centres by the next: the check stops it while the contact still pushes the right way.
    /// A pair of two bodies built from meshes is left to the run's interpenetration watch
    /// (`qdem-io`, every step, `[[body]]`s on one process), which reports it with its cause;
    /// this covers every pair with a stone's sphere (`[granular]`, `[ballast]`), on one
    /// process and over ranks.
    fn deep_pair(&self) -> Option<DeepPair> {
        let center = self.spheres.center();
        let radius = self.spheres.radius();
        let body = self.spheres.body();
        let mut meshed = vec![false; self.spheres.body_names().len()];
        for surface in &self.passage.surfaces {
            meshed[surface.body] = true;
        }
        self.candidates.pairs().items.iter().find_map(|c| {
            let (a, b) = (c.first as usize, c.second as usize);
            if meshed[body[a] as usize] && meshed[body[b] as usize] {
                return None;
            }
            let mut d = center[b] - center[a];
            if let Some(p) = &self.periodic {
                d += p.image_shift(&d);
            }
            let depth = radius[a] + radius[b] - d.norm();
            (depth > radius[a].min(radius[b])).then_some(DeepPair {
                sphere: a,
                other: b,
                depth,
            })
        })
    }

    /// The first wall sphere `s` went into or through.
    fn through_wall(&self, s: usize, time: f64, since: Option<f64>) -> Option<Passage> {
        let x = self.spheres.center()[s];
        self.walls.list().iter().enumerate().find_map(|(w, wall)| {
            let depth = match &wall.shape {
                WallShape::Plane(p) => Some(-p.distance(&x, time)).filter(|d| *d > 0.0),
                WallShape::Mesh(m) => m.depth_inside(&x, time).or_else(|| {
                    let from = x - self.moved_since_build(s);
                    m.crossed((&from, since?), (&x, time)).then_some(0.0)
                }),
            };
            depth.map(|depth| Passage::Wall {
                sphere: s,
                wall: w,
                depth,
            })
        })
    }

    /// Sphere `s`'s displacement since the last build (the minimum image when periodic);
    /// zero before the lists were built.
    fn moved_since_build(&self, s: usize) -> Vec3 {
        if !self.lists_built() {
            return Vec3::zeros();
        }
        let d = self.spheres.center()[s] - self.candidates.built_at()[s];
        match &self.periodic {
            Some(p) => d + p.image_shift(&d),
            None => d,
        }
    }

    /// The first of `spheres`, of another body, whose centre lies inside `surface` (at its
    /// spheres' centres now) deeper than its radius.
    fn inside_body(&self, surface: &BodySurface, spheres: &[u32]) -> Option<Passage> {
        let vertices: Vec<Vec3> = surface
            .spheres
            .iter()
            .map(|&s| self.spheres.center()[s as usize])
            .collect();
        let (lower, upper) = bounds(&vertices);
        let inside_box = |s: &u32| {
            let (s, x) = (*s as usize, self.spheres.center()[*s as usize]);
            self.spheres.body()[s] as usize != surface.body
                && (0..3).all(|k| {
                    x[k] > lower[k] + self.spheres.radius()[s]
                        && x[k] < upper[k] - self.spheres.radius()[s]
                })
        };
        let candidates: Vec<u32> = spheres.iter().copied().filter(inside_box).collect();
        if candidates.is_empty() {
            return None;
        }
        let mesh = oriented(&vertices, &surface.triangles)?;
        candidates.into_iter().find_map(|s| {
            let x = self.spheres.center()[s as usize];
            let projection = mesh.project_local_point(Vector::new(x.x, x.y, x.z), false);
            let p = projection.point;
            let depth = (Vec3::new(p.x, p.y, p.z) - x).norm();
            (projection.is_inside && depth > self.spheres.radius()[s as usize]).then_some(
                Passage::Body {
                    sphere: s as usize,
                    other: surface.body,
                    depth,
                },
            )
        })
    }

    /// The report of `passage` at `time`: the sphere, where it went and its speed since the
    /// last build; and the fix.
    fn describe(&self, passage: Passage, time: f64) -> (String, String) {
        let (s, into) = match passage {
            Passage::Wall {
                sphere,
                wall,
                depth,
            } if depth > 0.0 => (
                sphere,
                format!(
                    "is {depth:.3e} m inside wall #{} (its centre went through the wall's \
                     surface)",
                    wall + 1
                ),
            ),
            Passage::Wall { sphere, wall, .. } => (
                sphere,
                format!(
                    "went through wall #{} since the last check (its path crosses the wall's \
                     surface)",
                    wall + 1
                ),
            ),
            Passage::Body {
                sphere,
                other,
                depth,
            } => (
                sphere,
                format!(
                    "is {depth:.3e} m inside body `{}`, deeper than its radius (it went between \
                     that body's contact spheres)",
                    self.spheres.body_names()[other]
                ),
            ),
        };
        let holder = match passage {
            Passage::Wall { .. } => "a thicker wall, larger contact spheres (contact_radius)",
            Passage::Body { .. } => {
                "larger contact spheres (contact_radius) or a finer mesh of the body, to close \
                 the gaps between its spheres"
            }
        };
        self.report(s, &into, holder, time)
    }

    /// The report of `pair` at `time`, as [`DemContacts::describe`] gives a passage's.
    fn describe_deep(&self, pair: DeepPair, time: f64) -> (String, String) {
        let other = pair.other;
        let into = format!(
            "overlaps the contact sphere of body `{}` (radius {:.3e} m) by {:.3e} m, more than \
             the smaller radius: its centre is inside that sphere",
            self.spheres.body_names()[self.spheres.body()[other] as usize],
            self.spheres.radius()[other],
            pair.depth
        );
        self.report(pair.sphere, &into, "larger contact spheres", time)
    }

    /// What happened to sphere `s` (where it went: `into`) at `time`, with its speed since the
    /// last build; and the fix, `holder` being what holds it back better.
    fn report(&self, s: usize, into: &str, holder: &str, time: f64) -> (String, String) {
        let elapsed = time - self.candidates.built_time();
        let speed = match self.lists_built() && elapsed > 0.0 {
            true => self.moved_since_build(s).norm() / elapsed,
            false => 0.0,
        };
        let (radius, x) = (self.spheres.radius()[s], self.spheres.center()[s]);
        let what = format!(
            "the contact sphere of body `{}` at ({:.4}, {:.4}, {:.4}) m (radius {radius:.3e} \
             m) {into}, moving at about {speed:.3e} m/s; the contact no longer holds it back.",
            self.spheres.body_names()[self.spheres.body()[s] as usize],
            x.x,
            x.y,
            x.z,
        );
        (what, self.fix(holder, speed, radius))
    }

    /// What to change: a smaller step when the sphere moves more than [`STEP_FRACTION`] of
    /// its radius per step, else `holder`, what holds it back better.
    fn fix(&self, holder: &str, speed: f64, radius: f64) -> String {
        let fraction = speed * self.passage.step / radius;
        let stiffer = "a stiffer contact ([contact] normal_stiffness, or young with \
                       hertz-mindlin)";
        if fraction > STEP_FRACTION {
            format!(
                "Fix: a smaller dt (it moves {fraction:.2} of its radius per step; dt <= \
                 {:.3e} s moves it a tenth), or {holder}, or {stiffer}",
                0.1 * radius / speed
            )
        } else {
            format!(
                "Fix: {stiffer}, or {holder}, or a lower speed; a smaller dt does not help \
                 here, it moves only {fraction:.2} of its radius per step"
            )
        }
    }

    /// Fails if a sphere's centre lies inside a mesh wall, beyond a plane wall, or inside
    /// another body's mesh deeper than its radius at `state` (read by
    /// [`DemContacts::check_initial_overlaps`] before): a body placed inside another.
    pub fn check_initial_passage(&self, state: &State) -> Result<(), ContactError> {
        let all: Vec<u32> = (0..self.spheres.len() as u32).collect();
        let Some(passage) = self.find_passage(&all, state.time, None) else {
            return Ok(());
        };
        let (s, inside, depth) = match passage {
            Passage::Wall {
                sphere,
                wall,
                depth,
            } => (sphere, format!("wall #{}", wall + 1), depth),
            Passage::Body {
                sphere,
                other,
                depth,
            } => (
                sphere,
                format!("body `{}`", self.spheres.body_names()[other]),
                depth,
            ),
        };
        Err(ContactError::InitialInside {
            body: self.spheres.body_names()[self.spheres.body()[s] as usize].clone(),
            inside,
            depth,
            radius: self.spheres.radius()[s],
            at: self.spheres.center()[s].into(),
        })
    }

    /// The pass-through found at the last rebuild, if any.
    pub(super) fn passage_failure(&self, time: f64) -> Option<qdem_core::error::CoreError> {
        self.passage.pass_through.clone().map(|(detail, fix)| {
            qdem_core::error::CoreError::PassThrough {
                step: 0,
                time,
                dt: 0.0,
                detail,
                fix,
            }
        })
    }
}
