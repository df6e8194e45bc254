//! What a checkpoint keeps of a [`DemContacts`]: the candidate lists with their tangential
//! springs, where and when they were built, the time-delayed boundary's estimates and the
//! servo walls' planes (none written without servo walls: the layout of a run without them is
//! unchanged).

use super::*;

impl Persistent for DemContacts {
    /// The candidate lists with their tangential springs, where and when they were built, and
    /// the time-delayed boundary's estimates: everything but the sphere centres, which are
    /// read from the state.
    fn save(&self, out: &mut Encoder) {
        out.tag("contact");
        out.option_f64(self.last_time);
        out.bool(self.built);
        out.f64(self.built_time);
        out.vec3s(&self.built_at);
        out.u64(self.rebuilds);
        self.pairs.save(out);
        self.wall_contacts.save(out);
        out.bool(self.time_delay.is_some());
        if let Some(delay) = &self.time_delay {
            out.f64(delay.scales.left);
            out.f64(delay.scales.right);
            out.f64(delay.boundary_force);
            delay.boundary.save(out);
        }
        self.save_servos(out);
    }
    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        input.tag("contact")?;
        let spheres = self.particle.len();
        self.last_time = input.option_f64("the last evaluation time")?;
        self.built = input.bool("the build flag")?;
        self.built_time = input.f64("the build time")?;
        self.built_at = input.vec3s("the build positions")?;
        if self.built {
            same_count("contact spheres", spheres, self.built_at.len())?;
        }
        self.rebuilds = input.u64("the rebuild count")?;
        self.pairs = ContactList::restore(input, spheres, spheres)?;
        self.wall_contacts = ContactList::restore(input, spheres, self.walls.len())?;
        let delayed = input.bool("the time-delay flag")?;
        same_count(
            "time-delayed boundaries",
            self.time_delay.is_some() as usize,
            delayed as usize,
        )?;
        if let Some(delay) = &mut self.time_delay {
            delay.scales = GhostScales {
                left: input.f64("the left ghost scale")?,
                right: input.f64("the right ghost scale")?,
            };
            delay.boundary_force = input.f64("the boundary force")?;
            delay.boundary.restore(input)?;
        }
        self.restore_servos(input)?;
        self.build_incidence();
        if let Some(split) = &mut self.split {
            split.whole = true;
        }
        Ok(())
    }
}
