//! The macro that turns the registry's list of engines into the types the
//! commands use: the [`Engine`](super::Engine) choice, the
//! [`EngineDevice`](super::EngineDevice) and [`Built`](super::Built) values
//! holding any engine's device or structure, and the `match`es between them.
//! Written once here so that an engine is one line of the list.

/// `registry! { /// doc  Variant => module::Type, … }`: one line per engine,
/// `Type` its [`EngineModule`](super::EngineModule).
macro_rules! registry {
    ($( $(#[doc = $doc:literal])* $variant:ident => $module:ident :: $ty:ident ),+ $(,)?) => {
        /// Which engine traces the rays: one per line of the registry.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize)]
        #[serde(rename_all = "lowercase")]
        pub enum Engine {
            $( $(#[doc = $doc])* $variant, )+
        }

        impl Engine {
            /// Every engine, in the registry's order.
            pub const ALL: &'static [Engine] = &[$(Engine::$variant),+];

            /// The name on the command line and in results.
            pub fn name(self) -> &'static str {
                match self {
                    $(Engine::$variant => <$module::$ty as EngineModule>::NAME,)+
                }
            }

            /// What the engine can trace.
            pub fn capabilities(self) -> Capabilities {
                match self {
                    $(Engine::$variant => <$module::$ty as EngineModule>::CAPABILITIES,)+
                }
            }

            /// Whether this build has the engine.
            pub fn linked(self) -> bool {
                match self {
                    $(Engine::$variant => <$module::$ty as EngineModule>::LINKED,)+
                }
            }

            /// Make the engine's device with `options`.
            pub fn device(self, options: &EngineOptions) -> anyhow::Result<EngineDevice> {
                Ok(match self {
                    $(Engine::$variant => EngineDevice::$variant(<$module::$ty as EngineModule>::device(options)?),)+
                })
            }

            /// Set up the calling thread to trace through this engine.
            pub fn thread_start(self) {
                match self {
                    $(Engine::$variant => <$module::$ty as EngineModule>::thread_start(),)+
                }
            }
        }

        impl std::fmt::Display for Engine {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        /// An engine's device ([`Engine::device`]), which builds its structures.
        pub enum EngineDevice {
            $( $(#[doc = $doc])* $variant(<$module::$ty as EngineModule>::Device), )+
        }

        impl EngineDevice {
            /// The engine whose device this is.
            pub fn engine(&self) -> Engine {
                match self {
                    $(EngineDevice::$variant(_) => Engine::$variant,)+
                }
            }

            /// Build the engine's structure over `prims` (a hit's primitive
            /// index is the position in `prims`); a [`NotApplicable`] error
            /// where the engine does not take their kinds.
            pub fn build<'p>(&self, prims: &'p [Primitive]) -> anyhow::Result<Built<'p>> {
                self.engine().takes(prims)?;
                Ok(match self {
                    $(EngineDevice::$variant(d) => Built::$variant(<$module::$ty as EngineModule>::build(d, prims)?),)+
                })
            }

            /// Build the engine's structure over `scene`, its instances
            /// included (hit ids as [`Scene::locate`](crate::scene::Scene::locate)
            /// reads them); a [`NotApplicable`] error where the engine does
            /// not take the primitives' kinds.
            pub fn build_scene<'p>(&self, scene: &'p crate::scene::Scene) -> anyhow::Result<Built<'p>> {
                self.engine().takes_scene(scene)?;
                Ok(match self {
                    $(EngineDevice::$variant(d) => Built::$variant(<$module::$ty as EngineModule>::build_scene(d, scene)?),)+
                })
            }
        }

        /// An engine's structure over a scene ([`EngineDevice::build`]).
        pub enum Built<'p> {
            $( $(#[doc = $doc])* $variant(<$module::$ty as EngineModule>::Built<'p>), )+
        }

        impl Built<'_> {
            /// The engine that built this.
            pub fn engine(&self) -> Engine {
                match self {
                    $(Built::$variant(_) => Engine::$variant,)+
                }
            }

            /// Run `job` with the structure, compiled for its type.
            pub fn visit<'s, J: WithAccel<'s>>(&'s self, job: J) -> J::Output {
                match self {
                    $(Built::$variant(b) => <$module::$ty as EngineModule>::visit(b, job),)+
                }
            }

            /// The tree's SAH cost, where the engine shows its tree.
            pub fn sah_cost(&self) -> Option<f64> {
                match self {
                    $(Built::$variant(b) => <$module::$ty as EngineModule>::sah_cost(b),)+
                }
            }

            /// What the structure says about itself.
            pub fn describe(&self) -> Description {
                match self {
                    $(Built::$variant(b) => <$module::$ty as EngineModule>::describe(b),)+
                }
            }
        }
    };
}

pub(super) use registry;
