//! `cloth-vis anim`: animation from mesh clips by PCA (thesis §3) — jump maps
//! ([`super::jumpmap`]) and clustered-PCA compression ([`super::cpca`]).

use clap::Subcommand;

use super::cpca::{CompressArgs, DecompressArgs, StatsArgs};
use super::jumpmap::JumpmapArgs;

/// The `anim` subcommands.
#[derive(Subcommand)]
pub enum AnimCommand {
    /// Endless new animation from a short clip by jump maps (thesis §3.2): writes N frames as
    /// .npy [N, V, 3], a .glb morph-target animation, or a folder of OBJ frames.
    Jumpmap(JumpmapArgs),
    /// Compress a clip by clustered PCA (thesis §3.3.2) into a .cpca file; prints V, F, k, c,
    /// c*, bits, file size, bpvf, d_a, the worst d_f and the encode time.
    Compress(CompressArgs),
    /// Decode every frame of a .cpca file into .npy [F, V, 3], a .glb morph-target animation
    /// or a folder of OBJ frames (with the triangles stored in the file).
    Decompress(DecompressArgs),
    /// Compare a .cpca file with its original clip: bpvf (eqs. 3.16–3.18 and file size), d_a
    /// and the worst d_f.
    Stats(StatsArgs),
}

impl AnimCommand {
    /// Run the subcommand.
    pub fn run(self) -> anyhow::Result<()> {
        match self {
            Self::Jumpmap(args) => args.run(),
            Self::Compress(args) => args.run(),
            Self::Decompress(args) => args.run(),
            Self::Stats(args) => args.run(),
        }
    }
}
