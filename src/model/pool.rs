//! The pool objects of thesis fig. 3 as kernel objects: balls, cushions, pockets and corners.
//!
//! ```text
//!                 NewVelocity (to every other object; at start only to higher-numbered balls)
//!   Ball ─────────────────────────────────────────────────────────► Ball / Cushion / Pocket / Corner
//!    ▲                                                                     │
//!    │            Collision (to the ball, and to itself)                   │
//!    └─────────────────────────────────────────────────────────────────────┘
//!                 Cancel (the kernel retracts both Collision messages)
//!
//!   Ball ──ReverseYourself──► itself (at the reversal, 4.6)
//!   Ball ──ReturnToTable────► itself (a pocketed ball comes back out, fig. 13)
//!   Projector ──DisplayYourself──► every object, and itself at the next frame time (4.2)
//! ```
//!
//! When a ball changes velocity it cancels the collisions it scheduled and tells every other
//! object its new trajectory. The receiver cancels what it had scheduled with that ball and, if
//! they will meet, schedules the collision by sending a Collision message to the ball and one to
//! itself (thesis 2.3). Exactly one object schedules each pair: a fixed object always; of two
//! balls, the receiver of the NewVelocity, except that when both changed at the same key (they
//! just collided) only the higher-numbered one does (it is the one told by a lower-numbered ball,
//! as at start, 4.1).
//!
//! Exact mode (`delay = 0`): NewVelocity goes out with zero delay, so it arrives within the same
//! key, and a collision's key is a pure function of the two trajectories and the keys they were
//! fixed at, exactly as in the event-list engine. The physical events are then the event-list
//! engine's, in the same order, bit for bit.
//!
//! Thesis mode (`delay = d > 0`, 4.4): NewVelocity arrives `d` later; a collision found in the past
//! is made immediate if the balls still overlap and close (5.3). Each ball computes its new
//! velocity from the partner's trajectory carried in the Collision message, as the thesis does, so
//! this mode shows the thesis' errors: lost updates in simultaneous collisions (table 2), balls
//! compressed into each other, and tunneling above `(r1 + r2) / d`.

use super::MessageKind;
use crate::engine::{Event, EventKind, Fixed, Span, Table};
use crate::geometry::Trajectory;
use crate::physics::{self, Contact};
use crate::scenario::{BallSpec, Scenario};
use crate::vtime::{pair, Key, DISPLAY, REVERSAL};
use pdes_kernel::{Ctx, Envelope, Model, SentTwo, VTime};
use std::sync::Arc;

/// What a ball tells others about itself.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BallInfo {
    /// Trajectory since its last velocity change.
    pub traj: Trajectory,
    /// Radius.
    pub radius: f64,
    /// Mass.
    pub mass: f64,
    /// The key of the event that fixed the trajectory.
    pub fixed: Key,
    /// How many times `fixed` has changed: it orders one ball's trajectories as `fixed` does,
    /// in a word that a sector's state or a message can copy for nothing.
    pub version: u64,
    /// The pocket it dropped into.
    pub pocket: Option<u32>,
}

impl BallInfo {
    /// A ball of the scenario as a run that starts at `start` takes it (fixed there, or where
    /// a checkpoint says), shared with the messages that will carry it.
    pub fn starting(b: &BallSpec, start: f64) -> Arc<BallInfo> {
        let fixed = b.fixed_at(start);
        Arc::new(BallInfo {
            traj: Trajectory {
                position: b.position,
                velocity: b.velocity,
                t0: fixed.t,
            },
            radius: b.radius,
            mass: b.mass,
            fixed,
            version: 0,
            pocket: b.pocket,
        })
    }

    /// The trajectory is fixed at `key` now (a new version, unless it was fixed there already).
    pub fn fix(&mut self, key: &Key) {
        if self.fixed != *key {
            self.fixed = key.clone();
            self.version += 1;
        }
    }

    /// Ball `me` meets ball `partner`, on trajectory `other`, now: it takes its velocity after
    /// the collision, computed with the lower-numbered ball first so that both partners compute
    /// the same numbers. The event to report, from the higher-numbered ball only (once a pair).
    #[inline]
    pub fn collide(
        &mut self,
        me: u32,
        partner: u32,
        other: &BallInfo,
        now: &VTime<Key>,
    ) -> Option<Event> {
        let t = now.t();
        let p = self.traj.at(t);
        let q = other.traj.at(t);
        let (mine, theirs) = (self.traj.velocity, other.traj.velocity);
        let v = if me < partner {
            physics::ball_ball_velocities(p, mine, self.mass, q, theirs, other.mass).0
        } else {
            physics::ball_ball_velocities(q, theirs, other.mass, p, mine, self.mass).1
        };
        self.traj = Trajectory {
            position: p,
            velocity: v,
            t0: t,
        };
        self.fix(&now.key);
        (me > partner).then_some(Event {
            t,
            kind: EventKind::BallBall,
            a: partner,
            b: me,
        })
    }

    /// Ball `me` hits fixed object `f` of `table` now: it bounces off a cushion or a corner, or
    /// drops into a pocket. The event to report.
    #[inline]
    pub fn hit(&mut self, me: u32, f: u32, table: &Table, now: &VTime<Key>) -> Event {
        let t = now.t();
        let p = self.traj.at(t);
        match table.bounce(f, p, self.traj.velocity) {
            Some(v) => self.traj.velocity = v,
            None => {
                let Fixed::Pocket(k) = table.fixed(f) else {
                    unreachable!("only pockets swallow balls")
                };
                self.pocket = Some(k);
            }
        }
        self.traj.position = p;
        self.traj.t0 = t;
        self.fix(&now.key);
        Event {
            t,
            kind: table.event_kind(f),
            a: me,
            b: f,
        }
    }

    /// This ball (number `me`) and ball `other_id`, on `other`, in the order of their numbers:
    /// the order in which every computation about the pair runs, so that both get one answer.
    #[inline]
    pub fn by_number<'a>(
        &'a self,
        me: u32,
        other_id: u32,
        other: &'a BallInfo,
    ) -> (&'a BallInfo, &'a BallInfo) {
        if me < other_id {
            (self, other)
        } else {
            (other, self)
        }
    }

    /// The later of the keys at which this trajectory and `other` were fixed: the parent of an
    /// instantaneous contact between the two balls.
    #[inline]
    pub fn later_fix<'a>(&'a self, other: &'a BallInfo) -> &'a Key {
        if self.fixed > other.fixed {
            &self.fixed
        } else {
            &other.fixed
        }
    }

    /// Turns ball `me` around at `now` (thesis 4.6, fig. 13). On the table it takes a position fix
    /// and reverses: `None`, its trajectory changed now. In a pocket it reverses the crossing it
    /// dropped in by and returns the key at which it comes back out (the mirror image in time).
    pub fn reverse(&mut self, me: u32, now: &VTime<Key>, table: &Table) -> Option<Key> {
        let back = match self.pocket {
            None => {
                self.traj.position = self.traj.at(now.t());
                self.traj.t0 = now.t();
                self.fix(&now.key);
                None
            }
            Some(k) => {
                let back = 2.0 * now.t() - self.traj.t0;
                self.traj.t0 = back;
                let f = table.fixed_id(Fixed::Pocket(k));
                Some(return_key(&now.key, back, pair(me, f)))
            }
        };
        self.traj.velocity = -self.traj.velocity;
        back
    }

    /// Ball `me` comes back out of its pocket at `now`: the event to report (a mirrored pocket
    /// crossing).
    pub fn come_back(&mut self, me: u32, now: &VTime<Key>, table: &Table) -> Event {
        let k = self.pocket.take().expect("only a pocketed ball returns");
        self.fix(&now.key);
        Event {
            t: now.t(),
            kind: EventKind::BallPocket,
            a: me,
            b: table.fixed_id(Fixed::Pocket(k)),
        }
    }
}

/// Messages of the pool simulation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum PoolMsg {
    /// A ball's new trajectory (thesis NewVelocity).
    NewVelocity(Arc<BallInfo>),
    /// A scheduled collision of the receiver with `partner`; for a ball partner, the partner's
    /// trajectory as the scheduler knew it.
    Collision {
        /// The other object of the collision.
        partner: u32,
        /// The partner ball's state when the collision was scheduled.
        info: Option<Arc<BallInfo>>,
    },
    /// Turn around now (thesis 4.6), sent by each ball to itself at the start.
    ReverseYourself,
    /// Come back out of the pocket now (thesis fig. 13), sent by a pocketed ball to itself.
    ReturnToTable,
    /// Draw yourself (thesis 4.2), sent by the Projector every frame time.
    DisplayYourself,
}

/// What the pool objects report.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum PoolOutput {
    /// A physical event.
    Event(Event),
    /// A ball drawing itself for the frame at `t`.
    Draw {
        /// The frame's time.
        t: f64,
        /// The ball.
        ball: u32,
        /// Its state, fixed at `t`.
        state: BallInfo,
    },
}

/// Type indices of the messages, for the statistics.
pub const NEW_VELOCITY: usize = 0;
/// See [`NEW_VELOCITY`].
pub const COLLISION: usize = 1;
/// See [`NEW_VELOCITY`].
pub const REVERSE_YOURSELF: usize = 2;
/// See [`NEW_VELOCITY`].
pub const RETURN_TO_TABLE: usize = 3;
/// See [`NEW_VELOCITY`].
pub const DISPLAY_YOURSELF: usize = 4;

/// One collision an object scheduled: the partner and the two Collision messages.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct Planned {
    /// The other object of the collision (the one that is not the scheduler).
    pub partner: u32,
    /// The Collision messages to the scheduler itself and to the partner.
    pub sent: SentTwo,
}

impl Planned {
    /// Retracts both Collision messages (two thesis Cancel messages).
    pub fn cancel<M: Model + ?Sized>(self, ctx: &mut Ctx<'_, M>) {
        ctx.cancel_two(self.sent, self.partner);
    }
}

/// Cancels the collision `planned` holds with `partner`, if any.
pub fn cancel_with<M: Model + ?Sized>(
    ctx: &mut Ctx<'_, M>,
    planned: &mut Vec<Planned>,
    partner: u32,
) {
    if let Some(k) = planned.iter().position(|p| p.partner == partner) {
        planned.swap_remove(k).cancel(ctx);
    }
}

/// The collisions a fixed object scheduled, by ball. A cushion hears of every ball, so this
/// holds up to one entry per ball: a persistent map, so that cancelling costs O(1) (not a scan)
/// and saving the state, as Time Warp does before every batch, costs O(1) too (the copy shares
/// everything but the path an update changes).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Plans(
    imbl::GenericHashMap<
        u32,
        Planned,
        rustc_hash::FxBuildHasher,
        imbl::shared_ptr::DefaultSharedPtr,
    >,
);

impl Plans {
    /// Records a collision scheduled with `p.partner`.
    pub fn add(&mut self, p: Planned) {
        self.0.insert(p.partner, p);
    }

    /// Forgets the collision with `partner`: it is happening.
    pub fn forget(&mut self, partner: u32) {
        self.0.remove(&partner);
    }

    /// Cancels the collision scheduled with `partner`, if any.
    pub fn cancel_with<M: Model + ?Sized>(&mut self, ctx: &mut Ctx<'_, M>, partner: u32) {
        if let Some(p) = self.0.remove(&partner) {
            p.cancel(ctx);
        }
    }
}

/// A pool object's state.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum PoolState {
    /// A ball and the collisions it scheduled.
    Ball {
        /// Its trajectory and properties.
        info: Arc<BallInfo>,
        /// Collisions it scheduled.
        planned: Vec<Planned>,
    },
    /// A cushion, pocket or corner and the collisions it scheduled.
    Fixed {
        /// Collisions it scheduled.
        planned: Plans,
        /// Balls it holds (pockets only), in the order they dropped in.
        holds: Vec<u32>,
    },
    /// The Projector: the frames it has shown.
    Projector {
        /// Frames shown so far.
        frames: u64,
    },
}

/// How NewVelocity messages travel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NvDelay {
    /// Zero delay: exact (the default).
    Exact,
    /// The thesis' small positive delay (4.4).
    Delay(f64),
}

/// The pool model: the table (static configuration), the NewVelocity delay and the reversal.
pub struct Pool {
    table: Table,
    delay: NvDelay,
    span: Span,
}

impl Pool {
    /// The model and the initial states of every object of a validated scenario, starting at
    /// `span.start`.
    pub fn new(s: &Scenario, delay: NvDelay, span: Span) -> (Pool, Vec<PoolState>) {
        let table = Table::new(s);
        let mut states: Vec<PoolState> = s
            .balls
            .iter()
            .map(|b| PoolState::Ball {
                info: BallInfo::starting(b, span.start),
                planned: Vec::new(),
            })
            .collect();
        for _ in 0..table.n_fixed() {
            states.push(PoolState::Fixed {
                planned: Plans::default(),
                holds: Vec::new(),
            });
        }
        if span.frame_time.is_some() {
            states.push(PoolState::Projector { frames: 0 });
        }
        (Pool { table, delay, span }, states)
    }

    /// The table.
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// The number of table objects (balls and fixed objects; the Projector comes after them).
    pub fn n_objects(&self) -> u32 {
        self.table.n_balls + self.table.n_fixed()
    }

    /// The Projector's next frame: a DisplayYourself to itself.
    fn next_frame(&self, ctx: &mut Ctx<'_, Pool>, me: u32, frames: &mut u64) {
        if let Some(t) = self.span.frame(*frames) {
            *frames += 1;
            ctx.send_at(me, VTime::at(Key::at(t, DISPLAY)), PoolMsg::DisplayYourself);
        }
    }

    /// The virtual time at which a NewVelocity sent now to `to` arrives.
    fn nv_time(&self, ctx: &Ctx<'_, Pool>, me: u32, to: u32) -> VTime<Key> {
        match self.delay {
            NvDelay::Exact => ctx.now().next_gen(),
            NvDelay::Delay(d) => VTime::at(Key::at(ctx.now().t() + d, pair(me, to))),
        }
    }

    /// Sends ball `me`'s new trajectory to `targets`.
    fn broadcast(
        &self,
        ctx: &mut Ctx<'_, Pool>,
        me: u32,
        info: &Arc<BallInfo>,
        targets: impl Iterator<Item = u32>,
    ) {
        for to in targets {
            let time = self.nv_time(ctx, me, to);
            ctx.relay_at(to, time, PoolMsg::NewVelocity(info.clone()));
        }
    }

    /// The key of a contact found now, or `None`. In thesis mode a contact already in the past
    /// becomes immediate if the objects still overlap and close (5.3).
    fn contact_key(
        &self,
        now: &VTime<Key>,
        contact: Contact,
        parent: &Key,
        p: crate::vtime::Pair,
        still_closing: impl Fn() -> bool,
    ) -> Option<Key> {
        match (contact, self.delay) {
            (Contact::Never, _) => None,
            (Contact::At(t), NvDelay::Exact) => Some(Key::at(t, p)),
            (Contact::Immediate, NvDelay::Exact) => Some(parent.child(p)),
            (Contact::At(t), NvDelay::Delay(_)) if t > now.t() => Some(Key::at(t, p)),
            (_, NvDelay::Delay(_)) => still_closing().then(|| now.key.child(p)),
        }
    }

    /// Schedules the collision of `me` and `partner` at `key`: a Collision message to each.
    fn schedule(
        ctx: &mut Ctx<'_, Pool>,
        me: u32,
        partner: u32,
        key: Key,
        mine: Option<Arc<BallInfo>>,
        theirs: Option<Arc<BallInfo>>,
    ) -> Planned {
        debug_assert_eq!(me, ctx.me(), "an object schedules its own collisions");
        let sent = ctx.send_two(
            partner,
            VTime::at(key),
            PoolMsg::Collision {
                partner,
                info: theirs,
            },
            PoolMsg::Collision {
                partner: me,
                info: mine,
            },
        );
        Planned { partner, sent }
    }

    /// A ball's batch: one handler per message; if its trajectory changed, it cancels the
    /// collisions it planned and tells every other object.
    fn ball_batch(
        &self,
        ctx: &mut Ctx<'_, Pool>,
        me: u32,
        info: &mut Arc<BallInfo>,
        planned: &mut Vec<Planned>,
        batch: &[Envelope<PoolMsg>],
    ) {
        let mut changed = false;
        for env in batch {
            changed |= match &env.msg {
                PoolMsg::Collision {
                    partner,
                    info: other,
                } => self.on_collision(ctx, me, info, planned, *partner, other.as_deref()),
                PoolMsg::NewVelocity(x) => {
                    self.on_new_velocity(ctx, me, info, planned, env.from, x);
                    false
                }
                PoolMsg::ReverseYourself => self.on_reverse(ctx, me, info),
                PoolMsg::ReturnToTable => self.on_return(ctx, me, info),
                PoolMsg::DisplayYourself => {
                    Self::on_display(ctx, me, info);
                    false
                }
            };
        }
        if changed {
            for p in planned.drain(..) {
                p.cancel(ctx);
            }
            let n = self.n_objects();
            self.broadcast(ctx, me, info, (0..n).filter(|&o| o != me));
        }
    }

    /// Collision: ball `me` meets ball `partner` (whose trajectory the message carries) or fixed
    /// object `partner` now, unless it lies in a pocket. Whether its trajectory changed.
    #[inline]
    fn on_collision(
        &self,
        ctx: &mut Ctx<'_, Pool>,
        me: u32,
        info: &mut Arc<BallInfo>,
        planned: &mut Vec<Planned>,
        partner: u32,
        other: Option<&BallInfo>,
    ) -> bool {
        if info.pocket.is_some() {
            return false;
        }
        // the collision happens: if this ball scheduled it, it is no longer planned
        if let Some(k) = planned.iter().position(|p| p.partner == partner) {
            planned.swap_remove(k);
        }
        let now = ctx.now().clone();
        let me_info = Arc::make_mut(info);
        let event = match other {
            Some(o) => me_info.collide(me, partner, o, &now),
            None => Some(me_info.hit(me, partner, &self.table, &now)),
        };
        if let Some(event) = event {
            ctx.emit(PoolOutput::Event(event));
        }
        true
    }

    /// NewVelocity: ball `from` has trajectory `x` now. Ball `me` cancels the collision it planned
    /// with it and plans their next one, if they meet; when both changed at one key (they just
    /// collided), the higher-numbered ball plans the pair.
    #[inline]
    fn on_new_velocity(
        &self,
        ctx: &mut Ctx<'_, Pool>,
        me: u32,
        info: &Arc<BallInfo>,
        planned: &mut Vec<Planned>,
        from: u32,
        x: &Arc<BallInfo>,
    ) {
        cancel_with(ctx, planned, from);
        if info.pocket.is_some() || x.pocket.is_some() || (x.fixed == info.fixed && from > me) {
            return;
        }
        let (lo, hi) = info.by_number(me, from, x);
        let contact = physics::ball_ball_contact(&lo.traj, lo.radius, &hi.traj, hi.radius);
        let now = ctx.now().clone();
        let closing = || overlapping_and_closing(lo, hi, now.t());
        let parent = info.later_fix(x);
        if let Some(key) = self.contact_key(&now, contact, parent, pair(me, from), closing) {
            let p = Self::schedule(ctx, me, from, key, Some(info.clone()), Some(x.clone()));
            planned.push(p);
        }
    }

    /// ReverseYourself: ball `me` turns around (thesis 4.6). Whether its trajectory changed now
    /// (not so in a pocket: it comes back out later, by a ReturnToTable to itself).
    fn on_reverse(&self, ctx: &mut Ctx<'_, Pool>, me: u32, info: &mut Arc<BallInfo>) -> bool {
        let now = ctx.now().clone();
        match Arc::make_mut(info).reverse(me, &now, &self.table) {
            None => true,
            Some(back) => {
                ctx.send_at(me, VTime::at(back), PoolMsg::ReturnToTable);
                false
            }
        }
    }

    /// ReturnToTable: pocketed ball `me` comes back out now; its trajectory changed.
    fn on_return(&self, ctx: &mut Ctx<'_, Pool>, me: u32, info: &mut Arc<BallInfo>) -> bool {
        let now = ctx.now().clone();
        let event = Arc::make_mut(info).come_back(me, &now, &self.table);
        ctx.emit(PoolOutput::Event(event));
        true
    }

    /// DisplayYourself: ball `me` draws itself where it is now (thesis 4.2).
    fn on_display(ctx: &mut Ctx<'_, Pool>, me: u32, info: &BallInfo) {
        let t = ctx.now().t();
        let mut state = info.clone();
        if state.pocket.is_none() {
            state.traj.position = state.traj.at(t);
            state.traj.t0 = t;
        }
        ctx.emit(PoolOutput::Draw { t, ball: me, state });
    }

    fn fixed_batch(
        &self,
        ctx: &mut Ctx<'_, Pool>,
        me: u32,
        planned: &mut Plans,
        holds: &mut Vec<u32>,
        batch: &[Envelope<PoolMsg>],
    ) {
        for env in batch {
            match &env.msg {
                PoolMsg::Collision { partner, .. } => {
                    planned.forget(*partner);
                    if let Fixed::Pocket(_) = self.table.fixed(me) {
                        holds.push(*partner);
                    }
                }
                PoolMsg::DisplayYourself => {} // a fixed object looks the same in every frame
                PoolMsg::ReverseYourself | PoolMsg::ReturnToTable => {
                    unreachable!("only balls are told to reverse or return")
                }
                PoolMsg::NewVelocity(x) => {
                    let from = env.from;
                    planned.cancel_with(ctx, from);
                    if x.pocket.is_none() {
                        holds.retain(|&b| b != from); // back out after a reversal
                    }
                    if x.pocket.is_some() {
                        continue;
                    }
                    let contact = self.table.contact(me, &x.traj, x.radius);
                    let now = ctx.now().clone();
                    let closing = || self.fixed_overlapping_and_closing(me, x, now.t());
                    if let Some(key) =
                        self.contact_key(&now, contact, &x.fixed, pair(from, me), closing)
                    {
                        let p = Self::schedule(ctx, me, from, key, None, None);
                        planned.add(p);
                    }
                }
            }
        }
    }

    /// Thesis mode: whether a ball overlapping fixed object `f` at `t` still moves into it.
    fn fixed_overlapping_and_closing(&self, f: u32, x: &BallInfo, t: f64) -> bool {
        let now = Trajectory {
            position: x.traj.at(t),
            velocity: x.traj.velocity,
            t0: t,
        };
        self.table.contact(f, &now, x.radius) == Contact::Immediate
    }
}

/// The key at which a ball that dropped into a pocket comes back out at time `back` after the
/// reversal at `reversal`: an ordinary event key, or a child of the reversal if it dropped in at
/// the very instant of the reversal.
pub fn return_key(reversal: &Key, back: f64, p: crate::vtime::Pair) -> Key {
    if back > reversal.t {
        Key::at(back, p)
    } else {
        reversal.child(p)
    }
}

/// Thesis mode: whether two balls overlap at `t` and are still closing (thesis 5.3).
fn overlapping_and_closing(a: &BallInfo, b: &BallInfo, t: f64) -> bool {
    let at = |x: &BallInfo| Trajectory {
        position: x.traj.at(t),
        velocity: x.traj.velocity,
        t0: t,
    };
    physics::ball_ball_contact(&at(a), a.radius, &at(b), b.radius) == Contact::Immediate
}

impl Model for Pool {
    type Time = Key;
    type Msg = PoolMsg;
    type State = PoolState;
    type Output = PoolOutput;
    type Undo = ();

    fn kind_names(&self) -> &'static [&'static str] {
        const NAMES: [&str; 5] = [
            MessageKind::NewVelocity.name(),
            MessageKind::Collision.name(),
            MessageKind::ReverseYourself.name(),
            MessageKind::ReturnToTable.name(),
            MessageKind::DisplayYourself.name(),
        ];
        &NAMES
    }

    fn kind(&self, msg: &PoolMsg) -> usize {
        match msg {
            PoolMsg::NewVelocity(_) => NEW_VELOCITY,
            PoolMsg::Collision { .. } => COLLISION,
            PoolMsg::ReverseYourself => REVERSE_YOURSELF,
            PoolMsg::ReturnToTable => RETURN_TO_TABLE,
            PoolMsg::DisplayYourself => DISPLAY_YOURSELF,
        }
    }

    /// Thesis 4.3.1 and 4.6: Collision before NewVelocity, ReverseYourself after all others.
    fn priority(&self, msg: &PoolMsg) -> u8 {
        match msg {
            PoolMsg::Collision { .. } => 0,
            PoolMsg::ReturnToTable => 1,
            PoolMsg::NewVelocity(_) => 2,
            PoolMsg::ReverseYourself => 3,
            PoolMsg::DisplayYourself => 4,
        }
    }

    /// Thesis 4.1: each ball tells the higher-numbered balls and every fixed object its initial
    /// trajectory, so every pair is scheduled once.
    fn observed(&self, obj: u32) -> bool {
        obj < self.table.n_balls
    }

    fn init(&self, ctx: &mut Ctx<'_, Pool>, me: u32, state: &mut PoolState) {
        match state {
            PoolState::Ball { info, .. } => {
                let n = self.n_objects();
                self.broadcast(ctx, me, info, me + 1..n);
                if let Some(t) = self.span.reverse_at {
                    ctx.send_at(
                        me,
                        VTime::at(Key::at(t, REVERSAL)),
                        PoolMsg::ReverseYourself,
                    );
                }
            }
            PoolState::Projector { frames } => self.next_frame(ctx, me, frames),
            PoolState::Fixed { .. } => {}
        }
    }

    fn handle(
        &self,
        ctx: &mut Ctx<'_, Pool>,
        me: u32,
        state: &mut PoolState,
        batch: &[Envelope<PoolMsg>],
    ) {
        match state {
            PoolState::Ball { info, planned } => self.ball_batch(ctx, me, info, planned, batch),
            PoolState::Fixed { planned, holds } => self.fixed_batch(ctx, me, planned, holds, batch),
            PoolState::Projector { frames } => {
                for to in 0..self.n_objects() {
                    ctx.send_now(to, PoolMsg::DisplayYourself);
                }
                self.next_frame(ctx, me, frames);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec2;

    #[test]
    fn a_version_counts_the_keys_a_trajectory_was_fixed_at() {
        let mut info = BallInfo {
            traj: Trajectory {
                position: Vec2::new(0.0, 0.0),
                velocity: Vec2::new(1.0, 0.0),
                t0: 0.0,
            },
            radius: 1.0,
            mass: 1.0,
            fixed: Key::start(0.0),
            version: 0,
            pocket: None,
        };
        info.fix(&Key::start(0.0));
        assert_eq!(
            info.version, 0,
            "fixed again where it was: the same trajectory version"
        );
        info.fix(&Key::at(1.0, pair(0, 1)));
        info.fix(&Key::at(1.0, pair(0, 1)));
        info.fix(&Key::at(2.0, pair(0, 2)));
        assert_eq!(info.version, 2);
        assert_eq!(info.fixed, Key::at(2.0, pair(0, 2)));
    }
}
