//! The instruction set the hot paths run on, chosen at run time.
//!
//! One binary carries the traversal and kernels compiled for each level, in
//! the spirit of Embree's per-ISA kernels: work written once, generic over a
//! [`Level`]'s lane types, is a [`LevelTask`], and [`Isa::run`] runs it inside
//! the level's entry point (`#[target_feature]`), the one place raypack
//! enters an instruction set's code. Which level runs is an [`Isa`]: the best the CPU has ([`Isa::best`]), unless a
//! command forces one (`--isa`) for a comparison. A level is only ever run
//! where [`Isa::is_available`] says the CPU has it.
//!
//! Fuzz builds (`--cfg fuzzing`, which cargo-fuzz sets) and the library's own
//! unit tests (`cfg(test)`) have the portable level only. The fuzzers look for
//! inputs that panic or misuse memory, and the unit tests for wrong results;
//! the x86 levels run the same generic code in safe Rust, checked bit for bit
//! against the portable level by `tests/bvh/isa.rs` in the ordinary library
//! build. Compiling them too would put two more copies of every traversal
//! into builds that never run them on another level (the unit tests' build was
//! about half of the test suite's, `docs/measurements.md`).

use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicU8, Ordering};

use crate::simd::{Simd8, SimdFloat};

/// An instruction-set level for the SIMD hot paths.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Isa {
    /// The `wide` crate's types, compiled for whatever the build targets
    /// (SSE2 on a baseline x86-64 build, NEON on aarch64): x86 CPUs without
    /// AVX2 run it (see `docs/measurements.md`, "Instruction sets at run time",
    /// for why SSE4.2 has no level of its own).
    Portable,
    /// AVX2 (with FMA, as Embree's level of the name): 8-lane registers.
    Avx2,
    /// AVX-512 (F, VL, BW, DQ, CD): 16-lane registers for 16-wide packets,
    /// 8-lane ones compared into mask registers for the rest (no 512-bit
    /// instruction where 8 lanes are wanted).
    Avx512,
}

impl Isa {
    /// Every level, lowest first.
    pub const ALL: [Isa; 3] = [Isa::Portable, Isa::Avx2, Isa::Avx512];

    /// The name `--isa` takes and results print.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// Whether this CPU can run the level.
    pub fn is_available(self) -> bool {
        match self {
            Isa::Portable => true,
            #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
            Isa::Avx2 => {
                is_x86_feature_detected!("sse4.2")
                    && is_x86_feature_detected!("popcnt")
                    && is_x86_feature_detected!("avx2")
                    && is_x86_feature_detected!("fma")
                    && is_x86_feature_detected!("bmi1")
                    && is_x86_feature_detected!("bmi2")
                    && is_x86_feature_detected!("lzcnt")
            }
            #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
            Isa::Avx512 => {
                Isa::Avx2.is_available()
                    && is_x86_feature_detected!("avx512f")
                    && is_x86_feature_detected!("avx512vl")
                    && is_x86_feature_detected!("avx512bw")
                    && is_x86_feature_detected!("avx512dq")
                    && is_x86_feature_detected!("avx512cd")
            }
            #[cfg(any(not(target_arch = "x86_64"), fuzzing, test))]
            _ => false,
        }
    }

    /// The levels this CPU can run, lowest first.
    pub fn available() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|isa| isa.is_available()).collect()
    }

    /// The highest level this CPU can run.
    pub fn best() -> Isa {
        Isa::ALL
            .into_iter()
            .rev()
            .find(|isa| isa.is_available())
            .unwrap_or(Isa::Portable)
    }

    /// The level new acceleration structures run on: [`Isa::best`] unless
    /// [`Isa::set_default`] chose another.
    pub fn default_level() -> Isa {
        match DEFAULT.load(Ordering::Relaxed) {
            UNSET => Isa::best(),
            i => Isa::ALL[usize::from(i)],
        }
    }

    /// Make `isa` the level of every acceleration structure built from now
    /// on (the `--isa` option); an error if this CPU cannot run it.
    pub fn set_default(isa: Isa) -> Result<(), IsaError> {
        if !isa.is_available() {
            return Err(IsaError::Unavailable(isa));
        }
        let index = Isa::ALL
            .iter()
            .position(|&i| i == isa)
            .expect("every level is in ALL");
        DEFAULT.store(index as u8, Ordering::Relaxed);
        Ok(())
    }
}

/// [`Isa::default_level`]'s choice: an index into [`Isa::ALL`], or [`UNSET`].
static DEFAULT: AtomicU8 = AtomicU8::new(UNSET);

/// No level chosen: the best the CPU has.
const UNSET: u8 = u8::MAX;

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A level that cannot be named or run.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum IsaError {
    /// Not a level's name.
    #[error("unknown instruction set `{0}` (expected auto, portable, avx2 or avx512)")]
    Unknown(String),
    /// The CPU lacks it.
    #[error("this CPU cannot run {0} (it has: {list})", list = Isa::available().iter().map(|i| i.name()).collect::<Vec<_>>().join(", "))]
    Unavailable(Isa),
}

impl FromStr for Isa {
    type Err = IsaError;

    /// A level by name; `auto` is [`Isa::best`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "auto" {
            return Ok(Isa::best());
        }
        Isa::ALL
            .into_iter()
            .find(|isa| isa.name() == s)
            .ok_or_else(|| IsaError::Unknown(s.to_string()))
    }
}

/// The lane types of one instruction-set level, of each width packets come in.
pub trait Level {
    /// The level.
    const ISA: Isa;
    /// 4 lanes.
    type F4: SimdFloat<Array = [f32; 4]>;
    /// 8 lanes: packets, and the wide-node and leaf-block tests of single rays.
    type F8: Simd8;
    /// 16 lanes.
    type F16: SimdFloat<Array = [f32; 16]>;
}

/// [`Isa::Portable`]'s lane types: `wide`'s.
pub struct PortableLanes;

impl Level for PortableLanes {
    const ISA: Isa = Isa::Portable;
    type F4 = wide::f32x4;
    type F8 = wide::f32x8;
    type F16 = wide::f32x16;
}

/// Work compiled for every level: [`Isa::run`] calls `run` with the chosen
/// level's lane types, inside a function compiled for that level. What `run`
/// calls must be `#[inline(always)]` (and free of closures over SIMD values)
/// to be compiled with the level's instructions; `tests/cli/inlining.rs`
/// checks the binary for intrinsics left out of line.
pub trait LevelTask {
    /// What the work returns.
    type Output;
    /// Do the work with the lane types of `L`.
    fn run<L: Level>(self) -> Self::Output;
}

impl Isa {
    /// Run `task` compiled for this level: the one place raypack enters an
    /// instruction set's code.
    ///
    /// # Safety
    /// The CPU must have the level ([`Isa::is_available`]); the levels that
    /// [`Isa::default_level`] returns and `Bvh::set_isa` accepts are checked.
    #[inline(always)]
    pub unsafe fn run<T: LevelTask>(self, task: T) -> T::Output {
        match self {
            // SAFETY: the caller guarantees the CPU has the level.
            #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
            Isa::Avx2 => unsafe { task.avx2() },
            // SAFETY: as above.
            #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
            Isa::Avx512 => unsafe { task.avx512() },
            _ => task.portable(),
        }
    }
}

/// A task's entry point at each level: the functions [`Isa::run`] calls,
/// each compiled whole (everything a task's `run` calls is inlined into it)
/// and never inlined into its callers, so that a task's code is compiled once
/// per level, not once per call site (test crates built at opt-level 1 reuse
/// the library's copy, see `docs/measurements.md`, "Build time of the test
/// suite"). This includes the portable level, for one call per query where it
/// runs (off x86, and on x86 CPUs without SSE4.2), and a two-level query's
/// mesh walks, which call another task of the same level.
///
/// Methods of the task's own type (a blanket impl), not free generic
/// functions: the compiler places a method's copies in the codegen unit of its
/// type's module, so each task's entry points are compiled in a unit of their
/// own. A free function's copies, all the tasks' at a level, share the one
/// unit of this module, which LLVM then works through on one core while the
/// others idle (the fuzz build's library: one unit of 16 held 45% of the
/// code).
pub trait EntryPoint: LevelTask + Sized {
    /// The task with [`Isa::Portable`]'s lane types.
    fn portable(self) -> Self::Output;
    /// The task compiled for [`Isa::Avx2`].
    ///
    /// # Safety
    /// The CPU must have the level.
    #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
    unsafe fn avx2(self) -> Self::Output;
    /// The task compiled for [`Isa::Avx512`].
    ///
    /// # Safety
    /// The CPU must have the level.
    #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
    unsafe fn avx512(self) -> Self::Output;
}

impl<T: LevelTask> EntryPoint for T {
    #[inline(never)]
    fn portable(self) -> T::Output {
        self.run::<PortableLanes>()
    }

    #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
    #[inline(never)]
    #[target_feature(enable = "sse4.1,sse4.2,popcnt,avx,avx2,fma,bmi1,bmi2,lzcnt")]
    unsafe fn avx2(self) -> T::Output {
        self.run::<x86::Avx2Lanes>()
    }

    #[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
    #[inline(never)]
    #[target_feature(
        enable = "sse4.1,sse4.2,popcnt,avx,avx2,fma,bmi1,bmi2,lzcnt,avx512f,avx512vl,avx512bw,avx512dq,avx512cd"
    )]
    unsafe fn avx512(self) -> T::Output {
        self.run::<x86::Avx512Lanes>()
    }
}

/// Declares a [`LevelTask`]: `level_task!(TYPE<'a, G: Bound, …>(field: Type, …) -> Output { body })`
/// makes the struct `TYPE`, holding the fields, built by `TYPE::new(fields…)`,
/// whose `run` evaluates `body` with the fields bound by name and the level's
/// lane types as `L`. Each task goes in a module of its own, the codegen
/// unit of its entry points (see [`EntryPoint`]).
macro_rules! level_task {
    (
        $(#[$doc:meta])*
        $task:ident<$lt:lifetime $(, $g:ident: $bound:path)*>($($field:ident: $ty:ty),* $(,)?) -> $output:ty
        $body:block
    ) => {
        $(#[$doc])*
        pub(crate) struct $task<$lt $(, $g: $bound)*>(
            $($ty,)*
            std::marker::PhantomData<&$lt ($($g,)*)>,
        );

        impl<$lt $(, $g: $bound)*> $task<$lt $(, $g)*> {
            /// The task of these arguments.
            #[inline(always)]
            pub(crate) fn new($($field: $ty),*) -> Self {
                Self($($field,)* std::marker::PhantomData)
            }
        }

        impl<$lt $(, $g: $bound)*> $crate::simd::isa::LevelTask for $task<$lt $(, $g)*> {
            type Output = $output;
            #[inline(always)]
            fn run<L: $crate::simd::isa::Level>(self) -> $output {
                let Self($($field,)* _) = self;
                $body
            }
        }
    };
}
pub(crate) use level_task;

/// The lane types of each x86 level.
#[cfg(all(target_arch = "x86_64", not(any(fuzzing, test))))]
mod x86 {
    use super::Level;
    use crate::simd::Isa;
    use crate::simd::x86::{Avx8, Avx8Vl, Avx8x2, Avx16, Sse4};

    /// Declares a level's lane types.
    macro_rules! x86_level {
        ($lanes:ident, $isa:ident, $f4:ty, $f8:ty, $f16:ty) => {
            #[doc = concat!("[`Isa::", stringify!($isa), "`]'s lane types.")]
            pub struct $lanes;

            impl Level for $lanes {
                const ISA: Isa = Isa::$isa;
                type F4 = $f4;
                type F8 = $f8;
                type F16 = $f16;
            }
        };
    }

    x86_level!(Avx2Lanes, Avx2, Sse4, Avx8, Avx8x2);
    x86_level!(Avx512Lanes, Avx512, Sse4, Avx8Vl, Avx16);
}
