//! Incremental state saving ([`Saving::Incremental`]): objects with large states whose
//! batches change a few entries, saved by the old values the handler records, must commit
//! the sequential executor's run bit for bit under Time Warp, with rollbacks forced by chaos
//! mode and by running every batch as undoable, beside objects saved by copy.

use pdes_kernel::sequential::Sequential;
use pdes_kernel::time_warp::threads::TimeWarp;
use pdes_kernel::time_warp::{ObjectMap, TwConfig};
use pdes_kernel::{Ctx, Envelope, Model, PlainTime, Saving, VTime};

/// Entries in each object's table.
const CELLS: usize = 4096;

/// Objects whose state is a table of floating-point cells; each message mixes its payload into
/// a few cells and sends one or two messages on.
struct Ledger {
    objects: u32,
}

/// One object's table, random stream and count.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct Book {
    cells: Vec<f64>,
    rng: u64,
    handled: u64,
}

/// Old values a batch records before it changes them.
#[derive(Clone, Debug)]
enum Undo {
    Cell(u32, f64),
    Counters { rng: u64, handled: u64 },
}

fn restore(book: &mut Book, undo: Undo) {
    match undo {
        Undo::Cell(k, v) => book.cells[k as usize] = v,
        Undo::Counters { rng, handled } => {
            book.rng = rng;
            book.handled = handled;
        }
    }
}

/// SplitMix64: the next word of a stream.
fn next(rng: &mut u64) -> u64 {
    *rng = rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *rng;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Ledger {
    fn books(&self) -> Vec<Book> {
        (0..self.objects)
            .map(|i| Book {
                cells: (0..CELLS)
                    .map(|k| (k as f64 + 0.5) / f64::from(i + 1))
                    .collect(),
                rng: u64::from(i) * 7919 + 1,
                handled: 0,
            })
            .collect()
    }

    /// Sends one message on, after a random delay (sometimes none: a zero-delay relay).
    fn forward(&self, ctx: &mut Ctx<'_, Ledger>, book: &mut Book, payload: u64) {
        let r = next(&mut book.rng);
        let to = (r % u64::from(self.objects)) as u32;
        if r >> 60 == 0 {
            ctx.send_now(to, payload);
        } else {
            let delay = 0.05 + ((r >> 11) as f64) / ((1u64 << 53) as f64);
            let at = ctx.now().t() + delay;
            ctx.send_at(to, VTime::at(PlainTime(at)), payload);
        }
    }
}

impl Model for Ledger {
    type Time = PlainTime;
    type Msg = u64;
    type State = Book;
    type Output = (u32, u64);
    type Undo = Undo;

    fn kind_names(&self) -> &'static [&'static str] {
        &["Entry"]
    }
    fn kind(&self, _: &u64) -> usize {
        0
    }
    fn priority(&self, _: &u64) -> u8 {
        0
    }
    /// Even objects are saved incrementally, odd ones by copy.
    fn saving(&self, obj: u32) -> Saving<Book, Undo> {
        if obj.is_multiple_of(2) {
            Saving::Incremental { restore }
        } else {
            Saving::Copy
        }
    }
    fn init(&self, ctx: &mut Ctx<'_, Self>, _: u32, book: &mut Book) {
        for k in 0..4 {
            self.forward(ctx, book, k);
        }
    }
    fn handle(&self, ctx: &mut Ctx<'_, Self>, me: u32, book: &mut Book, batch: &[Envelope<u64>]) {
        ctx.save(|| Undo::Counters {
            rng: book.rng,
            handled: book.handled,
        });
        for env in batch {
            book.handled += 1;
            for _ in 0..3 {
                let k = (next(&mut book.rng) % CELLS as u64) as usize;
                ctx.save(|| Undo::Cell(k as u32, book.cells[k]));
                // not undoable by arithmetic: only the saved bits give it back
                book.cells[k] = (book.cells[k] * 1.000_001 + (env.msg as f64).sqrt()).sin();
            }
            let payload = next(&mut book.rng) >> 40;
            if book.handled.is_multiple_of(13) {
                ctx.emit((me, book.handled));
            }
            self.forward(ctx, book, payload);
        }
    }
}

/// What a run committed: each output with a hash of the states the sink saw with it, and the
/// final states' hash.
fn run(workers: Option<TwConfig>, until: f64) -> (Vec<(u32, u64, u64)>, u64, u64, u64) {
    let model = Ledger { objects: 32 };
    let books = model.books();
    let mut seen = Vec::new();
    let mut sink = |_: &Ledger, books: &[Book], (me, n): (u32, u64)| -> Result<(), ()> {
        seen.push((me, n, hash(&books[me as usize])));
        Ok(())
    };
    let start = VTime::start(0.0);
    let (finals, batches, rolled_back) = match workers {
        None => {
            let mut ex = Sequential::new(model, books, start);
            ex.run(until, &mut sink).unwrap();
            (ex.states().to_vec(), ex.stats().batches, 0)
        }
        Some(cfg) => {
            let mut ex = TimeWarp::new(model, books, start, &ObjectMap::RoundRobin, cfg);
            ex.run(until, &mut sink).unwrap();
            let st = ex.tw_stats();
            assert_eq!(st.committed, ex.stats().batches);
            (ex.states().to_vec(), ex.stats().batches, st.rolled_back)
        }
    };
    let all = finals.iter().fold(0u64, |h, b| h.rotate_left(7) ^ hash(b));
    (seen, all, batches, rolled_back)
}

/// The bits of every value of a state.
fn hash(b: &Book) -> u64 {
    let mut h = b.rng ^ b.handled.rotate_left(32);
    for c in &b.cells {
        h = (h ^ c.to_bits()).wrapping_mul(0x100_0000_01b3);
    }
    h
}

#[test]
fn incremental_saving_commits_the_sequential_run() {
    let want = run(None, 20.0);
    assert!(
        want.2 > 3000 && want.0.len() > 200,
        "a run of some length: {} batches",
        want.2
    );
    for workers in [1usize, 2, 3] {
        for (chaos, final_batches) in [(None, true), (Some(3), true), (Some(9), false)] {
            let cfg = TwConfig {
                workers,
                chaos,
                final_batches,
                gvt_interval: Some(32),
                ..Default::default()
            };
            let got = run(Some(cfg), 20.0);
            let what = format!("{workers} workers, chaos {chaos:?}, final {final_batches}");
            assert_eq!(got.2, want.2, "{what}: batches");
            assert_eq!(got.1, want.1, "{what}: final states");
            assert!(
                got.0 == want.0,
                "{what}: outputs and the states seen with them differ"
            );
            if chaos.is_some() && workers > 1 {
                assert!(got.3 > 100, "{what}: rollbacks to test ({})", got.3);
            }
        }
    }
}

#[test]
fn a_rollback_restores_the_recorded_bits_only_where_a_batch_saved_them() {
    // the sequential executor keeps no records: saving costs it nothing and changes nothing
    let model = Ledger { objects: 2 };
    let mut books = model.books();
    let mut seq = 0;
    let mut journal = Vec::new();
    let before = books[0].clone();
    {
        let mut ctx =
            Ctx::speculative(&model, VTime::start(1.0), 0, &mut seq).journaled(&mut journal);
        assert!(ctx.saves());
        let batch = [Envelope {
            from: 1,
            seq: 1,
            msg: 12345,
        }];
        model.handle(&mut ctx, 0, &mut books[0], &batch);
    }
    assert_eq!(journal.len(), 4, "the counters and three cells");
    assert_ne!(hash(&books[0]), hash(&before));
    while let Some(undo) = journal.pop() {
        restore(&mut books[0], undo);
    }
    assert_eq!(hash(&books[0]), hash(&before), "restored bit for bit");
    let mut ctx = Ctx::new(&model, VTime::start(1.0), 0, &mut seq);
    assert!(!ctx.saves());
    ctx.save(|| unreachable!("no record is made where none is kept"));
}
