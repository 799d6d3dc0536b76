//! Real-time scheduling for the threads of a test that plays both ends of a real link (the
//! master's loop and the emulated segment): on a loaded machine a SCHED_OTHER thread is held
//! back for milliseconds, which the emulated drives rightly count as lost frames.

/// Runs the calling thread SCHED_FIFO at `priority` (1–99); false where not permitted (not
/// root), and the thread stays as it was.
pub fn fifo(priority: i32) -> bool {
    set(libc::SCHED_FIFO, priority)
}

fn set(policy: libc::c_int, priority: i32) -> bool {
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: sched_setscheduler on the calling thread (pid 0) with a valid parameter.
    unsafe { libc::sched_setscheduler(0, policy, &param) == 0 }
}

/// The calling thread SCHED_FIFO (best effort) until this is dropped, then SCHED_OTHER again.
pub struct Fifo(());

impl Fifo {
    /// Enters SCHED_FIFO at `priority` where permitted.
    pub fn enter(priority: i32) -> Fifo {
        fifo(priority);
        Fifo(())
    }
}

impl Drop for Fifo {
    fn drop(&mut self) {
        set(libc::SCHED_OTHER, 0);
    }
}
