//! How to render: shading mode, kernel, pixel block, tile size, depth limit, sampling.

/// What a pixel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Ray casting: the nearest object's colour under a headlight.
    Cast,
    /// The shading normal as a colour.
    Normals,
    /// Distance of the primary hit as grey levels.
    Depth,
    /// A colour per primitive.
    Id,
    /// Recursive ray tracing: shadows, reflection, refraction.
    Whitted,
}

impl Mode {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Cast => "cast",
            Mode::Normals => "normals",
            Mode::Depth => "depth",
            Mode::Id => "id",
            Mode::Whitted => "whitted",
        }
    }
}

/// Which kernels trace the rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum KernelKind {
    /// One ray at a time.
    Scalar,
    /// 8-wide SIMD packets: a batch's 4×4 (8×2) block as two 4×2 (8×1) packets.
    Packet8,
    /// 16-wide SIMD packets: a batch's whole block in one packet (one register
    /// per vector with AVX-512, two elsewhere).
    Packet16,
}

impl KernelKind {
    /// Rays traced together: 1 for single rays, else the packet width.
    pub fn lanes(self) -> usize {
        match self {
            KernelKind::Scalar => 1,
            KernelKind::Packet8 => 8,
            KernelKind::Packet16 => 16,
        }
    }

    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            KernelKind::Scalar => "scalar",
            KernelKind::Packet8 => "packet8",
            KernelKind::Packet16 => "packet16",
        }
    }
}

/// The pixel block traced as one batch of 16 rays: one 16-wide packet, or
/// two 8-wide ones of its upper and lower halves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum Block {
    /// 4 pixels wide, 4 high (8-wide packets of 4×2).
    #[value(name = "4x4")]
    #[serde(rename = "4x4")]
    B4x4,
    /// 8 pixels wide, 2 high (8-wide packets of 8×1).
    #[value(name = "8x2")]
    #[serde(rename = "8x2")]
    B8x2,
}

impl Block {
    /// `(width, height)` in pixels.
    pub fn dims(self) -> (u32, u32) {
        match self {
            Block::B4x4 => (4, 4),
            Block::B8x2 => (8, 2),
        }
    }

    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Block::B4x4 => "4x4",
            Block::B8x2 => "8x2",
        }
    }
}

/// Where the primary rays go through the image plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    /// Pixel centres: `width × height` rays (images).
    PixelCentres,
    /// Pixel corners: `(width + 1) × (height + 1)` rays (the SPD's statistics).
    PixelCorners,
}

/// How to render. 12 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// What a pixel shows.
    pub mode: Mode,
    /// Scalar or packet kernels.
    pub kernel: KernelKind,
    /// Pixel block per batch.
    pub block: Block,
    /// Tile edge in pixels.
    pub tile_size: u32,
    /// Maximum ray tree depth in `whitted` mode (eye ray = 1).
    pub max_depth: u32,
    /// Pixel centres or corners.
    pub sampling: Sampling,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            mode: Mode::Whitted,
            kernel: KernelKind::Packet8,
            block: Block::B4x4,
            tile_size: 16,
            max_depth: 5,
            sampling: Sampling::PixelCentres,
        }
    }
}
