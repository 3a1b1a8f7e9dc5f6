//! Flush-to-zero and denormals-are-zero (FTZ/DAZ) for the calling thread.
//!
//! Embree expects both MXCSR flags set: its kernels are tuned for them, and a
//! verbose device warns when they are not. The mode is per thread (new threads
//! inherit their creator's), so every thread that traces through Embree sets
//! it; it stays set afterwards. For a fair comparison
//! the benchmarks set it for raypack's threads as well.

/// MXCSR bit 15 (flush results to zero) and bit 6 (treat denormal inputs as zero).
const FTZ_DAZ: u32 = (1 << 15) | (1 << 6);

/// The calling thread's MXCSR register.
#[inline]
fn read_mxcsr() -> u32 {
    let mut csr = 0u32;
    // SAFETY: stmxcsr stores 4 bytes into a valid, writable u32.
    unsafe {
        std::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack, preserves_flags));
    }
    csr
}

/// Set FTZ and DAZ on the calling thread (a no-op when they are already set).
#[inline]
pub fn flush_denormals() {
    let csr = read_mxcsr();
    if csr & FTZ_DAZ != FTZ_DAZ {
        let new = csr | FTZ_DAZ;
        // SAFETY: ldmxcsr loads 4 valid bytes; setting FTZ/DAZ only changes how
        // denormals round, and leaves exception masks and rounding mode as they were.
        unsafe {
            std::arch::asm!("ldmxcsr [{}]", in(reg) &new, options(nostack, readonly, preserves_flags));
        }
    }
}

/// Whether FTZ and DAZ are both set on the calling thread.
pub fn denormals_flushed() -> bool {
    read_mxcsr() & FTZ_DAZ == FTZ_DAZ
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flushing_makes_denormal_products_zero_on_this_thread_only() {
        std::thread::spawn(|| {
            let tiny = std::hint::black_box(1e-30f32);
            assert!(!denormals_flushed());
            assert!(tiny * 1e-10 > 0.0, "1e-40 is a denormal before");
            flush_denormals();
            assert!(denormals_flushed());
            assert_eq!(std::hint::black_box(tiny * 1e-10), 0.0, "1e-40 flushed to zero");
            // A denormal input reads as zero.
            let denormal = std::hint::black_box(f32::from_bits(1));
            assert_eq!(denormal * 1e30, 0.0);
        })
        .join()
        .unwrap();
        // A fresh thread starts with the default mode again.
        std::thread::spawn(|| assert!(!denormals_flushed()))
            .join()
            .unwrap();
    }
}
