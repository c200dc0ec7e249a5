//! The sectored pool simulation (thesis ch. 5, fig. 14 and 15): the table is cut into sectors of
//! any polygon shape, and sectors relay a ball's new trajectory only to the balls near it.
//!
//! ```text
//!        VelocityChange                 NewVelocity                Collision
//!  Ball ───────────────► its Sectors ─────────────► their Balls ─────────────► Ball (and itself)
//!    │                        │        NewVelocity                SectorEntry
//!    │                        └──────────────────► adjacent Sectors ─────────► Ball (and itself)
//!    │  NewVelocity (in reach)                       SectorDeparture
//!    └──────────────► Cushions, Pockets, Corners     Sector ────────────────► Ball (and itself)
//! ```
//!
//! A sector knows every ball whose disk touches it: it enters at the first instant it touches
//! (keyed before everything else of that instant) and leaves after everything of the instant it
//! stops touching. Any two balls that collide touch a common sector at that moment, so one of them
//! hears of the other's trajectory there in time: through a velocity change relayed by a sector
//! they share, or when one enters a sector the other is in.
//!
//! Fixed objects hear from the balls directly, as in the plain simulation, but (beyond the
//! thesis, [`FixedNews::Near`]) only from balls in sectors within reach of them: a ball tells
//! them when it changes course in such a sector or enters one. A fixed object may then hold a
//! collision computed from a trajectory the ball has since left; the ball finds it stale by its
//! version, as below, and lets it pass. [`FixedNews::Thesis`] tells every fixed object of every
//! change, for the thesis' message counts.
//!
//! Beyond the thesis: a ball may hold a collision that a ball it no longer shares a sector with
//! scheduled, so it would never hear that the other changed course. Each Collision therefore
//! carries the trajectory versions it was computed from, and the two balls exchange a
//! CollisionConfirm with zero delay before acting: the collision happens only if both are still
//! on the trajectories it was predicted for. With zero delays the physical events are then exactly
//! those of the event-list engine.

use super::layout::near_fixed;
pub use super::layout::{FixedNews, Layout};
use super::pool::{cancel_with, BallInfo, Planned, Plans};
use super::MessageKind;
use crate::engine::{Event, Span, Table};
use crate::geometry::{Trajectory, Vec2};
use crate::physics::{self, Contact};
use crate::polygon;
use crate::scenario::{BallSpec, Scenario};
use crate::vtime::{pair, Key, DEPARTURE, REVERSAL};
use pdes_kernel::{Ctx, Envelope, Model, SentTwo, VTime};
use smallvec::SmallVec;
use std::sync::Arc;

/// Messages of the sectored simulation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum SecMsg {
    /// A ball's trajectory, relayed by a sector or sent to a fixed object.
    NewVelocity {
        /// The ball.
        ball: u32,
        /// Its trajectory.
        info: Arc<BallInfo>,
    },
    /// A scheduled collision of the receiver with `partner`.
    Collision {
        /// The other object.
        partner: u32,
        /// The partner ball's trajectory as the scheduler knew it.
        info: Option<Arc<BallInfo>>,
        /// The receiver's trajectory version as the scheduler knew it.
        seen: u64,
    },
    /// Turn around now (thesis 4.6), sent by each ball to itself at the start.
    ReverseYourself,
    /// Come back out of the pocket now (thesis fig. 13), sent by a pocketed ball to itself.
    ReturnToTable,
    /// Before a ball–ball collision: is the sender still on the trajectory it was predicted for?
    CollisionConfirm {
        /// Whether the sender's own trajectory is still the one the collision was computed for.
        valid: bool,
        /// The sender's current trajectory.
        info: Arc<BallInfo>,
    },
    /// A ball tells a sector it occupies that it changed velocity.
    VelocityChange {
        /// The ball.
        ball: u32,
        /// Its new trajectory.
        info: Arc<BallInfo>,
    },
    /// A ball tells a sector it occupies its initial trajectory (thesis 5.4).
    VelocityInitialization {
        /// The ball.
        ball: u32,
        /// Its trajectory.
        info: Arc<BallInfo>,
    },
    /// A ball's disk starts touching a sector.
    SectorEntry {
        /// The ball.
        ball: u32,
        /// The sector.
        sector: u32,
        /// In the sector's own copy, the ball's trajectory the entry was computed from (relayed
        /// to the sector's balls when the ball enters): the message keeps it, so that the
        /// sector's state holds no shared pointers to copy when it is saved.
        info: Option<Arc<BallInfo>>,
    },
    /// A ball's disk stops touching a sector.
    SectorDeparture {
        /// The ball.
        ball: u32,
        /// The sector.
        sector: u32,
    },
}

const KIND_NAMES: [&str; 9] = [
    MessageKind::NewVelocity.name(),
    MessageKind::Collision.name(),
    MessageKind::VelocityChange.name(),
    MessageKind::SectorEntry.name(),
    MessageKind::SectorDeparture.name(),
    MessageKind::VelocityInitialization.name(),
    MessageKind::CollisionConfirm.name(),
    MessageKind::ReverseYourself.name(),
    MessageKind::ReturnToTable.name(),
];

/// A sector's scheduled entry or departure of one ball.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct Passage {
    /// The ball.
    pub ball: u32,
    /// For an entry, the version of the ball's trajectory it was computed from; [`DEPARTS`]
    /// for a departure (a word, not an `Option` of one, so that a passage takes 40 bytes, not
    /// 48: a sector's state is mostly passages, and Time Warp copies it before each batch it
    /// may undo).
    entry: u64,
    /// The messages to the sector itself and to the ball.
    pub sent: SentTwo,
}

/// [`Passage`]'s `entry` of a departure: no trajectory has this version (one ball would
/// have to change course 2^64 - 1 times).
const DEPARTS: u64 = u64::MAX;

impl Passage {
    /// For an entry, the version of the ball's trajectory it was computed from; `None` for a
    /// departure.
    pub fn entry(&self) -> Option<u64> {
        (self.entry != DEPARTS).then_some(self.entry)
    }
}

/// The sectors a ball's disk touches: rarely more than four, kept inline so that saving the
/// ball's state (Time Warp) allocates nothing for them.
pub type Sectors = SmallVec<[u32; 4]>;

/// An object's state in the sectored simulation.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub enum SecState {
    /// A ball.
    Ball {
        /// Its trajectory.
        info: Arc<BallInfo>,
        /// Collisions it scheduled.
        planned: Vec<Planned>,
        /// Sectors its disk touches.
        sectors: Sectors,
        /// Ball–ball collisions awaiting the partner's confirmation: partner, own validity.
        awaiting: Vec<(u32, bool)>,
    },
    /// A cushion, pocket or corner.
    Fixed {
        /// Collisions it scheduled.
        planned: Plans,
    },
    /// A sector.
    Sector {
        /// Balls whose disks touch it, with the version ([`BallInfo::version`]) of their
        /// trajectories as last heard: a word, not the trajectory or its key, so that saving the
        /// state is one plain copy.
        members: Vec<(u32, u64)>,
        /// Entries and departures it scheduled.
        planned: Vec<Passage>,
    },
}

/// Written out so that `clone_from`, with which Time Warp saves a state before each batch it
/// may undo, copies into the buffers of a saved state it no longer needs instead of allocating.
impl Clone for SecState {
    fn clone(&self) -> Self {
        match self {
            SecState::Ball {
                info,
                planned,
                sectors,
                awaiting,
            } => SecState::Ball {
                info: info.clone(),
                planned: planned.clone(),
                sectors: sectors.clone(),
                awaiting: awaiting.clone(),
            },
            SecState::Fixed { planned } => SecState::Fixed {
                planned: planned.clone(),
            },
            SecState::Sector { members, planned } => SecState::Sector {
                members: members.clone(),
                planned: planned.clone(),
            },
        }
    }

    fn clone_from(&mut self, source: &Self) {
        match (self, source) {
            (
                SecState::Ball {
                    info,
                    planned,
                    sectors,
                    awaiting,
                },
                SecState::Ball {
                    info: i,
                    planned: p,
                    sectors: s,
                    awaiting: a,
                },
            ) => {
                info.clone_from(i);
                planned.clone_from(p);
                sectors.clone_from(s);
                awaiting.clone_from(a);
            }
            (
                SecState::Sector { members, planned },
                SecState::Sector {
                    members: m,
                    planned: p,
                },
            ) => {
                members.clone_from(m);
                planned.clone_from(p);
            }
            (this, source) => *this = source.clone(),
        }
    }
}

/// A ball's state while it handles one batch of messages, and what the batch has done so far.
struct BallTurn<'s> {
    me: u32,
    info: &'s mut Arc<BallInfo>,
    planned: &'s mut Vec<Planned>,
    sectors: &'s mut Sectors,
    awaiting: &'s mut Vec<(u32, bool)>,
    /// The balls heard from (by a collision or a new trajectory): once a batch is enough.
    heard: Vec<u32>,
    /// Whether the trajectory changed.
    changed: bool,
}

impl BallTurn<'_> {
    /// Whether this is the batch's first word from `ball` (and notes it).
    #[inline]
    fn first_from(&mut self, ball: u32) -> bool {
        let first = !self.heard.contains(&ball);
        if first {
            self.heard.push(ball);
        }
        first
    }
}

/// The sectored pool model.
pub struct Sectored {
    table: Table,
    layout: Layout,
    span: Span,
    /// For each sector (from 0), the fixed objects within reach of a ball touching it.
    near_fixed: Vec<Vec<u32>>,
    /// Fixed objects near no sector: every ball tells them every trajectory.
    far_fixed: Vec<u32>,
}

/// Where ball `b` is when a run that starts at `start` takes it up.
fn starting_position(b: &BallSpec, start: f64) -> Vec2 {
    match &b.fixed {
        None => b.position,
        Some(k) => Trajectory {
            position: b.position,
            velocity: b.velocity,
            t0: k.t,
        }
        .at(start),
    }
}

impl Sectored {
    /// The model and initial states of a validated scenario over `layout`, starting at
    /// `span.start` (frames are not drawn here); the balls' sectors are found on `threads`
    /// threads (Time Warp builds its model with as many as it has workers).
    pub fn new(
        s: &Scenario,
        layout: Layout,
        span: Span,
        threads: usize,
    ) -> (Sectored, Vec<SecState>) {
        let table = Table::new(s);
        let n = table.n_balls;
        let first_sector = n + table.n_fixed();
        let balls = |specs: &[BallSpec]| -> Vec<SecState> {
            specs
                .iter()
                .map(|b| SecState::Ball {
                    info: BallInfo::starting(b, span.start),
                    planned: Vec::new(),
                    // where it is at the start; a ball in a pocket is in no sector
                    sectors: match b.pocket {
                        Some(_) => SmallVec::new(),
                        None => layout
                            .touching(starting_position(b, span.start), b.radius)
                            .into_iter()
                            .map(|k| first_sector + k)
                            .collect(),
                    },
                    awaiting: Vec::new(),
                })
                .collect()
        };
        let objects = first_sector as usize + layout.polys.len();
        let mut states: Vec<SecState> = Vec::with_capacity(objects);
        let chunk = s.balls.len().div_ceil(threads.max(1)).max(1);
        if threads > 1 && s.balls.len() > chunk {
            let balls = &balls;
            std::thread::scope(|scope| {
                let parts: Vec<_> = s
                    .balls
                    .chunks(chunk)
                    .map(|c| scope.spawn(move || balls(c)))
                    .collect();
                for p in parts {
                    states.extend(p.join().expect("finding sectors does not panic"));
                }
            });
        } else {
            states.extend(balls(&s.balls));
        }
        let mut members: Vec<Vec<(u32, u64)>> = vec![Vec::new(); layout.polys.len()];
        for (i, st) in states.iter().enumerate() {
            if let SecState::Ball { info, sectors, .. } = st {
                for &k in sectors {
                    members[(k - first_sector) as usize].push((i as u32, info.version));
                }
            }
        }
        for _ in 0..table.n_fixed() {
            states.push(SecState::Fixed {
                planned: Plans::default(),
            });
        }
        for m in members {
            states.push(SecState::Sector {
                members: m,
                planned: Vec::new(),
            });
        }
        let rmax = s.balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        let (near_fixed, far_fixed) = near_fixed(&table, &layout, rmax);
        (
            Sectored {
                table,
                layout,
                span,
                near_fixed,
                far_fixed,
            },
            states,
        )
    }

    /// The table.
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    fn first_sector(&self) -> u32 {
        self.table.n_balls + self.table.n_fixed()
    }

    /// The fixed objects a ball in `sectors` could reach before it leaves them, in order.
    fn fixed_near(&self, sectors: &[u32]) -> SmallVec<[u32; 8]> {
        let first = self.first_sector();
        let mut fs = SmallVec::from_slice(&self.far_fixed);
        for &s in sectors {
            fs.extend_from_slice(&self.near_fixed[(s - first) as usize]);
        }
        fs.sort_unstable();
        fs.dedup();
        fs
    }

    /// Tells ball `me`'s trajectory to the fixed objects it could reach from `sectors`.
    fn tell_fixed(
        &self,
        ctx: &mut Ctx<'_, Sectored>,
        me: u32,
        info: &Arc<BallInfo>,
        sectors: &[u32],
    ) {
        self.tell(ctx, me, info, &self.fixed_near(sectors));
    }

    /// Tells ball `me`'s trajectory to the fixed objects `fs`.
    fn tell(&self, ctx: &mut Ctx<'_, Sectored>, me: u32, info: &Arc<BallInfo>, fs: &[u32]) {
        for &f in fs {
            ctx.send_now(
                f,
                SecMsg::NewVelocity {
                    ball: me,
                    info: info.clone(),
                },
            );
        }
    }

    /// Schedules a collision of `me` with `partner` at `key`.
    #[allow(clippy::too_many_arguments)]
    fn schedule(
        ctx: &mut Ctx<'_, Sectored>,
        me: u32,
        partner: u32,
        key: Key,
        mine: Option<Arc<BallInfo>>,
        my_version: u64,
        theirs: Option<Arc<BallInfo>>,
        their_version: u64,
    ) -> Planned {
        debug_assert_eq!(me, ctx.me(), "an object schedules its own collisions");
        let sent = ctx.send_two(
            partner,
            VTime::at(key),
            SecMsg::Collision {
                partner,
                info: theirs,
                seen: my_version,
            },
            SecMsg::Collision {
                partner: me,
                info: mine,
                seen: their_version,
            },
        );
        Planned { partner, sent }
    }

    fn key_of(contact: Contact, parent: &Key, p: crate::vtime::Pair) -> Option<Key> {
        match contact {
            Contact::Never => None,
            Contact::At(t) => Some(Key::at(t, p)),
            Contact::Immediate => Some(parent.child(p)),
        }
    }

    /// A ball's batch: one handler per message; then, if its trajectory changed, it cancels
    /// the collisions it planned and tells its sectors and the fixed objects within reach.
    fn ball_batch(
        &self,
        ctx: &mut Ctx<'_, Sectored>,
        mut turn: BallTurn<'_>,
        batch: &[Envelope<SecMsg>],
    ) {
        // the fixed objects that know the trajectory already, when the ball may enter sectors
        let entering = batch
            .iter()
            .any(|e| matches!(e.msg, SecMsg::SectorEntry { .. }));
        let knew = entering.then(|| self.fixed_near(turn.sectors));
        for env in batch {
            match &env.msg {
                SecMsg::Collision {
                    partner,
                    info: other,
                    seen,
                } => self.on_collision(ctx, &mut turn, *partner, other.is_some(), *seen),
                SecMsg::CollisionConfirm { valid, info: other } => {
                    Self::on_confirm(ctx, &mut turn, env.from, *valid, other)
                }
                SecMsg::NewVelocity { ball, info: x } => {
                    Self::on_new_velocity(ctx, &mut turn, *ball, x)
                }
                SecMsg::ReverseYourself => self.on_reverse(ctx, &mut turn),
                SecMsg::ReturnToTable => self.on_return(ctx, &mut turn),
                SecMsg::SectorEntry { sector, .. } => {
                    if !turn.sectors.contains(sector) {
                        turn.sectors.push(*sector);
                    }
                }
                SecMsg::SectorDeparture { sector, .. } => turn.sectors.retain(|s| s != sector),
                SecMsg::VelocityChange { .. } | SecMsg::VelocityInitialization { .. } => {
                    unreachable!("balls are not told of velocity changes by balls")
                }
            }
        }
        if turn.changed {
            self.tell_change(ctx, turn);
        } else if let Some(knew) = knew {
            // a fixed object newly in reach hears of the trajectory on entry
            let mut now_near = self.fixed_near(turn.sectors);
            now_near.retain(|f| knew.binary_search(f).is_err());
            self.tell(ctx, turn.me, turn.info, &now_near);
        }
    }

    /// Collision with `partner`, predicted from the ball's trajectory of version `seen`. Against
    /// a fixed object it happens now if that trajectory still holds; against a ball (`with_ball`)
    /// both first confirm, by a CollisionConfirm each, that their trajectories still hold.
    #[inline]
    fn on_collision(
        &self,
        ctx: &mut Ctx<'_, Sectored>,
        turn: &mut BallTurn<'_>,
        partner: u32,
        with_ball: bool,
        seen: u64,
    ) {
        if !turn.first_from(partner) {
            return; // scheduled twice: once is enough
        }
        if let Some(k) = turn.planned.iter().position(|p| p.partner == partner) {
            turn.planned.swap_remove(k);
        }
        let valid = turn.info.version == seen && turn.info.pocket.is_none();
        if with_ball {
            let info = turn.info.clone();
            ctx.send_now(partner, SecMsg::CollisionConfirm { valid, info });
            turn.awaiting.push((partner, valid));
        } else if valid {
            let now = ctx.now().clone();
            let event = Arc::make_mut(turn.info).hit(turn.me, partner, &self.table, &now);
            ctx.emit(event);
            turn.changed = true;
        }
    }

    /// CollisionConfirm from ball `from`, on trajectory `other`: the collision happens now if
    /// both trajectories still hold.
    #[inline]
    fn on_confirm(
        ctx: &mut Ctx<'_, Sectored>,
        turn: &mut BallTurn<'_>,
        from: u32,
        valid: bool,
        other: &BallInfo,
    ) {
        let Some(k) = turn.awaiting.iter().position(|a| a.0 == from) else {
            return;
        };
        let (partner, mine) = turn.awaiting.swap_remove(k);
        if mine && valid {
            let now = ctx.now().clone();
            if let Some(event) = Arc::make_mut(turn.info).collide(turn.me, partner, other, &now) {
                ctx.emit(event);
            }
            turn.changed = true;
        }
    }

    /// NewVelocity: ball `ball` has trajectory `x` now. The ball cancels the collision it planned
    /// with it and plans their next one, if they meet; when both changed at this key, the
    /// higher-numbered ball plans the pair.
    #[inline]
    fn on_new_velocity(
        ctx: &mut Ctx<'_, Sectored>,
        turn: &mut BallTurn<'_>,
        ball: u32,
        x: &Arc<BallInfo>,
    ) {
        if !turn.first_from(ball) {
            return;
        }
        let (me, info) = (turn.me, &*turn.info);
        cancel_with(ctx, turn.planned, ball);
        if info.pocket.is_some() || x.pocket.is_some() {
            return;
        }
        if x.fixed == info.fixed && x.fixed == ctx.now().key && ball > me {
            return; // both changed at this key: the higher-numbered ball schedules
        }
        let (lo, hi) = info.by_number(me, ball, x);
        let contact = physics::ball_ball_contact(&lo.traj, lo.radius, &hi.traj, hi.radius);
        if let Some(key) = Self::key_of(contact, info.later_fix(x), pair(me, ball)) {
            let mine = Some(info.clone());
            let p = Self::schedule(
                ctx,
                me,
                ball,
                key,
                mine,
                info.version,
                Some(x.clone()),
                x.version,
            );
            turn.planned.push(p);
        }
    }

    /// ReverseYourself: the ball turns around (thesis 4.6); in a pocket it comes back out later,
    /// by a ReturnToTable to itself.
    fn on_reverse(&self, ctx: &mut Ctx<'_, Sectored>, turn: &mut BallTurn<'_>) {
        let now = ctx.now().clone();
        match Arc::make_mut(turn.info).reverse(turn.me, &now, &self.table) {
            None => turn.changed = true,
            Some(back) => {
                ctx.send_at(turn.me, VTime::at(back), SecMsg::ReturnToTable);
            }
        }
    }

    /// ReturnToTable: the pocketed ball comes back out now, into the sectors its disk touches.
    fn on_return(&self, ctx: &mut Ctx<'_, Sectored>, turn: &mut BallTurn<'_>) {
        let now = ctx.now().clone();
        let event = Arc::make_mut(turn.info).come_back(turn.me, &now, &self.table);
        let first = self.first_sector();
        *turn.sectors = self
            .layout
            .touching(turn.info.traj.position, turn.info.radius)
            .into_iter()
            .map(|s| first + s)
            .collect();
        turn.changed = true;
        ctx.emit(event);
    }

    /// The ball's trajectory changed: it cancels the collisions it planned and tells its sectors
    /// (which relay it to their balls) and the fixed objects within reach.
    fn tell_change(&self, ctx: &mut Ctx<'_, Sectored>, turn: BallTurn<'_>) {
        let (me, info) = (turn.me, &*turn.info);
        for p in turn.planned.drain(..) {
            p.cancel(ctx);
        }
        for &s in turn.sectors.iter() {
            let info = info.clone();
            ctx.send_now(s, SecMsg::VelocityChange { ball: me, info });
        }
        self.tell_fixed(ctx, me, info, turn.sectors);
        if info.pocket.is_some() {
            turn.sectors.clear();
        }
    }

    fn fixed_batch(
        &self,
        ctx: &mut Ctx<'_, Sectored>,
        me: u32,
        planned: &mut Plans,
        batch: &[Envelope<SecMsg>],
    ) {
        for env in batch {
            match &env.msg {
                SecMsg::Collision { partner, .. } => planned.forget(*partner),
                SecMsg::NewVelocity { ball, info: x } => {
                    planned.cancel_with(ctx, *ball);
                    if x.pocket.is_some() {
                        continue;
                    }
                    let contact = self.table.contact(me, &x.traj, x.radius);
                    if let Some(key) = Self::key_of(contact, &x.fixed, pair(*ball, me)) {
                        // a fixed object's own message carries no version: it never changes
                        let p = Self::schedule(ctx, me, *ball, key, None, 0, None, x.version);
                        planned.add(p);
                    }
                }
                _ => unreachable!("fixed objects hear only of trajectories and collisions"),
            }
        }
    }

    /// Schedules ball `ball`'s entry into sector `me` (with the trajectory it was predicted from)
    /// or its departure (`None`) at `time`.
    fn passage(
        ctx: &mut Ctx<'_, Sectored>,
        me: u32,
        ball: u32,
        entry: Option<Arc<BallInfo>>,
        time: VTime<Key>,
    ) -> Passage {
        debug_assert_eq!(me, ctx.me(), "a sector schedules its own passages");
        let version = entry.as_ref().map_or(DEPARTS, |e| e.version);
        let sent = match entry {
            Some(info) => {
                let entering = |info| SecMsg::SectorEntry {
                    ball,
                    sector: me,
                    info,
                };
                ctx.send_two(ball, time, entering(Some(info)), entering(None))
            }
            None => {
                let msg = SecMsg::SectorDeparture { ball, sector: me };
                ctx.send_two(ball, time, msg.clone(), msg)
            }
        };
        Passage {
            ball,
            entry: version,
            sent,
        }
    }

    /// Cancels the entry or departure of `ball` the sector planned, if any.
    fn cancel_passage(ctx: &mut Ctx<'_, Sectored>, planned: &mut Vec<Passage>, ball: u32) {
        if let Some(k) = planned.iter().position(|p| p.ball == ball) {
            let p = planned.swap_remove(k);
            ctx.cancel_two(p.sent, p.ball);
        }
    }

    /// A member's new trajectory: plan its departure and tell the balls here (those after
    /// `after` only, at initialization) and the adjacent sectors.
    #[allow(clippy::too_many_arguments)]
    fn relay(
        &self,
        ctx: &mut Ctx<'_, Sectored>,
        me: u32,
        members: &[(u32, u64)],
        planned: &mut Vec<Passage>,
        ball: u32,
        info: &Arc<BallInfo>,
        after: Option<u32>,
    ) {
        Self::cancel_passage(ctx, planned, ball);
        let poly = &self.layout.polys[(me - self.first_sector()) as usize];
        if info.pocket.is_none() {
            let now = ctx.now().clone();
            if let Some(t) = polygon::departure_time(poly, &info.traj, info.radius, now.t()) {
                let key = Key::at(t.max(now.t()), DEPARTURE);
                let time = if VTime::at(key.clone()) > now {
                    VTime::at(key)
                } else {
                    now.next_gen()
                };
                let p = Self::passage(ctx, me, ball, None, time);
                planned.push(p);
            }
        }
        for &(b, _) in members {
            if b != ball && after.is_none_or(|a| b > a) {
                ctx.send_now(
                    b,
                    SecMsg::NewVelocity {
                        ball,
                        info: info.clone(),
                    },
                );
            }
        }
        for &s in &self.layout.adjacent[(me - self.first_sector()) as usize] {
            ctx.send_now(
                self.first_sector() + s,
                SecMsg::NewVelocity {
                    ball,
                    info: info.clone(),
                },
            );
        }
    }

    fn sector_batch(
        &self,
        ctx: &mut Ctx<'_, Sectored>,
        me: u32,
        members: &mut Vec<(u32, u64)>,
        planned: &mut Vec<Passage>,
        batch: &[Envelope<SecMsg>],
    ) {
        let poly = &self.layout.polys[(me - self.first_sector()) as usize];
        for env in batch {
            match &env.msg {
                SecMsg::SectorEntry { ball, info, .. } => {
                    let Some(k) = planned
                        .iter()
                        .position(|p| p.ball == *ball && p.entry != DEPARTS)
                    else {
                        continue;
                    };
                    let version = planned.swap_remove(k).entry();
                    let info = info
                        .as_ref()
                        .expect("a sector's own entry carries the trajectory");
                    debug_assert_eq!(version, Some(info.version), "the entry planned last");
                    members.push((*ball, info.version));
                    self.relay(ctx, me, members, planned, *ball, info, None);
                }
                SecMsg::SectorDeparture { ball, .. } => {
                    planned.retain(|p| p.ball != *ball);
                    members.retain(|m| m.0 != *ball);
                }
                SecMsg::VelocityChange { ball, info } => {
                    match members.iter().position(|m| m.0 == *ball) {
                        Some(k) => members[k].1 = info.version,
                        None => members.push((*ball, info.version)),
                    }
                    if info.pocket.is_some() {
                        members.retain(|m| m.0 != *ball);
                    }
                    self.relay(ctx, me, members, planned, *ball, info, None);
                }
                SecMsg::VelocityInitialization { ball, info } => {
                    self.relay(ctx, me, members, planned, *ball, info, Some(*ball));
                }
                SecMsg::NewVelocity { ball, info } => {
                    if let Some(k) = members.iter().position(|m| m.0 == *ball) {
                        // a member: only news (its course changed out of our sight) matters
                        if info.version > members[k].1 {
                            members[k].1 = info.version;
                            if info.pocket.is_some() {
                                members.retain(|m| m.0 != *ball);
                            }
                            self.relay(ctx, me, members, planned, *ball, info, None);
                        }
                        continue;
                    }
                    if planned
                        .iter()
                        .any(|p| p.ball == *ball && p.entry == info.version)
                    {
                        continue; // this entry is planned already
                    }
                    Self::cancel_passage(ctx, planned, *ball);
                    if info.pocket.is_some() {
                        continue;
                    }
                    let now = ctx.now().clone();
                    let at_now = info.traj.at(now.t());
                    let time = if polygon::touches(poly, at_now, info.radius) {
                        Some(now.next_gen())
                    } else {
                        polygon::entry_time(poly, &info.traj, info.radius, now.t()).map(|t| {
                            let key = Key::start(t);
                            if VTime::at(key.clone()) > now {
                                VTime::at(key)
                            } else {
                                now.next_gen()
                            }
                        })
                    };
                    if let Some(time) = time {
                        let p = Self::passage(ctx, me, *ball, Some(info.clone()), time);
                        planned.push(p);
                    }
                }
                SecMsg::Collision { .. }
                | SecMsg::CollisionConfirm { .. }
                | SecMsg::ReverseYourself
                | SecMsg::ReturnToTable => {
                    unreachable!("sectors take part in no collision and never turn around")
                }
            }
        }
    }
}

impl Model for Sectored {
    type Time = Key;
    type Msg = SecMsg;
    type State = SecState;
    type Output = Event;
    type Undo = ();

    fn kind_names(&self) -> &'static [&'static str] {
        &KIND_NAMES
    }

    fn kind(&self, msg: &SecMsg) -> usize {
        match msg {
            SecMsg::NewVelocity { .. } => 0,
            SecMsg::Collision { .. } => 1,
            SecMsg::VelocityChange { .. } => 2,
            SecMsg::SectorEntry { .. } => 3,
            SecMsg::SectorDeparture { .. } => 4,
            SecMsg::VelocityInitialization { .. } => 5,
            SecMsg::CollisionConfirm { .. } => 6,
            SecMsg::ReverseYourself => 7,
            SecMsg::ReturnToTable => 8,
        }
    }

    /// Collisions first (4.3.1), then entries, velocity news, and departures last.
    fn priority(&self, msg: &SecMsg) -> u8 {
        match msg {
            SecMsg::Collision { .. } => 0,
            SecMsg::CollisionConfirm { .. } | SecMsg::ReturnToTable => 1,
            SecMsg::SectorEntry { .. } => 2,
            SecMsg::VelocityChange { .. } | SecMsg::VelocityInitialization { .. } => 3,
            SecMsg::NewVelocity { .. } => 4,
            SecMsg::SectorDeparture { .. } => 5,
            SecMsg::ReverseYourself => 6,
        }
    }

    /// Only the balls: observers read trajectories, never sectors or fixed objects.
    fn observed(&self, obj: u32) -> bool {
        obj < self.table.n_balls
    }

    /// Balls, fixed objects and sectors.
    fn state_class(&self, obj: u32) -> usize {
        let t = &self.table;
        usize::from(obj >= t.n_balls) + usize::from(obj >= t.n_balls + t.n_fixed())
    }

    /// Thesis 5.4: each ball sends VelocityInitialization to its sectors, which tell only the
    /// balls after it; fixed objects hear from every ball directly.
    fn init(&self, ctx: &mut Ctx<'_, Sectored>, me: u32, state: &mut SecState) {
        if let SecState::Ball { info, sectors, .. } = state {
            for &s in sectors.iter() {
                ctx.send_now(
                    s,
                    SecMsg::VelocityInitialization {
                        ball: me,
                        info: info.clone(),
                    },
                );
            }
            self.tell_fixed(ctx, me, info, sectors);
            if let Some(t) = self.span.reverse_at {
                ctx.send_at(me, VTime::at(Key::at(t, REVERSAL)), SecMsg::ReverseYourself);
            }
        }
    }

    fn handle(
        &self,
        ctx: &mut Ctx<'_, Sectored>,
        me: u32,
        state: &mut SecState,
        batch: &[Envelope<SecMsg>],
    ) {
        match state {
            SecState::Ball {
                info,
                planned,
                sectors,
                awaiting,
            } => {
                let turn = BallTurn {
                    me,
                    info,
                    planned,
                    sectors,
                    awaiting,
                    heard: Vec::new(),
                    changed: false,
                };
                self.ball_batch(ctx, turn, batch)
            }
            SecState::Fixed { planned } => self.fixed_batch(ctx, me, planned, batch),
            SecState::Sector { members, planned } => {
                self.sector_batch(ctx, me, members, planned, batch)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec2;
    use crate::scenario::builtin::{build, Params};

    #[test]
    fn a_passage_takes_forty_bytes() {
        // five words: a sector's state, which Time Warp copies, is mostly passages
        assert_eq!(std::mem::size_of::<Passage>(), 40);
    }

    #[test]
    fn a_state_cloned_into_another_equals_its_source() {
        let s = build("gas", &Params::default()).unwrap();
        let table = Table::new(&s);
        let (_, states) = Sectored::new(&s, Layout::grid(&table, 3, 3), Span::default(), 1);
        let json = |st: &SecState| serde_json::to_string(st).unwrap();
        // every pair of kinds: ball into ball, sector into ball, ball into sector, and so on
        for from in &states {
            for into in [
                &states[0],
                &states[states.len() - 1],
                &states[s.balls.len()],
            ] {
                let mut copy = into.clone();
                copy.clone_from(from);
                assert_eq!(json(&copy), json(from));
                assert_eq!(json(&from.clone()), json(from));
            }
        }
    }

    #[test]
    fn a_points_home_is_the_first_sector_that_holds_it() {
        let s = build("gas", &Params::default()).unwrap();
        let table = Table::new(&s);
        let span = table.hi - table.lo;
        for (nx, ny) in [(1, 1), (3, 2), (7, 5), (16, 16)] {
            let layout = Layout::grid(&table, nx, ny);
            // points on a fine lattice, corners and borders between sectors included
            for i in 0..=4 * nx {
                for j in 0..=4 * ny {
                    let p = Vec2::new(
                        table.lo.x + span.x * i as f64 / (4 * nx) as f64,
                        table.lo.y + span.y * j as f64 / (4 * ny) as f64,
                    );
                    assert_eq!(layout.home(p), layout.touching(p, 0.0).first().copied());
                }
            }
        }
    }

    #[test]
    fn fixed_objects_hear_from_the_sectors_within_reach() {
        // a gas on a square table of four cushions, cut into 5 x 5 sectors
        let s = build("gas", &Params::default()).unwrap();
        let table = Table::new(&s);
        let mut layout = Layout::grid(&table, 5, 5);
        let w = (table.hi.x - table.lo.x) / 5.0;
        // balls of radius w / 2 reach a sector's width in from a cushion, and not the middle
        let (near, far) = near_fixed(&table, &layout, 0.5 * w);
        assert!(far.is_empty());
        assert!(near[12].is_empty(), "{:?}", near[12]);
        assert_eq!(near[0].len(), 2);
        assert_eq!(near[6].len(), 2);
        assert_eq!(near[7].len(), 1);
        // smaller balls reach only the sectors along the cushions
        let (near, _) = near_fixed(&table, &layout, 0.45 * w);
        assert!(near[6].is_empty() && near[12].is_empty());
        assert_eq!(near[0].len(), 2);
        assert_eq!(near[1].len(), 1);
        layout.fixed_news = FixedNews::Thesis;
        let (near, far) = near_fixed(&table, &layout, 30.0);
        assert!(near.iter().all(Vec::is_empty));
        assert_eq!(far.len(), table.n_fixed() as usize);
    }
}
