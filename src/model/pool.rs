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
    /// A ball of the scenario as it starts at `t0`, shared with the messages that will carry it.
    pub fn starting(b: &BallSpec, t0: f64) -> Arc<BallInfo> {
        Arc::new(BallInfo {
            traj: Trajectory {
                position: b.position,
                velocity: b.velocity,
                t0,
            },
            radius: b.radius,
            mass: b.mass,
            fixed: Key::start(t0),
            version: 0,
            pocket: None,
        })
    }

    /// The trajectory is fixed at `key` now (a new version, unless it was fixed there already).
    pub fn fix(&mut self, key: &Key) {
        if self.fixed != *key {
            self.fixed = key.clone();
            self.version += 1;
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
            match &env.msg {
                PoolMsg::Collision {
                    partner,
                    info: other,
                } => {
                    if info.pocket.is_some() {
                        continue;
                    }
                    // the collision happens: if this ball scheduled it, it is no longer planned
                    if let Some(k) = planned.iter().position(|p| p.partner == *partner) {
                        planned.swap_remove(k);
                    }
                    let now = ctx.now().clone();
                    let t = now.t();
                    let me_info = Arc::make_mut(info);
                    let p = me_info.traj.at(t);
                    let mut kind = None;
                    if let Some(o) = other {
                        let q = o.traj.at(t);
                        let (v, _) = if me < *partner {
                            let (a, b) = physics::ball_ball_velocities(
                                p,
                                me_info.traj.velocity,
                                me_info.mass,
                                q,
                                o.traj.velocity,
                                o.mass,
                            );
                            (a, b)
                        } else {
                            let (a, b) = physics::ball_ball_velocities(
                                q,
                                o.traj.velocity,
                                o.mass,
                                p,
                                me_info.traj.velocity,
                                me_info.mass,
                            );
                            (b, a)
                        };
                        me_info.traj.velocity = v;
                        if me > *partner {
                            kind = Some((EventKind::BallBall, *partner, me));
                        }
                    } else {
                        match self.table.bounce(*partner, p, me_info.traj.velocity) {
                            Some(v) => me_info.traj.velocity = v,
                            None => {
                                let Fixed::Pocket(k) = self.table.fixed(*partner) else {
                                    unreachable!("only pockets swallow balls")
                                };
                                me_info.pocket = Some(k);
                            }
                        }
                        kind = Some((self.table.event_kind(*partner), me, *partner));
                    }
                    me_info.traj.position = p;
                    me_info.traj.t0 = t;
                    me_info.fix(&now.key);
                    changed = true;
                    if let Some((kind, a, b)) = kind {
                        ctx.emit(PoolOutput::Event(Event { t, kind, a, b }));
                    }
                }
                PoolMsg::ReverseYourself => {
                    let now = ctx.now().clone();
                    match Arc::make_mut(info).reverse(me, &now, &self.table) {
                        None => changed = true,
                        Some(back) => {
                            ctx.send_at(me, VTime::at(back), PoolMsg::ReturnToTable);
                        }
                    }
                }
                PoolMsg::DisplayYourself => {
                    let t = ctx.now().t();
                    let mut state = (**info).clone();
                    if state.pocket.is_none() {
                        state.traj.position = state.traj.at(t);
                        state.traj.t0 = t;
                    }
                    ctx.emit(PoolOutput::Draw { t, ball: me, state });
                }
                PoolMsg::ReturnToTable => {
                    let now = ctx.now().clone();
                    let ev = Arc::make_mut(info).come_back(me, &now, &self.table);
                    changed = true;
                    ctx.emit(PoolOutput::Event(ev));
                }
                PoolMsg::NewVelocity(x) => {
                    let from = env.from;
                    cancel_with(ctx, planned, from);
                    if info.pocket.is_some() || x.pocket.is_some() {
                        continue;
                    }
                    // both changed at one key: the higher-numbered ball schedules the pair
                    if x.fixed == info.fixed && from > me {
                        continue;
                    }
                    let (lo, hi) = if me < from {
                        (&**info, &**x)
                    } else {
                        (&**x, &**info)
                    };
                    let contact =
                        physics::ball_ball_contact(&lo.traj, lo.radius, &hi.traj, hi.radius);
                    let now = ctx.now().clone();
                    let parent = if info.fixed > x.fixed {
                        &info.fixed
                    } else {
                        &x.fixed
                    };
                    let closing = || overlapping_and_closing(lo, hi, now.t());
                    if let Some(key) =
                        self.contact_key(&now, contact, parent, pair(me, from), closing)
                    {
                        let p =
                            Self::schedule(ctx, me, from, key, Some(info.clone()), Some(x.clone()));
                        planned.push(p);
                    }
                }
            }
        }
        if changed {
            for p in planned.drain(..) {
                p.cancel(ctx);
            }
            let n = self.n_objects();
            self.broadcast(ctx, me, info, (0..n).filter(|&o| o != me));
        }
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
