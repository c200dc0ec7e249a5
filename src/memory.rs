//! The process's use of transparent huge pages (Linux), the one memory setting that depends on
//! the engine. With 2 MiB pages the event list touches fewer page-table entries per event (its
//! loop at 10^6 balls: 1,317-1,324 ns per event with them, 1,410-1,428 without), but every page
//! a run touches for the first time costs the kernel 2 MiB to zero, and the objects engines
//! touch fresh memory all run long, their messages most of all (at 10^5 balls to t = 0.5, 2
//! Time Warp workers take 2.65-3.58 s wall with them, 0.97-2.56 s of it in the kernel, against
//! 2.25-2.75 s without; the sequential objects engine 2.3-2.9 s with 0.7-1.2 s in the kernel,
//! against about 1.7 s without).

/// Lets the kernel back this process's later memory with transparent huge pages, or not
/// (`prctl(PR_SET_THP_DISABLE)`: process-wide, for pages faulted in from now on). Does nothing
/// where the system has no such switch.
pub fn transparent_huge_pages(on: bool) {
    #[cfg(target_os = "linux")]
    // SAFETY: PR_SET_THP_DISABLE takes one integer flag and changes nothing but how the kernel
    // backs this process's memory; it cannot fail in a way that matters (a kernel without it
    // returns an error, which leaves things as they were).
    unsafe {
        libc::prctl(libc::PR_SET_THP_DISABLE, libc::c_ulong::from(!on), 0, 0, 0);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = on;
}
