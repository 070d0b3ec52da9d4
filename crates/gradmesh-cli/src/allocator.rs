//! The C allocator's settings for a short-lived process.
//!
//! glibc gives each thread that allocates its own arena, and grows an arena's heap by exactly
//! what the allocation needs: without a pad, a render on two threads grows its arenas about
//! 1,400 times, mostly a page at a time, each an `mprotect` system call. With a top pad of
//! 64 MiB an arena commits that much address space at once (pages are still only used when
//! touched: the peak resident memory hardly changes). See docs/performance.md, *A whole
//! process*.

/// Sets the allocator's top pad (see the module's notes). Only for glibc; a no-op elsewhere.
#[allow(unsafe_code)]
pub fn tune() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        const TOP_PAD: libc::c_int = 64 << 20;
        // SAFETY: `mallopt` only sets a parameter of the allocator; it is called before any
        // other thread exists.
        unsafe {
            libc::mallopt(libc::M_TOP_PAD, TOP_PAD);
        }
    }
}
