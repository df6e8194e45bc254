//! The contacts' step, from the contacts present: the estimate a run steps at
//! ([`Model::stable_dt`]), and the step above which one contact alone makes the run unstable,
//! which refuses a step at the start ([`Model::unstable_above`]) and stops a run whose
//! contacts come to need a shorter step than its own, checked at each rebuild of the lists.
//!
//! **The linearised system.** Central differences are stable for ∆t ≤ 2/(√(ω² + γ²/4) + γ/2)
//! with ω² the largest eigenvalue of M⁻¹K and γ of M⁻¹C ([`critical_step`]). The contacts
//! make K = Σ_c G_cᵀ K_c G_c, where G_c maps the carriers' motion (a particle's translation,
//! a rigid body's translation and rotation) to the relative displacement of the contact
//! point and K_c = diag(k_n, k_t, k_t) in the contact's frame (n, t₁, t₂); likewise C with
//! the dashpots c = 2ζ√(k m*) (Hertz: 2√(5/6) ζ √(S m*), [`ContactLaw::dashpot`]) of the
//! pair's reduced mass m* = m_a m_b/(m_a + m_b), m_a against a wall, which is what the law
//! uses, also for a rigid body (its whole mass: item 8 of the project's notes used the body's
//! mass on every one of its spheres, touching or not).
//!
//! **The upper bound (the estimate).** With y = M^{1/2} x, u_a = G_a M_a^{-1/2} y_a the
//! motion of a's contact point, and λ_a = λ_max(K_c^{1/2} G_a M_a⁻¹ G_aᵀ K_c^{1/2}), Cauchy–
//! Schwarz with weight t = √(λ_b/λ_a) gives for each contact
//! (u_a − u_b)ᵀ K_c (u_a − u_b) ≤ (λ_a + √(λ_a λ_b)) |y_a|² + (λ_b + √(λ_a λ_b)) |y_b|²,
//! so that
//!
//! ω² ≤ max over carriers i of Σ_{contacts c of i} (λ_i + √(λ_i λ_j)),
//!
//! a true bound of the highest frequency, tighter than Gershgorin's 2 Σ k/m_i: against a wall
//! (λ_j = 0) or a heavy partner a contact counts once, not twice. λ_a is the largest
//! eigenvalue of the 3 × 3 matrix K_c^{1/2} A K_c^{1/2}, A = G_a M_a⁻¹ G_aᵀ the mobility of the
//! contact point (its displacement per unit force on it): 1/m for a sphere that does not
//! turn; 1/m + (r²/I)(1 − n nᵀ) for one that turns about its own centre (its turn moves the
//! point only across the normal); 1/m + [a]× I_w⁻¹ [a]×ᵀ for a sphere of a rigid body, a the
//! arm from the body's centre to the contact point and I_w the body's inertia in the world
//! frame (1/m where its rotation is held). The same sum of the dashpots bounds γ. With
//! rolling friction each contact's rolling spring k_r = k_t R*² adds k_r times the largest
//! rotational mobility of the carrier to its λ (the springs' quadratic forms add, and
//! √(Σλ_a Σλ_b) ≥ Σ√(λ_a λ_b)).
//!
//! **Which contacts, at which overlap.** Every contact touching at the state, at
//! [`OVERLAP_MARGIN`] times its overlap (Hertz's stiffness grows as √δ between two
//! estimates), and at least at the floor overlap δ_f: the larger of [`FLOOR_OVERLAP`] R*
//! (the top of a settled bed's 0.1–1%) and Hertz's largest overlap of a head-on impact at
//! the largest approach speed present, δ = (15 m* v²/(16 E* √R*))^{2/5}, v twice the fastest
//! sphere's speed plus the fastest wall's. A carrier with fewer than [`FLOOR_CONTACTS`]
//! contacts (a pour starts with none) counts the rest as contacts with a sphere like its own
//! (R* = r/2, m* = m/2) at δ_f, so that the bed it settles into is within the estimate. The
//! estimate is the step of the worst carrier's stiffness and damping together; the run's
//! `dt_safety` multiplies it.
//!
//! **The lower bound (a step no run survives).** The Rayleigh quotient of a test motion that
//! moves only the two carriers of one contact, along n (or along t, with a sphere's own turn),
//! gives ω² ≥ k_n (1/m_a + 1/m_b), k_t (C_t,a + C_t,b), whatever the other contacts add; above
//! 2/ω of the stiffest contact (damping only shortens it further) the run is unstable. A
//! requested step above it is refused at the start, and a run whose contacts come to need a
//! shorter step, found at a rebuild of the lists, stops naming the contact and the step it
//! needs ([`DemContacts::step_failure`]): between the two bounds a step is warned of only
//! (`qdem check`, `qdem run`).

use super::*;
use crate::dem::laws::contact_law::PairElasticity;
use qdem_core::Mat3;

/// The present overlaps are taken this many times larger (Hertz's stiffness √δ about 22%,
/// the step about 10% shorter): the margin for their growth between two estimates.
pub const OVERLAP_MARGIN: f64 = 1.5;

/// The smallest overlap the estimate takes, as a fraction of the reduced radius: the top of
/// the 0.1–1% a settled bed carries.
pub const FLOOR_OVERLAP: f64 = 0.01;

/// The contacts a carrier is counted with at least (a settled bed's coordination, about
/// 6): the contacts about to form of a pour or a loose packing.
pub const FLOOR_CONTACTS: usize = 6;

/// The stiffness and damping one side of a contact adds to its carrier's row: λ of K_c and
/// of C_c over the side's mobility (1/s², 1/s).
#[derive(Clone, Copy, Default)]
struct Side {
    stiffness: f64,
    damping: f64,
}

/// One carrier's row sums and its contact count.
#[derive(Clone, Copy, Default)]
struct Row {
    stiffness: f64,
    damping: f64,
    contacts: usize,
}

/// Hertz's largest overlap (m) of a head-on impact at `speed` (m/s) of a pair of reduced
/// mass `mass` and radius `radius` and effective modulus `e_star`: (15 m* v²/(16 E* √R*))^{2/5}.
pub fn impact_overlap(mass: f64, speed: f64, radius: f64, e_star: f64) -> f64 {
    (15.0 * mass * speed * speed / (16.0 * e_star * radius.sqrt())).powf(0.4)
}

/// Rayleigh's time T_R = π r √(ρ/G)/(0.1631 ν + 0.8766) (s) of a sphere of radius `radius`
/// (m) of density `density` (kg/m³), Young's modulus `young` (Pa) and Poisson's ratio
/// `poisson`, G = E/(2(1 + ν)): the time a Rayleigh wave takes to cross the sphere, of which
/// LIGGGHTS's and EDEM's users usually step at 20%.
///
/// ```
/// use qdem_contact::rayleigh_time;
/// // A grain of 8 mm (E = 50 MPa, ν = 0.25, ρ = 2,500 kg/m³): 1.53e-4 s.
/// let t = rayleigh_time(0.004, 2500.0, 5e7, 0.25);
/// assert!((t - 1.5315e-4).abs() < 1e-8);
/// ```
pub fn rayleigh_time(radius: f64, density: f64, young: f64, poisson: f64) -> f64 {
    let shear = young / (2.0 * (1.0 + poisson));
    std::f64::consts::PI * radius * (density / shear).sqrt() / (0.1631 * poisson + 0.8766)
}

/// The contact that needs the shortest step at a rebuild, and that step.
#[derive(Clone, Debug)]
pub(super) struct StepNeed {
    /// 2/ω of the contact alone (s).
    pub(super) step: f64,
    /// The contact: its spheres and bodies, overlap and reduced mass.
    pub(super) contact: String,
}

impl DemContacts {
    /// The estimate of [`Model::stable_dt`] at `state` (module docs); `None` when every
    /// carrier is held.
    pub(super) fn estimated_step(&self, state: &State) -> Option<f64> {
        let center: Vec<Vec3> = self
            .spheres
            .particle()
            .iter()
            .map(|&p| state.position[p as usize])
            .collect();
        let speed = self.approach_speed(state);
        let mut rows = vec![Row::default(); state.len()];
        self.add_pair_rows(state, &center, speed, &mut rows);
        self.add_wall_rows(state, &center, speed, &mut rows);
        self.add_floor_contacts(state, &mut rows, speed);
        let (omega_squared, damping_rate) = rows.iter().fold((0.0f64, 0.0f64), |w, r| {
            (w.0.max(r.stiffness), w.1.max(r.damping))
        });
        (omega_squared > 0.0).then(|| critical_step(omega_squared, damping_rate))
    }

    /// Adds every pair of spheres touching at `center` to both carriers' rows.
    fn add_pair_rows(&self, state: &State, center: &[Vec3], speed: f64, rows: &mut [Row]) {
        let set = SphereSet {
            center,
            radius: self.spheres.radius(),
            body: self.spheres.body(),
            periodic: self.periodic.as_ref(),
        };
        for (a, b) in find_pairs(&set, 0.0) {
            let (a, b) = (a as usize, b as usize);
            let mut d = center[b] - center[a];
            if let Some(p) = &self.periodic {
                d += p.image_shift(&d);
            }
            let (ra, rb) = (self.spheres.radius()[a], self.spheres.radius()[b]);
            let overlap = ra + rb - d.norm();
            if overlap <= 0.0 {
                continue;
            }
            let normal = d / d.norm();
            let (sa, sb) = (self.spheres.now(a), self.spheres.now(b));
            let e = self.spheres.pair_elasticity(sa, sb);
            let mass = sa.mass * sb.mass / (sa.mass + sb.mass);
            let springs = self.springs(overlap, reduced(ra, rb), mass, &e, speed, normal);
            let point_a = center[a] + (ra - 0.5 * overlap) * normal;
            let point_b = center[b] - (rb - 0.5 * overlap) * normal;
            let radius = reduced(ra, rb);
            let side_a = springs.side(&self.mobility(state, a, point_a, normal));
            let side_a = self.with_rolling(state, a, side_a, springs.kt, radius);
            let side_b = springs.side(&self.mobility(state, b, point_b, normal));
            let side_b = self.with_rolling(state, b, side_b, springs.kt, radius);
            add(rows, self.carrier(state, a), side_a, side_b);
            add(rows, self.carrier(state, b), side_b, side_a);
        }
    }

    /// Adds every sphere's contacts with the walls at `center` to its carrier's row.
    fn add_wall_rows(&self, state: &State, center: &[Vec3], speed: f64, rows: &mut [Row]) {
        for (s, x) in center.iter().enumerate() {
            let r = self.spheres.radius()[s];
            for wall in self.walls.list() {
                let (overlap, normal) = wall.overlap(x, r, state.time);
                if overlap <= 0.0 || normal == Vec3::zeros() {
                    continue;
                }
                let sphere = self.spheres.now(s);
                let e = self.walls.elasticity(sphere.material);
                let springs = self.springs(overlap, r, sphere.mass, &e, speed, normal);
                let point = x + (r - 0.5 * overlap) * normal;
                let own = springs.side(&self.mobility(state, s, point, normal));
                let own = self.with_rolling(state, s, own, springs.kt, r);
                add(rows, self.carrier(state, s), own, Side::default());
            }
        }
    }

    /// The largest approach speed present: twice the fastest free sphere's plus the fastest
    /// wall's (m/s).
    fn approach_speed(&self, state: &State) -> f64 {
        let spheres = (0..self.spheres.len())
            .filter(|&s| self.spheres.bound_mass()[s].is_finite())
            .map(|s| state.velocity[self.spheres.particle()[s] as usize].norm())
            .fold(0.0, f64::max);
        let walls = self
            .walls
            .list()
            .iter()
            .map(|w| w.velocity().norm())
            .fold(0.0, f64::max);
        2.0 * spheres + walls
    }

    /// The springs and dashpots of a contact of normal `normal` at `overlap` (taken
    /// [`OVERLAP_MARGIN`] times larger, and at least at the floor overlap) of reduced radius
    /// `radius` and mass `mass`.
    fn springs(
        &self,
        overlap: f64,
        radius: f64,
        mass: f64,
        e: &PairElasticity,
        speed: f64,
        normal: Vec3,
    ) -> Springs {
        let floor = (FLOOR_OVERLAP * radius).max(impact_overlap(mass, speed, radius, e.e_star));
        let law = &self.settings.law;
        let (kn, kt) = law.stiffness((OVERLAP_MARGIN * overlap).max(floor), radius, e);
        Springs {
            normal,
            kn,
            kt,
            cn: law.dashpot(kn, mass),
            ct: law.dashpot(kt, mass),
        }
    }

    /// Counts every carrier with fewer than [`FLOOR_CONTACTS`] contacts with the rest, each
    /// with a sphere like its own at the floor overlap (the worst of its spheres, for a rigid
    /// body).
    fn add_floor_contacts(&self, state: &State, rows: &mut [Row], speed: f64) {
        let mut like = vec![Side::default(); rows.len()];
        for s in 0..self.spheres.len() {
            let sphere = self.spheres.now(s);
            let (r, m) = (0.5 * self.spheres.radius()[s], 0.5 * sphere.mass);
            let e = self.spheres.pair_elasticity(sphere, sphere);
            let springs = self.springs(0.0, r, m, &e, speed, Vec3::z());
            let one = springs.side(&self.floor_mobility(s));
            let entry = &mut like[self.carrier(state, s)];
            entry.stiffness = entry.stiffness.max(2.0 * one.stiffness);
            entry.damping = entry.damping.max(2.0 * one.damping);
        }
        for (row, like) in rows.iter_mut().zip(like) {
            let missing = FLOOR_CONTACTS.saturating_sub(row.contacts) as f64;
            row.stiffness += missing * like.stiffness;
            row.damping += missing * like.damping;
        }
    }

    /// The particle whose row sphere `s`'s contacts add to: its own, or its rigid body's
    /// centre.
    fn carrier(&self, state: &State, s: usize) -> usize {
        match self.spheres.rigid()[s] {
            NOT_RIGID => self.spheres.particle()[s] as usize,
            b => state.rigid.center[b as usize],
        }
    }

    /// The mobility (1/kg) of sphere `s`'s contact point `point`, of normal `normal`: the
    /// point's displacement per unit force on it (module docs); zero for a held carrier.
    fn mobility(&self, state: &State, s: usize, point: Vec3, normal: Vec3) -> Mat3 {
        let mass = self.spheres.bound_mass()[s];
        if mass.is_infinite() {
            return Mat3::zeros();
        }
        let translation = Mat3::identity() / mass;
        match self.spheres.rigid()[s] {
            NOT_RIGID => {
                let tangential = Mat3::identity() - normal * normal.transpose();
                translation + self.spheres.lever()[s] * tangential
            }
            b if state.rigid.spin_fixed[b as usize] => translation,
            b => {
                let b = b as usize;
                translation + turn_mobility(state, b, point - state.position[state.rigid.center[b]])
            }
        }
    }

    /// `side` of sphere `s` with its share of the contact's rolling spring
    /// ([`RollingResistance::stiffness`] k_r = k_t R*², for tangential stiffness `kt` and
    /// reduced radius `radius`): k_r times the largest rotational mobility of its carrier
    /// (1/I, I = r²/ℓ² of a turning sphere, the body's smallest principal moment for a rigid
    /// body, none where the rotation is held). The quadratic forms of the springs add, so
    /// their λ do in the bound (module docs).
    fn with_rolling(&self, state: &State, s: usize, side: Side, kt: f64, radius: f64) -> Side {
        if self.rolling().is_none() || self.spheres.bound_mass()[s].is_infinite() {
            return side;
        }
        let turn = match self.spheres.rigid()[s] {
            NOT_RIGID => self.spheres.lever()[s] / self.spheres.radius()[s].powi(2),
            b if state.rigid.spin_fixed[b as usize] => 0.0,
            b => state.rigid.inertia[b as usize].map(|i| 1.0 / i).max(),
        };
        Side {
            stiffness: side.stiffness + RollingResistance::stiffness(kt, radius) * turn,
            damping: side.damping,
        }
    }

    /// The mobility of a floor contact of sphere `s`, along z: its lever's bound for a rigid
    /// body (the contact point is not known).
    fn floor_mobility(&self, s: usize) -> Mat3 {
        let mass = self.spheres.bound_mass()[s];
        if mass.is_infinite() {
            return Mat3::zeros();
        }
        let lever = self.spheres.lever()[s];
        let turned = match self.spheres.rigid()[s] {
            NOT_RIGID => Vec3::new(lever, lever, 0.0),
            _ => Vec3::new(lever, lever, lever),
        };
        Mat3::from_diagonal(&turned.add_scalar(1.0 / mass))
    }

    /// The touching contact of the lists (a rank's, in a decomposed run) that needs the
    /// shortest step alone (module docs: the lower bound), its overlap read from the current
    /// centres at `time`.
    pub(super) fn step_need(&self, time: f64) -> Option<StepNeed> {
        let mut worst: Option<(f64, usize, Option<usize>, f64, f64)> = None;
        let mut keep = |step: f64, a: usize, b: Option<usize>, overlap: f64, mass: f64| {
            if step.is_finite() && worst.is_none_or(|w| step < w.0) {
                worst = Some((step, a, b, overlap, mass));
            }
        };
        for c in &self.candidates.pairs().items {
            let (a, b) = (c.first as usize, c.second as usize);
            let (ra, rb) = (self.spheres.radius()[a], self.spheres.radius()[b]);
            let overlap = ra + rb - self.separation(a, b).0.norm();
            if overlap > 0.0 {
                let (sa, sb) = (self.spheres.now(a), self.spheres.now(b));
                let e = self.spheres.pair_elasticity(sa, sb);
                let (kn, kt) = self.settings.law.stiffness(overlap, reduced(ra, rb), &e);
                let step = alone_step(kn, kt, self.lower_mobility(a), self.lower_mobility(b));
                keep(
                    step,
                    a,
                    Some(b),
                    overlap,
                    sa.mass * sb.mass / (sa.mass + sb.mass),
                );
            }
        }
        for c in &self.candidates.wall_contacts().items {
            let (s, w) = (c.first as usize, c.second as usize);
            let r = self.spheres.radius()[s];
            let (overlap, _) = self
                .walls
                .get(w)
                .overlap(&self.spheres.center()[s], r, time);
            if overlap > 0.0 {
                let sphere = self.spheres.now(s);
                let e = self.walls.elasticity(sphere.material);
                let (kn, kt) = self.settings.law.stiffness(overlap, r, &e);
                let step = alone_step(kn, kt, self.lower_mobility(s), (0.0, 0.0));
                keep(step, s, None, overlap, sphere.mass);
            }
        }
        let (step, a, b, overlap, mass) = worst?;
        let name = |s: usize| {
            format!(
                "sphere {s} of `{}`",
                self.spheres.body_names()[self.spheres.body()[s] as usize]
            )
        };
        let against = b.map_or_else(|| "a wall".to_string(), name);
        Some(StepNeed {
            step,
            contact: format!(
                "the contact of {} and {against} (overlap {overlap:.3e} m, reduced mass \
                 {mass:.3e} kg)",
                name(a)
            ),
        })
    }

    /// Builds the candidate lists at `state`'s positions when they are not current (a
    /// `[run] start_from` stage's hold the checkpoint's springs until the first evaluation
    /// rebuilds them), keeping the springs of the contacts they list, as that rebuild does:
    /// then [`DemContacts::touching_at`] counts, and [`Model::unstable_above`] reads, the
    /// contacts of the state a run starts from. A no-op on a rank of a decomposed run (its
    /// lists are its part's).
    ///
    /// ```
    /// use qdem_contact::{ContactLaw, ContactSettings, ContactSphere, DemContacts, LinearSpring};
    /// use qdem_core::{step::State, Vec3};
    ///
    /// // Two spheres of 1 cm overlapping by 1 mm: one contact before any step.
    /// let mut state = State::at_rest(vec![Vec3::zeros(), Vec3::new(0.019, 0.0, 0.0)]);
    /// state.mass = vec![0.01, 0.01];
    /// let spheres: Vec<ContactSphere> = (0..2)
    ///     .map(|i| ContactSphere { particle: i, radius: 0.01, body: i, material: 0 })
    ///     .collect();
    /// let settings = ContactSettings {
    ///     law: ContactLaw::Linear(LinearSpring {
    ///         normal_stiffness: 1e5,
    ///         tangential_stiffness: 1e5,
    ///         damping_ratio: 0.0,
    ///     }),
    ///     friction: 0.5,
    ///     skin: 0.001,
    /// };
    /// let names = vec!["a".to_string(), "b".to_string()];
    /// let mut contacts = DemContacts::new(&state, &spheres, names, &[(1e9, 0.25)], settings, vec![]);
    /// assert_eq!(contacts.touching_at(state.time), 0);
    /// contacts.build_lists(&state);
    /// assert_eq!(contacts.touching_at(state.time), 1);
    /// ```
    pub fn build_lists(&mut self, state: &State) {
        if self.lists_built() || self.split.is_some() {
            return;
        }
        self.read_centers(state);
        self.rebuild_all(state.time);
    }

    /// The contacts of the lists (a rank's, in a decomposed run) touching at the centres of
    /// their last build or evaluation, walls at `time`: those [`Model::stable_dt`] and
    /// [`Model::unstable_above`] take at that state; none before the lists are built
    /// ([`DemContacts::build_lists`]).
    pub fn touching_at(&self, time: f64) -> usize {
        if !self.lists_built() {
            return 0;
        }
        let pairs = self.candidates.pairs().items.iter().filter(|c| {
            let (a, b) = (c.first as usize, c.second as usize);
            let reach = self.spheres.radius()[a] + self.spheres.radius()[b];
            self.separation(a, b).0.norm() < reach
        });
        let walls = self.candidates.wall_contacts().items.iter().filter(|c| {
            let (s, w) = (c.first as usize, c.second as usize);
            let r = self.spheres.radius()[s];
            self.walls
                .get(w)
                .overlap(&self.spheres.center()[s], r, time)
                .0
                > 0.0
        });
        pairs.count() + walls.count()
    }

    /// The exact mobility (C_n, C_t) of sphere `s`'s contact point along directions it
    /// surely has: translation, and a sphere's turn about its own centre.
    fn lower_mobility(&self, s: usize) -> (f64, f64) {
        let mass = self.spheres.bound_mass()[s];
        if mass.is_infinite() {
            return (0.0, 0.0);
        }
        match self.spheres.rigid()[s] {
            NOT_RIGID => (1.0 / mass, 1.0 / mass + self.spheres.lever()[s]),
            _ => (1.0 / mass, 1.0 / mass),
        }
    }

    /// At a rebuild: keeps the contact that needs a shorter step than the run's, for
    /// [`Model::failure`].
    pub(super) fn check_step_need(&mut self, time: f64) {
        let dt = self.passage.step();
        if dt <= 0.0 || self.step_short.is_some() {
            return;
        }
        self.step_short = self.step_need(time).filter(|need| need.step < dt);
    }

    /// The contact found at a rebuild to need a shorter step than the run's, as the failure
    /// that stops the run.
    pub(super) fn step_failure(&self) -> Option<qdem_core::error::CoreError> {
        self.step_short
            .as_ref()
            .map(|need| qdem_core::error::CoreError::ContactStep {
                contact: need.contact.clone(),
                needed: need.step,
                dt: self.passage.step(),
            })
    }

    /// [`Model::unstable_above`]: the shortest step a contact of the lists needs alone, when
    /// they were built at `state`'s positions (by [`DemContacts::check_initial_overlaps`]);
    /// `None` when none touches or the lists are not current (the first rebuild checks it).
    pub(super) fn unstable_step(&self, state: &State) -> Option<f64> {
        if !self.lists_built() {
            return None;
        }
        let center = |s: usize| state.position[self.spheres.particle()[s] as usize];
        let moved = (0..self.spheres.len()).any(|s| center(s) != self.spheres.center()[s]);
        if moved {
            return None;
        }
        self.step_need(state.time).map(|need| need.step)
    }
}

/// A contact's springs and dashpots: k_n, c_n along the normal, k_t, c_t across it.
struct Springs {
    normal: Vec3,
    kn: f64,
    kt: f64,
    cn: f64,
    ct: f64,
}

impl Springs {
    /// A side's λ_max(K_c^{1/2} A K_c^{1/2}) of the springs, and of the dashpots, over its
    /// contact point's mobility A.
    fn side(&self, mobility: &Mat3) -> Side {
        let nn = self.normal * self.normal.transpose();
        let largest = |along: f64, across: f64| {
            let root = along.sqrt() * nn + across.sqrt() * (Mat3::identity() - nn);
            (root * mobility * root)
                .symmetric_eigenvalues()
                .iter()
                .fold(0.0f64, |m, &v| m.max(v))
        };
        Side {
            stiffness: largest(self.kn, self.kt),
            damping: largest(self.cn, self.ct),
        }
    }
}

/// Adds a contact's share λ_i + √(λ_i λ_j) to carrier `carrier`'s row.
fn add(rows: &mut [Row], carrier: usize, own: Side, other: Side) {
    let row = &mut rows[carrier];
    row.stiffness += own.stiffness + (own.stiffness * other.stiffness).sqrt();
    row.damping += own.damping + (own.damping * other.damping).sqrt();
    row.contacts += 1;
}

/// 2/ω of one contact alone, ω² = max(k_n (C_n,a + C_n,b), k_t (C_t,a + C_t,b)).
fn alone_step(kn: f64, kt: f64, a: (f64, f64), b: (f64, f64)) -> f64 {
    let omega_squared = (kn * (a.0 + b.0)).max(kt * (a.1 + b.1));
    2.0 / omega_squared.sqrt()
}

/// [a]× I_w⁻¹ [a]×ᵀ (1/kg) of rigid body `b`, the arm a from its centre: how the point at
/// the arm's end moves per unit force on it through the body's turn.
fn turn_mobility(state: &State, b: usize, arm: Vec3) -> Mat3 {
    let rotation = state.rigid.orientation[b].to_rotation_matrix();
    let inverse = Mat3::from_diagonal(&state.rigid.inertia[b].map(|i| 1.0 / i));
    let inverse_world = rotation.matrix() * inverse * rotation.matrix().transpose();
    let cross = arm.cross_matrix();
    cross * inverse_world * cross.transpose()
}
