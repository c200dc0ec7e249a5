//! The pool objects of the thesis as models of the [`pdes_kernel`] crate: balls, cushions,
//! pockets and corners exchanging messages on a plain table (thesis fig. 3), and the same with
//! sectors relaying news (fig. 14).

pub mod layout;
pub mod pool;
pub mod regions;
pub mod sectored;

/// The message types of the thesis (and of its sectored objects), in the order the summary
/// lists them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MessageKind {
    /// A ball's new trajectory, to the objects that must know it (thesis 4.3).
    NewVelocity,
    /// A predicted collision, to both parties.
    Collision,
    /// A retracted message (thesis Cancel).
    Cancel,
    /// A ball's new trajectory relayed by a sector (thesis 5.4).
    VelocityChange,
    /// A ball enters a sector (thesis 5.1).
    SectorEntry,
    /// A ball leaves a sector (thesis 5.1).
    SectorDeparture,
    /// A ball's first trajectory, at the start.
    VelocityInitialization,
    /// A frame request to a ball (thesis 4.2).
    DisplayYourself,
    /// A reversal of every ball (thesis 4.6).
    ReverseYourself,
    /// A pocketed ball put back (reversal through a pocket).
    ReturnToTable,
    /// The sectored engines' zero-delay check that both balls are still on the trajectories a
    /// collision was predicted for.
    CollisionConfirm,
}

impl MessageKind {
    /// Every kind, in the summary's order.
    pub const ALL: [MessageKind; 11] = [
        MessageKind::NewVelocity,
        MessageKind::Collision,
        MessageKind::Cancel,
        MessageKind::VelocityChange,
        MessageKind::SectorEntry,
        MessageKind::SectorDeparture,
        MessageKind::VelocityInitialization,
        MessageKind::DisplayYourself,
        MessageKind::ReverseYourself,
        MessageKind::ReturnToTable,
        MessageKind::CollisionConfirm,
    ];

    /// The kinds the thesis counts in its message totals (table 5): the simulation logic,
    /// neither set-up, display, reversal nor the sectored engines' own confirmation.
    pub const THESIS_TOTAL: [MessageKind; 6] = [
        MessageKind::VelocityChange,
        MessageKind::NewVelocity,
        MessageKind::SectorDeparture,
        MessageKind::SectorEntry,
        MessageKind::Cancel,
        MessageKind::Collision,
    ];

    /// The thesis' name of the type.
    pub const fn name(self) -> &'static str {
        match self {
            MessageKind::NewVelocity => "NewVelocity",
            MessageKind::Collision => "Collision",
            MessageKind::Cancel => "Cancel",
            MessageKind::VelocityChange => "VelocityChange",
            MessageKind::SectorEntry => "SectorEntry",
            MessageKind::SectorDeparture => "SectorDeparture",
            MessageKind::VelocityInitialization => "VelocityInitialization",
            MessageKind::DisplayYourself => "DisplayYourself",
            MessageKind::ReverseYourself => "ReverseYourself",
            MessageKind::ReturnToTable => "ReturnToTable",
            MessageKind::CollisionConfirm => "CollisionConfirm",
        }
    }

    /// The kind named `name`, if any.
    pub fn from_name(name: &str) -> Option<MessageKind> {
        MessageKind::ALL.into_iter().find(|k| k.name() == name)
    }
}
