//! Building a [`DemContacts`]: its spheres, their carriers and elastic constants, periodic
//! axes and a time-delayed boundary, and the check of the initial overlaps.

use super::*;
use crate::dem::walls::servo_wall::Servo;

impl DemContacts {
    /// Contacts between `spheres` (of bodies `body_names`, with elastic constants (E, ν) per
    /// material) and against `walls`, at the state's current configuration.
    pub fn new(
        state: &State,
        spheres: &[ContactSphere],
        body_names: Vec<String>,
        materials: &[(f64, f64)],
        settings: ContactSettings,
        walls: Vec<Wall>,
    ) -> DemContacts {
        // The rigid body of each sphere: through a member, or at the body's centre.
        let mut body_of_center = vec![NOT_RIGID; state.len()];
        for (b, &c) in state.rigid.center.iter().enumerate() {
            body_of_center[c] = b as u32;
        }
        let rigid: Vec<u32> = spheres
            .iter()
            .map(|s| {
                state
                    .rigid
                    .body_of_member(s.particle)
                    .map_or(body_of_center[s.particle], |b| b as u32)
            })
            .collect();
        let carrier = |s: &ContactSphere, r: u32| match r {
            NOT_RIGID => s.particle,
            b => state.rigid.center[b as usize],
        };
        let mass: Vec<f64> = spheres
            .iter()
            .zip(&rigid)
            .map(|(s, &r)| state.mass[carrier(s, r)])
            .collect();
        let turns = |p: usize| state.spin.fixed.get(p).is_some_and(|f| *f != Dofs::ALL);
        let turn: Vec<u32> = spheres
            .iter()
            .zip(&rigid)
            .map(|(s, &r)| match r {
                NOT_RIGID if turns(s.particle) => (state.rigid.len() + s.particle) as u32,
                r => r,
            })
            .collect();
        let lever = spheres
            .iter()
            .zip(&rigid)
            .map(|(s, &r)| match r {
                NOT_RIGID if turns(s.particle) => {
                    s.radius * s.radius / state.spin.inertia[s.particle]
                }
                NOT_RIGID => 0.0,
                b if state.rigid.spin_fixed[b as usize] => 0.0,
                b => {
                    let arm = state.position[s.particle] - state.position[carrier(s, r)];
                    (arm.norm() + s.radius).powi(2) / state.rigid.inertia[b as usize].min()
                }
            })
            .collect();
        // A carrier held in every direction (and, for a rigid body, in rotation) cannot
        // oscillate: it does not limit the step (infinite mass in the bound below).
        let held = |s: &ContactSphere, r: u32| {
            let c = carrier(s, r);
            let still = match r {
                NOT_RIGID => !turns(s.particle),
                b => state.rigid.spin_fixed[b as usize],
            };
            state.fixed[c] == Dofs::ALL && still
        };
        let bound_mass: Vec<f64> = spheres
            .iter()
            .zip(&rigid)
            .zip(&mass)
            .map(|((s, &r), &m)| if held(s, r) { f64::INFINITY } else { m })
            .collect();
        let now: Vec<SphereNow> = spheres
            .iter()
            .zip(&mass)
            .map(|(s, &m)| SphereNow {
                radius: s.radius,
                mass: m,
                material: s.material as u32,
                ..SphereNow::default()
            })
            .collect();
        let particle: Vec<u32> = spheres.iter().map(|s| s.particle as u32).collect();
        DemContacts {
            name: "contact".to_string(),
            spheres: Spheres::new(SphereColumns {
                exclusive: pair_kernel::exclusive_carriers(&particle, &turn),
                particle,
                radius: spheres.iter().map(|s| s.radius).collect(),
                body: spheres.iter().map(|s| s.body as u32).collect(),
                rigid,
                turn,
                lever,
                bound_mass,
                now,
                body_names,
                materials,
            }),
            order: SphereOrder::default(),
            settings,
            walls: Walls::new(walls, materials),
            evaluation: Evaluation::new(),
            candidates: Candidates::default(),
            kernel: KernelPlan::new(spheres.len()),
            periodic: None,
            time_delay: None,
            split: None,
            passage: PassageCheck::default(),
            rolling: None,
            step_short: None,
        }
    }

    /// Makes the contacts periodic along the axes of `periodic`; refused when a period is not
    /// longer than twice the reach of the largest spheres (two radii plus the skin).
    pub fn with_periodic(mut self, periodic: PeriodicBox) -> Result<DemContacts, ContactError> {
        let r_max = self.spheres.radius().iter().cloned().fold(0.0, f64::max);
        periodic.check_reach(2.0 * r_max + self.settings.skin)?;
        self.periodic = Some(periodic);
        self.candidates.invalidate();
        Ok(self)
    }

    /// Makes plane wall `wall` stress-controlled by `servo`, from now on; refused for a mesh
    /// wall or a wall out of range.
    pub fn set_servo(&mut self, wall: usize, servo: Servo) -> Result<(), ContactError> {
        self.walls.set_servo(wall, servo)
    }

    /// Scales the forces from ghosts beyond the boundaries of periodic `axis` by `boundary`'s
    /// ghost scales (paper 003 §5). Needs [`DemContacts::with_periodic`] along that axis first.
    pub fn with_time_delay(
        mut self,
        axis: usize,
        boundary: TimeDelayedBoundary,
    ) -> Result<DemContacts, ContactError> {
        if self
            .periodic
            .as_ref()
            .and_then(|p| p.length(axis))
            .is_none()
        {
            return Err(ContactError::TimeDelayNotPeriodic {
                axis: ['x', 'y', 'z'][axis.min(2)],
            });
        }
        self.time_delay = Some(TimeDelay::new(axis, boundary));
        Ok(self)
    }

    /// Fails if two bodies, or a body and a wall, overlap at the current configuration by more
    /// than `tolerance` times the reduced radius (the sphere radius for walls).
    pub fn check_initial_overlaps(
        &mut self,
        state: &State,
        tolerance: f64,
    ) -> Result<(), ContactError> {
        self.check_placed_overlaps(state, tolerance, |_| true)
    }

    /// [`DemContacts::check_initial_overlaps`] for what a start places anew: every wall
    /// against every sphere, but a pair of spheres only when `placed` holds for the particle
    /// carrying one of them. A stage that starts from a checkpoint passes `false` for the
    /// particles the checkpoint put where they are: their overlaps with each other are the
    /// contacts the previous stage left, loaded as it loaded them, not a placement to refuse.
    ///
    /// ```
    /// use qdem_contact::{ContactLaw, ContactSettings, ContactSphere, DemContacts, LinearSpring};
    /// use qdem_core::{step::State, Vec3};
    ///
    /// // Two spheres of 10 mm radius, 5 mm deep in each other: 50% of the reduced radius.
    /// let mut state = State::at_rest(vec![Vec3::zeros(), Vec3::new(0.015, 0.0, 0.0)]);
    /// state.mass = vec![1.0; 2];
    /// let spheres: Vec<ContactSphere> = (0..2)
    ///     .map(|i| ContactSphere { particle: i, radius: 0.01, body: i, material: 0 })
    ///     .collect();
    /// let law = LinearSpring { normal_stiffness: 1e5, tangential_stiffness: 5e4, damping_ratio: 0.0 };
    /// let settings = ContactSettings { law: ContactLaw::Linear(law), friction: 0.5, skin: 1e-3 };
    /// let names = vec!["a".to_string(), "b".to_string()];
    /// let mut model = DemContacts::new(&state, &spheres, names, &[(1e9, 0.25)], settings, vec![]);
    /// assert!(model.check_initial_overlaps(&state, 0.05).is_err());
    /// // Both where a checkpoint left them: their contact is not checked.
    /// assert!(model.check_placed_overlaps(&state, 0.05, |_| false).is_ok());
    /// ```
    pub fn check_placed_overlaps(
        &mut self,
        state: &State,
        tolerance: f64,
        placed: impl Fn(usize) -> bool,
    ) -> Result<(), ContactError> {
        self.read_centers(state);
        self.rebuild_all(state.time);
        let particle = self.spheres.particle();
        let new = |s: u32| placed(particle[s as usize] as usize);
        let pairs = self.candidates.pairs().items.iter();
        for c in pairs.filter(|c| new(c.first) || new(c.second)) {
            let (a, b) = (c.first as usize, c.second as usize);
            let radius = reduced(self.spheres.radius()[a], self.spheres.radius()[b]);
            let overlap = self.spheres.radius()[a] + self.spheres.radius()[b]
                - self.separation(a, b).0.norm();
            if overlap > tolerance * radius {
                return Err(ContactError::InitialOverlap {
                    a: self.spheres.body_names()[self.spheres.body()[a] as usize].clone(),
                    b: self.spheres.body_names()[self.spheres.body()[b] as usize].clone(),
                    overlap,
                    radius,
                    tolerance: 100.0 * tolerance,
                    at_a: self.spheres.center()[a].into(),
                    at_b: self.spheres.center()[b].into(),
                });
            }
        }
        for c in &self.candidates.wall_contacts().items {
            let (s, w) = (c.first as usize, c.second as usize);
            let (overlap, _) = self.walls.get(w).overlap(
                &self.spheres.center()[s],
                self.spheres.radius()[s],
                state.time,
            );
            if overlap > tolerance * self.spheres.radius()[s] {
                return Err(ContactError::InitialWallOverlap {
                    body: self.spheres.body_names()[self.spheres.body()[s] as usize].clone(),
                    wall: w + 1,
                    overlap,
                    radius: self.spheres.radius()[s],
                    tolerance: 100.0 * tolerance,
                    at: self.spheres.center()[s].into(),
                });
            }
        }
        Ok(())
    }
}
