//! SIGINT and SIGTERM as a clean stop: the first one asks the run to end at its next event
//! (the trace, the final state and the summary are then written as of that event, and the
//! process exits with 128 + the signal); a second one ends the process at once, as the
//! default action would.

use crate::common::{internal, Failure};
use pdes_kernel::Interrupt;
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::flag;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Raises `interrupt` (with the signal's number) on the first SIGINT or SIGTERM, for the rest
/// of the process; the second one exits at once with status 128 + its number.
pub fn stop_on_signals(interrupt: &Interrupt) -> Result<(), Failure> {
    let armed = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        // in this order: the exit looks at the flag before the first signal sets it
        flag::register_conditional_shutdown(sig, 128 + sig, armed.clone())
            .and_then(|_| flag::register(sig, armed.clone()))
            .and_then(|_| flag::register_usize(sig, interrupt.cell(), sig as usize))
            .map_err(|e| internal(format!("cannot handle signal {sig}: {e}")))?;
    }
    Ok(())
}

/// The failure an interrupted run ends with, once everything is written: exit status 128 +
/// the signal's number, and a line that says where the run stopped.
pub fn interrupted(interrupt: &Interrupt, at: f64) -> Result<(), Failure> {
    match interrupt.cause() {
        None => Ok(()),
        Some(sig) => Err(Failure {
            code: u8::try_from(128 + sig).unwrap_or(u8::MAX),
            message: format!(
                "interrupted by {} at t = {at:?}: the trace, final state and summary are \
                 complete up to that time",
                poolsim::summary::Interruption::new(at, sig).signal
            ),
        }),
    }
}
