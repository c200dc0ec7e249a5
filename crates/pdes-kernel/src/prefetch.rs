//! A hint to the processor to start loading a record into cache before it is read: an executor
//! knows which object runs next a little before it runs, and with a million objects each of
//! their records is a trip to main memory.

/// Asks the processor to bring the cache line holding `r` closer; does nothing elsewhere.
#[inline(always)]
pub fn prefetch<T>(r: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint: it never faults and changes no memory, and `r` is a
    // valid reference anyway.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(r).cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = r;
}

/// [`prefetch`] for every cache line a record lies on: its first, then each line start within
/// it (a record that does not start on a line's start reaches one line further than its size
/// alone says).
#[inline(always)]
pub fn prefetch_all<T>(r: &T) {
    prefetch(r);
    let base = std::ptr::from_ref(r).cast::<u8>();
    let mut offset = 64 - base as usize % 64;
    while offset < std::mem::size_of::<T>() {
        // SAFETY: `offset` is within the record, so the pointer stays inside one allocation.
        prefetch(unsafe { &*base.add(offset) });
        offset += 64;
    }
}
