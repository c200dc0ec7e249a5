//! Which worker runs which object: a contiguous block of objects per worker, objects dealt out
//! in turn, or a model's own placement.

/// How Time Warp places a model's objects on its workers (all ranks' workers together, numbered
/// rank by rank).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ObjectMap {
    /// Worker `w` of `W` runs a contiguous block of about `N / W` objects: object `o` goes to
    /// `⌊o W / N⌋`. Neighbours by number stay together, so models whose objects talk mostly
    /// to nearby numbers (PHOLD's partitions, a grid of regions in row order) send few messages
    /// between workers.
    Block,
    /// Objects dealt out in turn: object `o` goes to `o mod W`. Spreads objects whose load
    /// grows with their number evenly; neighbours by number land on different workers.
    RoundRobin,
    /// The model's own placement: entry `o` is object `o`'s worker (below the number of
    /// workers). For models that know their communication pattern (the pool's sectors).
    Given(Vec<u32>),
}

impl ObjectMap {
    /// Each of `objects` objects' worker among `workers`.
    ///
    /// Panics if a given placement has not one entry per object, or names a worker that does
    /// not exist (a bug in the model).
    pub fn workers_of(&self, objects: usize, workers: usize) -> Vec<u32> {
        let w = workers.max(1) as u64;
        let n = objects.max(1) as u64;
        match self {
            ObjectMap::Block => (0..objects as u64).map(|o| (o * w / n) as u32).collect(),
            ObjectMap::RoundRobin => (0..objects as u64).map(|o| (o % w) as u32).collect(),
            ObjectMap::Given(v) => {
                assert_eq!(v.len(), objects, "one worker per object");
                if let Some(bad) = v.iter().find(|&&k| u64::from(k) >= w) {
                    panic!("object placed on worker {bad}, but there are {workers} workers");
                }
                v.clone()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_and_turns_cover_every_worker_evenly() {
        let block = ObjectMap::Block.workers_of(10, 3);
        assert_eq!(block, [0, 0, 0, 0, 1, 1, 1, 2, 2, 2]);
        let turns = ObjectMap::RoundRobin.workers_of(10, 3);
        assert_eq!(turns, [0, 1, 2, 0, 1, 2, 0, 1, 2, 0]);
        for v in [block, turns] {
            for k in 0..3 {
                let n = v.iter().filter(|&&x| x == k).count();
                assert!((3..=4).contains(&n), "worker {k}: {n}");
            }
        }
        assert_eq!(ObjectMap::Block.workers_of(2, 4), [0, 2]);
        assert!(ObjectMap::Block.workers_of(0, 4).is_empty());
        assert_eq!(ObjectMap::Given(vec![1, 0]).workers_of(2, 2), [1, 0]);
    }

    #[test]
    #[should_panic(expected = "there are 2 workers")]
    fn a_given_placement_names_existing_workers() {
        ObjectMap::Given(vec![0, 2]).workers_of(2, 2);
    }
}
