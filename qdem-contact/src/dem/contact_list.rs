//! The candidate list of a contact set: one record per candidate contact (a pair of spheres, or
//! a sphere and a wall) holding everything a step reads and writes of it, so that the pair
//! loop streams through one array.
//!
//! A record keeps what a step reads and writes of a contact, in 64 bytes: its partners, its
//! tangential spring ξ and this evaluation's results, the force f on the first partner and
//! δ/2. The moment of the contact force about a partner's centre follows from them and the
//! normal: the contact point lies at x_a + (r_a − δ/2) n, at a distance r − δ/2 from either
//! centre along ∓n, so the moment on a is (r_a − δ/2) n × f and the moment on b, which feels
//! −f, is (r_b − δ/2) n × f. The pair kernel adds the moments as it evaluates; when its sums
//! run apart from its law (a time-delayed boundary, a servo wall) or a rank's records are
//! merged, it keeps n × f in a column beside the records. The image translation of the second partner, only through a periodic boundary, is
//! a column too, and so is the rolling spring torque, only with rolling friction.

use qdem_core::checkpoint::same_count;
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, Vec3};

/// One candidate contact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Contact {
    /// The first partner (a sphere).
    pub(crate) first: u32,
    /// The second partner (a sphere after the first, or a wall).
    pub(crate) second: u32,
    /// Tangential spring elongation ξ (m).
    pub(crate) history: Vec3,
    /// Force on the first partner at the last evaluation (N), zero when apart.
    pub(crate) force: Vec3,
    /// Half the overlap, δ/2 (m).
    pub(crate) half_overlap: f64,
}

// A record is one cache line of the pair loop's stream.
const _: () = assert!(std::mem::size_of::<Contact>() == 64);

impl Contact {
    /// Records a touching contact's force `force` with its normal and overlap; returns n × f,
    /// the moment about a partner's centre per metre of lever.
    #[inline]
    pub(crate) fn touch(&mut self, force: Vec3, normal: &Vec3, overlap: f64) -> Vec3 {
        self.force = force;
        self.half_overlap = 0.5 * overlap;
        normal.cross(&force)
    }

    /// Records a contact that is apart: no force, the spring released.
    #[inline]
    pub(crate) fn part(&mut self) {
        self.history = Vec3::zeros();
        self.force = Vec3::zeros();
        self.half_overlap = 0.0;
    }

    /// The moment about the centre of a partner of radius `radius` of the force `scale` f (or
    /// −`scale` f on the second partner), given `turn` = n × f: (r − δ/2) `scale` n × f.
    #[inline]
    pub(crate) fn moment(&self, turn: &Vec3, radius: f64, scale: f64) -> Vec3 {
        ((radius - self.half_overlap) * scale) * turn
    }
}

/// The records of a candidate list, sorted by partners, and their columns.
#[derive(Default)]
pub(crate) struct ContactList {
    /// The records.
    pub(crate) items: Vec<Contact>,
    /// Image translation of each contact's second partner (m): one per record with periodic
    /// axes, else none (all zero).
    pub(crate) shift: Vec<Vec3>,
    /// n × f of each contact at the last evaluation (N), when the kernel keeps it (a sum
    /// pass apart from the law, a rank's records); else none.
    pub(crate) turn: Vec<Vec3>,
    /// The rolling spring torque M_r of each contact (N m, as it acts against the first
    /// partner: [`crate::dem::laws::rolling_resistance`]): one per record with rolling
    /// resistance, else none.
    pub(crate) roll: Vec<Vec3>,
}

impl ContactList {
    /// Replaces the list by `keys`, sorted, keeping the springs (and rolling springs) of
    /// contacts that stay; with an image translation per record when `periodic`.
    pub(crate) fn rebuild(&mut self, keys: Vec<(u32, u32)>, periodic: bool) {
        let old = std::mem::take(&mut self.items);
        let old_roll = std::mem::take(&mut self.roll);
        let rolling = !old_roll.is_empty();
        let mut at = 0;
        self.items = keys
            .iter()
            .map(|&(first, second)| {
                while at < old.len() && (old[at].first, old[at].second) < (first, second) {
                    at += 1;
                }
                let kept = old
                    .get(at)
                    .filter(|c| (c.first, c.second) == (first, second));
                if rolling {
                    let roll = kept.map_or(Vec3::zeros(), |_| old_roll[at]);
                    self.roll.push(roll);
                }
                Contact {
                    first,
                    second,
                    history: kept.map_or(Vec3::zeros(), |c| c.history),
                    ..Contact::default()
                }
            })
            .collect();
        self.shift.clear();
        if periodic {
            self.shift.resize(self.items.len(), Vec3::zeros());
        }
        self.turn.clear();
    }

    /// Renumbers the spheres: the sphere `t` becomes `to[t]` (and so does a second partner
    /// when `pairs`, the pair then turned so that its first partner is the lower: its spring,
    /// force and image translation change sign, n × f stays); the list sorted again.
    pub(crate) fn renumber(&mut self, to: &[u32], pairs: bool) {
        for (k, c) in self.items.iter_mut().enumerate() {
            c.first = to[c.first as usize];
            if !pairs {
                continue;
            }
            c.second = to[c.second as usize];
            if c.first > c.second {
                std::mem::swap(&mut c.first, &mut c.second);
                c.history = -c.history;
                c.force = -c.force;
                if let Some(shift) = self.shift.get_mut(k) {
                    *shift = -*shift;
                }
                // M_r acts against the first partner: the other one's is its opposite.
                if let Some(roll) = self.roll.get_mut(k) {
                    *roll = -*roll;
                }
            }
        }
        let mut order: Vec<u32> = (0..self.items.len() as u32).collect();
        order.sort_unstable_by_key(|&k| {
            let c = &self.items[k as usize];
            (c.first, c.second)
        });
        let pick = |column: &[Vec3]| order.iter().map(|&k| column[k as usize]).collect();
        if !self.shift.is_empty() {
            self.shift = pick(&self.shift);
        }
        if !self.turn.is_empty() {
            self.turn = pick(&self.turn);
        }
        if !self.roll.is_empty() {
            self.roll = pick(&self.roll);
        }
        self.items = order.iter().map(|&k| self.items[k as usize]).collect();
    }

    /// Keeps the records (and their image translations) for which `keep` holds; the n × f
    /// column is dropped (the next evaluation rewrites it).
    pub(crate) fn retain(&mut self, keep: impl Fn(&Contact) -> bool) {
        let kept: Vec<bool> = self.items.iter().map(keep).collect();
        retain_by(&mut self.items, &kept);
        if !self.shift.is_empty() {
            retain_by(&mut self.shift, &kept);
        }
        if !self.roll.is_empty() {
            retain_by(&mut self.roll, &kept);
        }
        self.turn.clear();
    }

    /// A list of the contacts `springs` (partners sorted, and the spring ξ of each), the
    /// rest of their records empty: what the next [`ContactList::rebuild`] keeps the springs
    /// of.
    pub(crate) fn with_springs(springs: Vec<(u32, u32, Vec3)>) -> ContactList {
        let items = springs
            .into_iter()
            .map(|(first, second, history)| Contact {
                first,
                second,
                history,
                ..Contact::default()
            })
            .collect();
        ContactList {
            items,
            ..ContactList::default()
        }
    }

    /// The stretched springs: each contact's partners and ξ, where ξ is not zero.
    pub(crate) fn springs(&self) -> impl Iterator<Item = (u32, u32, Vec3)> + '_ {
        self.items
            .iter()
            .filter(|c| c.history != Vec3::zeros())
            .map(|c| (c.first, c.second, c.history))
    }

    /// Number of candidates.
    pub(crate) fn len(&self) -> usize {
        self.items.len()
    }

    /// The image translation of contact `k`'s second partner.
    #[inline]
    pub(crate) fn shift(&self, k: usize) -> Vec3 {
        self.shift.get(k).copied().unwrap_or_default()
    }

    /// Gives every record a rolling spring (zero where it has none yet): the column of a
    /// list built, restored or carried without one.
    pub(crate) fn keep_rolling(&mut self) {
        self.roll.resize(self.items.len(), Vec3::zeros());
    }

    /// The records with their image translations.
    pub(crate) fn with_shifts(&self) -> impl Iterator<Item = (&Contact, Vec3)> {
        self.items
            .iter()
            .enumerate()
            .map(|(k, c)| (c, self.shift(k)))
    }

    /// Writes the list into a checkpoint: partners, springs, forces and image translations
    /// (`shift` of each record; n × f and δ/2 are rewritten by every evaluation before they are
    /// read). The spheres are written as `id` names them (and a second partner too when
    /// `pairs`).
    pub(crate) fn save(
        &self,
        out: &mut Encoder,
        id: impl Fn(u32) -> u32,
        pairs: bool,
        shift: impl Fn(usize) -> Vec3,
    ) {
        let column = |f: fn(&Contact) -> Vec3| self.items.iter().map(f).collect::<Vec<_>>();
        let second = |c: &Contact| if pairs { id(c.second) } else { c.second };
        out.u32s(&self.items.iter().map(|c| id(c.first)).collect::<Vec<_>>());
        out.u32s(&self.items.iter().map(second).collect::<Vec<_>>());
        out.vec3s(&column(|c| c.history));
        out.vec3s(&column(|c| c.force));
        out.vec3s(&(0..self.len()).map(shift).collect::<Vec<_>>());
    }

    /// Reads back a list whose first partners index `0..firsts` and second partners
    /// `0..seconds`.
    pub(crate) fn restore(
        input: &mut Decoder<'_>,
        firsts: usize,
        seconds: usize,
    ) -> Result<ContactList, CheckpointError> {
        let first = input.u32s("contact partners")?;
        let second = input.u32s("contact partners")?;
        same_count("contact partners", first.len(), second.len())?;
        if let Some(k) =
            (0..first.len()).find(|&k| first[k] as usize >= firsts || second[k] as usize >= seconds)
        {
            return Err(CheckpointError::Invalid {
                what: "contact list",
                detail: format!(
                    "contact {k} joins {} and {}, beyond the scene's {firsts} spheres",
                    first[k], second[k]
                ),
            });
        }
        let n = first.len();
        let history = input.vec3s_exact(n, "tangential springs")?;
        let force = input.vec3s_exact(n, "contact forces")?;
        let shift = input.vec3s_exact(n, "image translations")?;
        let items = (0..n)
            .map(|k| Contact {
                first: first[k],
                second: second[k],
                history: history[k],
                force: force[k],
                ..Contact::default()
            })
            .collect();
        Ok(ContactList {
            items,
            shift,
            ..ContactList::default()
        })
    }
}

/// Keeps `items[k]` where `kept[k]` (`retain` visits the items once, in order).
fn retain_by<T>(items: &mut Vec<T>, kept: &[bool]) {
    let mut kept = kept.iter();
    items.retain(|_| kept.next() == Some(&true));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rebuild_keeps_the_springs_of_the_pairs_that_stay() {
        let mut list = ContactList::default();
        list.rebuild(vec![(0, 1), (0, 2), (1, 2)], false);
        for (k, c) in list.items.iter_mut().enumerate() {
            c.history = Vec3::repeat(k as f64 + 1.0);
        }
        list.rebuild(vec![(0, 2), (1, 3)], false);
        assert_eq!(list.items[0].history, Vec3::repeat(2.0));
        assert_eq!(list.items[1].history, Vec3::zeros());
    }

    #[test]
    fn a_cut_list_keeps_each_records_image_translation() {
        let mut list = ContactList::default();
        list.rebuild(vec![(0, 1), (0, 2), (1, 2), (2, 3)], true);
        for k in 0..list.len() {
            list.shift[k] = Vec3::repeat(k as f64);
        }
        list.retain(|c| c.second != 2);
        let kept: Vec<_> = list
            .with_shifts()
            .map(|(c, s)| (c.first, c.second, s.x))
            .collect();
        assert_eq!(kept, [(0, 1, 0.0), (2, 3, 3.0)]);
    }

    #[test]
    fn the_moments_on_both_partners_are_their_levers_times_n_cross_f() {
        // Spheres of radii 2 and 1 overlapping by 0.5 along x: the contact point is 1.75 from
        // a's centre and 0.75 from b's; a force f = (0, 3, 0) on a gives a the moment
        // 1.75 x × f and b, which feels −f at 0.75 along −x, the moment 0.75 x × f.
        let mut c = Contact::default();
        let f = Vec3::new(0.0, 3.0, 0.0);
        let turn = c.touch(f, &Vec3::x(), 0.5);
        let point_from_a = 1.75 * Vec3::x();
        let point_from_b = -0.75 * Vec3::x();
        assert_eq!(c.moment(&turn, 2.0, 1.0), point_from_a.cross(&f));
        assert_eq!(c.moment(&turn, 1.0, 1.0), point_from_b.cross(&-f));
        c.part();
        assert_eq!(c.force, Vec3::zeros());
        assert_eq!(c.half_overlap, 0.0);
    }
}
