//! What the stages of a [`DemContacts`] evaluation (`stages.rs`) read and build (paper 000
//! §4): the sphere centres and motions from the state, the displacement check, the candidate
//! lists of the broad phase and their partners, and each candidate's geometry for the narrow
//! phase.

use super::*;

impl DemContacts {
    /// x_b − x_a, the minimum image when periodic, and the translation of b's image.
    #[inline]
    pub(super) fn separation(&self, a: usize, b: usize) -> (Vec3, Vec3) {
        let d = self.spheres.center()[b] - self.spheres.center()[a];
        match &self.periodic {
            Some(p) => {
                let shift = p.image_shift(&d);
                (d + shift, shift)
            }
            None => (d, Vec3::zeros()),
        }
    }

    /// The largest distance a sphere has moved since the last build (infinite before it), or
    /// a bound on it that keeps the lists as that distance would ([`DemContacts::displacement`]),
    /// and the centres and the narrow phase's records ([`read_motion`]) of the spheres the
    /// lists read: every sphere's in the same pass when most spheres are partners of
    /// candidates (a packing), else only the partners', in a pass over them alone (most
    /// spheres of a ballast stone touch nothing: the others' centres are read at the next
    /// build).
    pub(super) fn read_centers(&mut self, state: &State) -> f64 {
        if self.reads_every_sphere() {
            let built_at = self.lists_built().then_some(self.candidates.built_at());
            self.spheres.read_every(state, built_at)
        } else {
            self.displacement(state)
        }
    }

    /// Copies every sphere's centre out of the state (before a build, when the read passed
    /// over the partners only).
    pub(super) fn read_every_center(&mut self, state: &State) {
        self.spheres.read_every_center(state);
    }

    /// Whether [`DemContacts::read_centers`] fills every sphere's narrow-phase record in its
    /// pass: before the first build, and when most spheres are partners of candidates.
    pub(super) fn reads_every_sphere(&self) -> bool {
        !self.lists_built() || 2 * self.candidates.partners().len() >= self.spheres.len()
    }

    /// Whether the candidate lists were built for these spheres (at `built_at`).
    pub(super) fn lists_built(&self) -> bool {
        self.candidates.built_for(self.spheres.len())
    }

    /// The narrow phase's record of every partner of a candidate, from `state`; serial: it
    /// runs only when fewer than half the spheres were partners (in the read, and once after
    /// a rebuild of such lists, for the new partners).
    pub(super) fn read_all_partners(&mut self, state: &State) {
        self.spheres.read_motions(state, self.candidates.partners());
    }

    /// The centres and the narrow phase's records ([`read_motion`]) of `spheres` from `state`.
    pub(super) fn read_motions(&mut self, state: &State, spheres: &[u32]) {
        self.spheres.read_motions(state, spheres);
    }

    /// Whether some pair outside the lists may have come within reach since the last build,
    /// given the largest distance a sphere has moved.
    pub(super) fn outgrew_skin(&self, moved: f64, time: f64) -> bool {
        let wall_moved = self
            .walls
            .moved_bound((time - self.candidates.built_time()).abs());
        2.0 * moved >= self.settings.skin || moved + wall_moved >= self.settings.skin
    }

    /// Broad phase: the spheres in spatial order (`spatial_order.rs`), new candidate lists
    /// and the incidence of pairs per sphere.
    pub(super) fn rebuild_all(&mut self, time: f64) {
        self.sort_spheres();
        let skin = self.settings.skin;
        let center = self.spheres.center();
        let set = SphereSet {
            center,
            radius: self.spheres.radius(),
            body: self.spheres.body(),
            periodic: self.periodic.as_ref(),
        };
        let keys = find_pairs(&set, skin);
        self.candidates
            .pairs_mut()
            .rebuild(keys, self.periodic.is_some());
        let wall_keys = self.wall_keys((0..center.len()).into_par_iter(), time);
        self.candidates
            .wall_contacts_mut()
            .rebuild(wall_keys, false);
        self.finish_build(time);
    }

    /// The wall candidates of `spheres` (ascending), sorted by sphere then wall.
    pub(super) fn wall_keys(
        &self,
        spheres: impl IndexedParallelIterator<Item = usize>,
        time: f64,
    ) -> Vec<(u32, u32)> {
        let (walls, skin) = (self.walls.list(), self.settings.skin);
        let (radius, center) = (self.spheres.radius(), self.spheres.center());
        spheres
            .with_min_len(CONTACT_CHUNK)
            .flat_map_iter(|s| {
                walls.iter().enumerate().filter_map(move |(w, wall)| {
                    wall.is_candidate(&center[s], radius[s], skin, time)
                        .then_some((s as u32, w as u32))
                })
            })
            .collect()
    }

    /// After new candidate lists: their partners, and where and when they were built.
    pub(super) fn finish_build(&mut self, time: f64) {
        self.index_partners();
        self.candidates.built(self.spheres.center(), time);
    }

    /// After new or changed lists: the partners of their candidates, and the pair
    /// kernel's plan for them.
    pub(super) fn index_partners(&mut self) {
        self.candidates.index_partners(self.spheres.len());
        self.plan_runs();
    }

    /// The geometry and elasticity of the pair of spheres of `contact`, with the image
    /// translation of its second sphere (written into `shift` when periodic, else read from
    /// it); `None` when apart.
    #[inline(always)]
    pub(super) fn pair_contact(
        &self,
        contact: &Contact,
        shift: &mut Vec3,
    ) -> Option<(PairGeometry, PairElasticity)> {
        if self.periodic.is_some() {
            *shift = self.image_of(contact);
        }
        let (pair, e) = self.spheres_through(contact, *shift)?;
        Some((pair.geometry(), e))
    }

    /// The translation of the minimum image of `contact`'s second sphere (periodic only).
    #[inline(always)]
    pub(super) fn image_of(&self, contact: &Contact) -> Vec3 {
        let (a, b) = (contact.first as usize, contact.second as usize);
        let d = self.spheres.now(b).center - self.spheres.now(a).center;
        self.periodic
            .as_ref()
            .map_or(Vec3::zeros(), |p| p.image_shift(&d))
    }

    /// The spheres of `contact` as the narrow phase finds them touching, its second sphere's
    /// image translated by `shift`, with their elasticity; `None` when apart.
    #[inline(always)]
    pub(super) fn spheres_through(
        &self,
        contact: &Contact,
        shift: Vec3,
    ) -> Option<(SpherePair, PairElasticity)> {
        let (a, b) = (contact.first as usize, contact.second as usize);
        let (sa, sb) = (self.spheres.now(a), self.spheres.now(b));
        let pair = touching_pair(sa, sb, shift, self.settings.friction)?;
        let e = self.spheres.pair_elasticity(sa, sb);
        Some((pair, e))
    }

    /// The geometry and elasticity of the contact of sphere s with wall w: the contact point
    /// at x + (r − δ/2) n, its velocity v + (r − δ/2) ω × n against the wall's; `None` when
    /// apart.
    #[inline(always)]
    pub(super) fn wall_contact(
        &self,
        time: f64,
        s: usize,
        w: usize,
    ) -> Option<(PairGeometry, PairElasticity)> {
        self.walls.contact(time, self.spheres.now(s), w)
    }
}
