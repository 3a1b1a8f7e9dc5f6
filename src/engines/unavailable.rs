//! The structure of an engine this build left out: a type with no values, so
//! the registry keeps the engine's line (and `--engine NAME` its clear error)
//! while no code of the engine is compiled in.

use crate::accel::Accel;
use crate::accel::stats::Counter;
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// No value: an engine built without its cargo feature never makes one.
#[derive(Clone, Copy, Debug)]
pub enum Unavailable {}

impl Accel for Unavailable {
    const COUNTS_WORK: bool = false;

    fn intersect_counted<S: Counter>(&self, _: &Ray, _: &mut S) -> Hit {
        match *self {}
    }

    fn intersect_packet_counted<F: SimdFloat, S: Counter>(
        &self,
        _: &RayPacket<F>,
        _: &mut S,
    ) -> HitPacket<F> {
        match *self {}
    }

    fn occluded_counted<S: Counter>(&self, _: &Ray, _: &mut S) -> bool {
        match *self {}
    }

    fn occluded_packet_counted<F: SimdFloat, S: Counter>(&self, _: &RayPacket<F>, _: &mut S) -> F {
        match *self {}
    }
}

/// The [`EngineModule`](crate::engines::engine_module::EngineModule) of an engine this
/// build left out: its name and capabilities, [`Unavailable`] device and
/// structure, and a device that fails saying how to get the engine: build
/// with `feature = "…"`, or `message = …`.
#[allow(unused_macros)]
macro_rules! not_linked {
    ($engine:ty, $name:literal, $capabilities:expr, feature = $feature:literal) => {
        $crate::engines::unavailable::not_linked!(
            $engine,
            $name,
            $capabilities,
            message = concat!(
                "this raypack was built without the `",
                $feature,
                "` feature: build with `cargo build --release --features ",
                $feature,
                "`"
            )
        );
    };
    ($engine:ty, $name:literal, $capabilities:expr, message = $missing:expr) => {
        impl $crate::engines::engine_module::EngineModule for $engine {
            const NAME: &'static str = $name;
            const CAPABILITIES: $crate::engines::capabilities::Capabilities = $capabilities;
            const LINKED: bool = false;
            type Device = $crate::engines::unavailable::Unavailable;
            type Built<'p> = $crate::engines::unavailable::Unavailable;

            fn device(_: &$crate::engines::engine_module::EngineOptions) -> anyhow::Result<Self::Device> {
                anyhow::bail!($missing)
            }

            fn build<'p>(
                device: &Self::Device,
                _: &'p [$crate::geometry::Primitive],
            ) -> anyhow::Result<Self::Built<'p>> {
                match *device {}
            }

            fn visit<'s, J: $crate::engines::engine_module::WithAccel<'s>>(
                built: &'s Self::Built<'_>,
                _: J,
            ) -> J::Output {
                match *built {}
            }

            fn describe(built: &Self::Built<'_>) -> $crate::engines::engine_module::Description {
                match *built {}
            }
        }
    };
}

// Unused in a build with every engine's feature.
#[allow(unused_imports)]
pub(crate) use not_linked;
