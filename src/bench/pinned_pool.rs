//! Rayon pools whose workers each keep to one CPU, for the benches' timed
//! traces: a pool that sleeps between short traces (another variant's turn)
//! wakes its workers where the scheduler likes, and two of them often shared
//! one CPU for much of a 5–30 ms trace. `bench scene gen:teapot --engine
//! raypack --threads 1,2 --runs 20`, Intel Xeon with 2 vCPUs: the 2-thread
//! runs of primary single rays spread over 16.2–30.7 Mrays/s unpinned (the
//! 1-thread speed to twice it) and 27.8–30.6 pinned.

/// A pool of `threads` workers, worker `i` on the `i`-th CPU this process may
/// run on (round and round). Where the CPUs cannot be read or set (not
/// Linux, or the call fails) the workers go unpinned: pinning is a hint.
pub fn pinned_pool(threads: usize) -> Result<rayon::ThreadPool, rayon::ThreadPoolBuildError> {
    let cpus = allowed_cpus();
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(move |i| {
            if !cpus.is_empty() {
                pin_to(cpus[i % cpus.len()]);
            }
        })
        .build()
}

/// The CPUs this process may run on, in order; empty where unknown.
fn allowed_cpus() -> Vec<usize> {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: a zeroed cpu_set_t is a valid empty set, which the call fills.
        unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            if libc::sched_getaffinity(0, size_of::<libc::cpu_set_t>(), &mut set) != 0 {
                return Vec::new();
            }
            (0..libc::CPU_SETSIZE as usize)
                .filter(|&cpu| libc::CPU_ISSET(cpu, &set))
                .collect()
        }
    }
    #[cfg(not(target_os = "linux"))]
    Vec::new()
}

/// Keep the calling thread on `cpu` (one the process may run on).
fn pin_to(cpu: usize) {
    #[cfg(target_os = "linux")]
    // SAFETY: a zeroed cpu_set_t is a valid empty set; `cpu` is below
    // CPU_SETSIZE (it came from `allowed_cpus`). A failure leaves the thread
    // where it was, which only costs speed.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, size_of::<libc::cpu_set_t>(), &set);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = cpu;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every worker runs the pool's jobs on a CPU the process may use, and
    /// the pool has the threads asked for.
    #[test]
    fn a_pinned_pool_runs_on_allowed_cpus() {
        let allowed = allowed_cpus();
        let pool = pinned_pool(3).expect("a pool of 3");
        assert_eq!(pool.current_num_threads(), 3);
        let on: Vec<i32> = pool.broadcast(|_| {
            #[cfg(target_os = "linux")]
            // SAFETY: sched_getcpu takes no arguments.
            return unsafe { libc::sched_getcpu() };
            #[cfg(not(target_os = "linux"))]
            return 0;
        });
        if cfg!(target_os = "linux") {
            assert!(!allowed.is_empty());
            for cpu in on {
                assert!(
                    allowed.contains(&(cpu as usize)),
                    "worker on CPU {cpu}, allowed {allowed:?}"
                );
            }
        }
    }
}
