//! [`GhostTable`]: who sends which item records to whom, for a split model that exchanges
//! records ([`crate::step::split::Halo::items`]: contact spheres), and the three exchanges that use
//! it: the **borders** (every item's record to every rank, at a rebuild of the lists and a
//! whole gather), the **ghost requests** (after a rebuild: each rank asks the owners for the
//! items its lists read) and the **forward** exchange (at each evaluation, the ghosts'
//! records from their owners).
//!
//! A record is copied, never summed, so every rank reads the owner's bits.

use crate::parallel::communicator::Communicator;
use crate::step::split::Halo;

/// One split model's exchange of item records.
pub(crate) struct GhostTable {
    /// Every item, grouped by owner rank, ascending within a rank.
    by_rank: Vec<u32>,
    /// Items per rank in `by_rank`.
    by_rank_counts: Vec<usize>,
    /// Where this rank's own items start in `by_rank`.
    own_start: usize,
    /// Per item, the rank that owns it.
    owner: Vec<u32>,
    /// The own items each other rank reads as ghosts, grouped by rank.
    send: Vec<u32>,
    send_counts: Vec<usize>,
    /// This rank's ghosts, grouped by owner, ascending within an owner.
    recv: Vec<u32>,
    recv_counts: Vec<usize>,
    mine: Vec<f64>,
    all: Vec<f64>,
}

impl GhostTable {
    /// The table of items owned by `owner` (one rank per item) among `ranks` ranks, seen by
    /// rank `me`; no ghosts yet.
    pub fn new(owner: Vec<u32>, me: usize, ranks: usize) -> GhostTable {
        let mut grouped = vec![Vec::new(); ranks];
        for (s, &r) in owner.iter().enumerate() {
            grouped[r as usize].push(s as u32);
        }
        GhostTable {
            own_start: grouped[..me].iter().map(Vec::len).sum(),
            by_rank_counts: grouped.iter().map(Vec::len).collect(),
            by_rank: grouped.concat(),
            owner,
            send: Vec::new(),
            send_counts: vec![0; ranks],
            recv: Vec::new(),
            recv_counts: vec![0; ranks],
            mine: Vec::new(),
            all: Vec::new(),
        }
    }

    /// Every item's record, from its owner, unpacked into `halo`.
    pub fn borders(&mut self, comm: &dyn Communicator, halo: &mut dyn Halo) {
        let per = halo.record_values();
        self.mine.clear();
        let own = self.own_start..self.own_start + self.by_rank_counts[comm.rank()];
        halo.pack(&self.by_rank[own], &mut self.mine);
        let counts: Vec<usize> = self.by_rank_counts.iter().map(|n| per * n).collect();
        self.all.resize(per * self.by_rank.len(), 0.0);
        comm.all_gather(&self.mine, &mut self.all, &counts);
        halo.unpack(&self.by_rank, &self.all);
    }

    /// The ghosts' records, from their owners, unpacked into `halo`.
    pub fn forward(&mut self, comm: &dyn Communicator, halo: &mut dyn Halo) {
        let per = halo.record_values();
        self.mine.clear();
        halo.pack(&self.send, &mut self.mine);
        let counts = |c: &[usize]| c.iter().map(|n| per * n).collect::<Vec<_>>();
        let (send_counts, recv_counts) = (counts(&self.send_counts), counts(&self.recv_counts));
        self.all.resize(per * self.recv.len(), 0.0);
        comm.all_to_all(&self.mine, &send_counts, &mut self.all, &recv_counts);
        halo.unpack(&self.recv, &self.all);
    }

    /// Makes `ghosts` (ascending) the items this rank receives at each evaluation, and
    /// learns which of its own the others receive: every rank's request counts (a ranks ×
    /// ranks table), then the requests.
    pub fn set_ghosts(&mut self, comm: &dyn Communicator, ghosts: &[u32]) {
        let ranks = comm.size();
        let mut asked = vec![Vec::new(); ranks];
        for &g in ghosts {
            asked[self.owner[g as usize] as usize].push(g);
        }
        self.recv_counts = asked.iter().map(Vec::len).collect();
        self.recv = asked.concat();
        let mine: Vec<f64> = self.recv_counts.iter().map(|&n| n as f64).collect();
        let mut table = vec![0.0; ranks * ranks];
        comm.all_gather(&mine, &mut table, &vec![ranks; ranks]);
        let per_rank: Vec<usize> = table
            .chunks_exact(ranks)
            .map(|row| row.iter().sum::<f64>() as usize)
            .collect();
        let requests: Vec<f64> = self.recv.iter().map(|&s| s as f64).collect();
        let mut all = vec![0.0; per_rank.iter().sum()];
        comm.all_gather(&requests, &mut all, &per_rank);
        let me = comm.rank();
        let (mut send, mut send_counts, mut at) = (Vec::new(), vec![0; ranks], 0);
        for (r, row) in table.chunks_exact(ranks).enumerate() {
            let before: usize = row[..me].iter().map(|&n| n as usize).sum();
            let n = row[me] as usize;
            if r != me {
                let from = at + before;
                send.extend(all[from..from + n].iter().map(|&s| s as u32));
                send_counts[r] = n;
            }
            at += per_rank[r];
        }
        self.send = send;
        self.send_counts = send_counts;
    }
}
