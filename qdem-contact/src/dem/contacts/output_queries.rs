//! The queries the outputs make of a [`DemContacts`]: counts, the spheres with their
//! contact forces, the touching contacts split into normal and tangential parts, the force
//! through a section or a time-delayed boundary (the record types they return are
//! `contact_view.rs`'s).

use super::*;
use crate::dem::walls::wall::WallShape;

impl DemContacts {
    /// The ghost scales (left, right) of the last evaluation and the average magnitude of the
    /// contact forces through the delayed boundary it measured; `None` without a time delay.
    pub fn time_delay_state(&self) -> Option<(GhostScales, f64)> {
        self.time_delay.as_ref().map(TimeDelay::state)
    }

    /// The average magnitude of the touching pairs' forces across the plane x\[axis\] = `at`
    /// (serial, in pair order): a pair crosses it when its two sphere centres, the second at
    /// the image it touches, lie on either side. In a periodic cell the plane repeats every
    /// period, so a section at a cell face measures what the boundary force does; in a box
    /// several cells long it measures the force through an inner face (paper 003's premise
    /// for Eqs. 4–5 is a statement about that force).
    pub fn section_force(&self, axis: usize, at: f64) -> f64 {
        let period = self.periodic.as_ref().and_then(|p| p.length(axis));
        self.mean_pair_force(|c, shift| {
            let a = self.spheres.center()[c.first as usize][axis] - at;
            let b = self.spheres.center()[c.second as usize][axis] + shift[axis] - at;
            crosses(a, b, period)
        })
    }

    /// The average magnitude of the forces of the touching pairs c for which `counted(c)`
    /// (serial, in pair order, so it does not depend on the thread count); 0 without any.
    pub(super) fn mean_pair_force(&self, counted: impl Fn(&Contact, Vec3) -> bool) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for (c, shift) in self.candidates.pairs().with_shifts() {
            if c.force != Vec3::zeros() && counted(c, shift) {
                sum += c.force.norm();
                count += 1;
            }
        }
        if count == 0 {
            0.0
        } else {
            sum / count as f64
        }
    }

    /// Number of contact spheres.
    pub fn spheres(&self) -> usize {
        self.spheres.len()
    }

    /// The smallest contact sphere's radius (m), if there is a sphere.
    pub fn smallest_radius(&self) -> Option<f64> {
        self.spheres.radius().iter().copied().reduce(f64::min)
    }

    /// Number of walls.
    pub fn walls(&self) -> usize {
        self.walls.len()
    }

    /// Number of candidate pairs and wall candidates in the current lists.
    pub fn candidates(&self) -> usize {
        self.candidates.pairs().len() + self.candidates.wall_contacts().len()
    }

    /// Number of touching contacts (sphere–sphere and sphere–wall) at the last evaluation.
    pub fn contacts(&self) -> usize {
        self.candidates
            .pairs()
            .items
            .iter()
            .chain(&self.candidates.wall_contacts().items)
            .filter(|c| c.force != Vec3::zeros())
            .count()
    }

    /// Whether some wall is stress-controlled.
    pub fn has_servo(&self) -> bool {
        self.walls.has_servo()
    }

    /// The displacement (m) of wall `wall` at `time` from its place at t = 0.
    pub fn wall_displacement(&self, wall: usize, time: f64) -> Vec3 {
        self.walls.displacement(wall, time)
    }

    /// Where wall `wall` is at `time` (m): a plane's point, its point at t = 0 moved by its
    /// velocity or its servo ([`DemContacts::wall_displacement`] is this less that point);
    /// a mesh's centre of the bounding box of its triangles.
    pub fn wall_position(&self, wall: usize, time: f64) -> Vec3 {
        match &self.walls.list()[wall].shape {
            WallShape::Plane(p) => p.point + p.velocity * time,
            WallShape::Mesh(m) => {
                let (vertices, _) = m.surface(time);
                let lower = vertices
                    .iter()
                    .fold(Vec3::repeat(f64::MAX), |l, v| l.inf(v));
                let upper = vertices
                    .iter()
                    .fold(Vec3::repeat(f64::MIN), |u, v| u.sup(v));
                0.5 * (lower + upper)
            }
        }
    }

    /// The walls.
    pub fn wall_list(&self) -> &[Wall] {
        self.walls.list()
    }

    /// The names of the bodies the spheres belong to ([`SphereRecord::body`] indexes them).
    pub fn body_names(&self) -> &[String] {
        self.spheres.body_names()
    }

    /// Every contact sphere's radius (m) and the index of its material.
    pub fn radii_and_materials(&self) -> impl Iterator<Item = (f64, usize)> + '_ {
        (0..self.spheres.len()).map(|s| {
            (
                self.spheres.radius()[s],
                self.spheres.now(s).material as usize,
            )
        })
    }

    /// Every contact sphere at `state` (the state the last evaluation saw, after the step),
    /// in sphere order (the builder's, whatever the engine's spatial order), with the contact
    /// force the model applied to it.
    pub fn sphere_records<'a>(
        &'a self,
        state: &'a State,
    ) -> impl Iterator<Item = SphereRecord> + 'a {
        let bodies = state.rigid.len();
        (0..self.spheres.len()).map(move |id| {
            let s = self.slot_of(id);
            let particle = self.spheres.particle()[s] as usize;
            let spin = match self.spheres.turn()[s] as usize {
                t if t == NOT_RIGID as usize => None,
                b if b < bodies => Some(state.rigid.angular_velocity[b]),
                t => Some(state.spin.velocity[t - bodies]),
            };
            SphereRecord {
                particle,
                radius: self.spheres.radius()[s],
                body: self.spheres.body()[s] as usize,
                center: state.position[particle],
                velocity: state.velocity[particle],
                spin,
                force: self.kernel.sum(s).0,
            }
        })
    }

    /// Every contact that touched at the last evaluation: the pairs, then the wall contacts,
    /// each named by the spheres' stable ids (the builder's order), a pair with its lower
    /// id first, sorted by them. Summed per sphere (+f on the first partner times its scale,
    /// −f on the second times its scale), their forces are [`SphereRecord::force`].
    pub fn touching(&self) -> impl Iterator<Item = TouchingContact> + '_ {
        let time = self.evaluation.last_time().unwrap_or(0.0);
        let delay = self.time_delay.as_ref().map(TimeDelay::ghosts);
        let pairs = self.candidates.pairs().with_shifts();
        let pairs = pairs.filter(|(c, _)| c.force != Vec3::zeros());
        let mut pairs: Vec<TouchingContact> = pairs
            .map(|(c, shift)| {
                let (mut a, mut b) = (c.first as usize, c.second as usize);
                let (mut shift, mut force) = (shift, c.force);
                if self.id_of(a) > self.id_of(b) {
                    (a, b, shift, force) = (b, a, -shift, -force);
                }
                let (from, to) = (self.spheres.center()[a], self.spheres.center()[b] + shift);
                let scales = delay.map_or((1.0, 1.0), |(axis, s)| pair_scales(shift[axis], &s));
                touching_contact(
                    self.id_of(a),
                    Partner::Sphere(self.id_of(b)),
                    from,
                    to,
                    (to - from).normalize(),
                    force,
                    scales,
                )
            })
            .collect();
        pairs.sort_by_key(|c| (c.first, partner_key(&c.second)));
        let walls = self
            .candidates
            .wall_contacts()
            .items
            .iter()
            .filter(|c| c.force != Vec3::zeros());
        let mut walls: Vec<TouchingContact> = walls
            .map(|c| {
                let (s, w) = (c.first as usize, c.second as usize);
                let from = self.spheres.center()[s];
                let (overlap, normal) =
                    self.walls
                        .get(w)
                        .overlap(&from, self.spheres.radius()[s], time);
                let to = from + (self.spheres.radius()[s] - overlap) * normal;
                let (first, wall) = (self.id_of(s), Partner::Wall(w));
                touching_contact(first, wall, from, to, normal, c.force, (1.0, 1.0))
            })
            .collect();
        walls.sort_by_key(|c| (c.first, partner_key(&c.second)));
        pairs.into_iter().chain(walls)
    }

    /// The spheres this rank owns (and evaluates the candidates of), in a run decomposed
    /// with split contacts ([`qdem_core::step::split::Facets`]); every sphere otherwise.
    pub fn own_spheres(&self) -> usize {
        self.split
            .as_ref()
            .map_or(self.spheres.particle().len(), |p| p.own().len())
    }

    /// The spheres of other ranks whose motion this rank receives at each evaluation, in a
    /// run decomposed with split contacts ([`qdem_core::step::split::Facets`]); 0 otherwise.
    pub fn ghosts(&self) -> usize {
        self.split.as_ref().map_or(0, |p| p.ghosts)
    }

    /// The touching pair of spheres whose overlap at the last evaluation is the largest part
    /// of the smaller radius: (first, second by stable id, the lower first, overlap in m);
    /// `None` without touching pairs.
    /// One pass over the pair records, cheap enough for every step.
    pub fn deepest_pair(&self) -> Option<(usize, usize, f64)> {
        let mut deepest: Option<(usize, usize, f64, f64)> = None;
        for c in self
            .candidates
            .pairs()
            .items
            .iter()
            .filter(|c| c.force != Vec3::zeros())
        {
            let (a, b) = (c.first as usize, c.second as usize);
            let overlap = 2.0 * c.half_overlap;
            let depth = overlap / self.spheres.radius()[a].min(self.spheres.radius()[b]);
            let (a, b) = (self.id_of(a), self.id_of(b));
            let (a, b) = (a.min(b), a.max(b));
            // Of equally deep pairs the one of lowest ids, whatever the engine's order.
            if deepest.is_none_or(|d| depth > d.3 || (depth == d.3 && (a, b) < (d.0, d.1))) {
                deepest = Some((a, b, overlap, depth));
            }
        }
        deepest.map(|(a, b, overlap, _)| (a, b, overlap))
    }

    /// How many times the candidate lists were rebuilt.
    pub fn rebuilds(&self) -> u64 {
        self.candidates.rebuilds()
    }
}

/// A touching contact of sphere `first` with `second` along the segment `from`–`to`, its
/// force `force` on the first split along the unit normal `normal`.
fn touching_contact(
    first: usize,
    second: Partner,
    from: Vec3,
    to: Vec3,
    normal: Vec3,
    force: Vec3,
    scales: (f64, f64),
) -> TouchingContact {
    let normal_force = force.dot(&normal) * normal;
    TouchingContact {
        first,
        second,
        from,
        to,
        normal,
        normal_force,
        tangential_force: force - normal_force,
        scales,
    }
}

/// The order of a contact's second partner: a sphere by its id, a wall by its index.
fn partner_key(p: &Partner) -> usize {
    match p {
        Partner::Sphere(s) | Partner::Wall(s) => *s,
    }
}

/// Whether the segment from a to b (coordinates relative to a plane) crosses the plane, or,
/// with a `period`, one of its copies a whole number of periods away.
#[inline]
fn crosses(a: f64, b: f64, period: Option<f64>) -> bool {
    match period {
        Some(l) => {
            let below = (a / l).floor() * l;
            b < below || b >= below + l
        }
        None => (a < 0.0) != (b < 0.0),
    }
}
