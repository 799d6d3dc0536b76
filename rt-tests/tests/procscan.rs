//! The /proc scanner on the current process: our own threads are found with the right policy,
//! and a SCHED_FIFO thread pinned to a CPU contaminates that CPU unless excluded.

use std::path::Path;
use std::sync::mpsc;

use cellrt_rt_tests::procscan::{all_rt_tasks, gettid, online_cpus, read_task, scan};

#[test]
fn reads_the_current_thread() {
    let pid = std::process::id() as i32;
    let tid = gettid();
    let t = read_task(Path::new(&format!("/proc/{pid}/task/{tid}")), pid, tid).expect("task");
    assert_eq!((t.pid, t.tid), (pid, tid));
    assert!(!t.kernel);
    assert!(!t.cpus_allowed.is_empty());
    // The test harness' threads run SCHED_OTHER.
    assert_eq!(t.policy, "SCHED_OTHER");
    assert!(!all_rt_tasks(Path::new("/proc"))
        .iter()
        .any(|t| t.tid == tid));
}

#[test]
fn a_fifo_thread_on_the_cpu_contaminates_it_unless_excluded() {
    let cpu = *online_cpus().last().expect("a CPU");
    let (tid_tx, tid_rx) = mpsc::channel();
    let (done_tx, done_rx) = mpsc::channel::<()>();
    let h = std::thread::spawn(move || {
        let mut set = unsafe { std::mem::zeroed::<libc::cpu_set_t>() };
        unsafe { libc::CPU_SET(cpu, &mut set) };
        let pinned = unsafe { libc::sched_setaffinity(0, std::mem::size_of_val(&set), &set) } == 0;
        let param = libc::sched_param { sched_priority: 5 };
        let fifo =
            unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) }
                == 0;
        tid_tx.send((gettid(), pinned && fifo)).unwrap();
        let _ = done_rx.recv();
    });
    let (tid, privileged) = tid_rx.recv().unwrap();
    if privileged {
        let s = scan(cpu, 80, &[], &[]);
        let me = s.contaminating.iter().find(|t| t.tid == tid);
        let me = me.expect("our SCHED_FIFO thread is found");
        assert_eq!(me.policy, "SCHED_FIFO");
        assert_eq!(me.priority, 5);
        assert!(s.contaminated());
        let s = scan(cpu, 80, &[], &[tid]);
        assert!(!s.contaminating.iter().any(|t| t.tid == tid));
        let s = scan(cpu, 80, &[std::process::id() as i32], &[]);
        assert!(!s.contaminating.iter().any(|t| t.tid == tid));
    } else {
        eprintln!("SCHED_FIFO refused (not root): only the exclusion path is checked");
        assert!(!scan(cpu, 80, &[], &[])
            .contaminating
            .iter()
            .any(|t| t.tid == tid));
    }
    done_tx.send(()).unwrap();
    h.join().unwrap();
}
