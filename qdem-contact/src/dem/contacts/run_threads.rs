//! Where the parallel loops of an evaluation run: as phases of the stepping thread's
//! [`Team`] when one is installed ([`qdem_core::step::team`]), else as rayon regions.
//!
//! The work of each item is the same either way and involves no other item's output, so the
//! results do not depend on the threads: the pair kernel's runs add into their own sums
//! (`pair_kernel.rs`), and the read of the centres takes the largest displacement, a maximum.
//! On a team the items are cut into contiguous shares, one per thread, by a function of their
//! count and cost alone ([`shares`]).

use qdem_core::step::team::{self, shares, Team};
use rayon::prelude::*;

/// Runs `body((r, input))` for every run `r` of `inputs`, the runs in parallel: on the
/// current team in one phase, each thread a contiguous share of about equal `cost` (by run
/// index); on rayon, each run a task of its own (the runs' costs differ: a packing's floor
/// layers carry its wall contacts, and rayon's halving split put them 2 : 1 on two threads
/// at 10⁴ spheres; on one thread the splitting is waste).
pub(super) fn for_each_run<T, B>(inputs: Vec<T>, cost: impl Fn(usize) -> usize, body: B)
where
    T: Send,
    B: Fn((usize, T)) + Sync + Send,
{
    team::with_current(|team| match team {
        Some(team) => on_team(team, inputs, cost, body),
        None => on_rayon(inputs, body),
    })
}

/// [`for_each_run`] as one phase of `team`.
fn on_team<T, B>(team: &Team, inputs: Vec<T>, cost: impl Fn(usize) -> usize, body: B)
where
    T: Send,
    B: Fn((usize, T)) + Sync,
{
    let costs: Vec<usize> = (0..inputs.len()).map(cost).collect();
    let cut = shares(&costs, team.size());
    let mut inputs = inputs.into_iter().enumerate();
    let parts: Vec<Vec<(usize, T)>> = cut
        .iter()
        .map(|r| inputs.by_ref().take(r.len()).collect())
        .collect();
    team.run(parts, |part| {
        for (r, input) in part {
            body((r, input));
        }
    });
}

/// [`for_each_run`] as a rayon region.
fn on_rayon<T, B>(inputs: Vec<T>, body: B)
where
    T: Send,
    B: Fn((usize, T)) + Sync + Send,
{
    let threads = rayon::current_num_threads();
    if threads > 1 && inputs.len() > 1 {
        team::note_rayon_region();
    }
    let per_task = match threads {
        1 => usize::MAX,
        _ => 1,
    };
    inputs
        .into_par_iter()
        .enumerate()
        .with_max_len(per_task)
        .for_each(body);
}
