//! `cloth-vis anim decompress`: a `.cpca` (thesis §3.3) decoded frame by frame, streamed into
//! `.npy`, a morph-target `.glb`, a vertex-animation texture or a folder of OBJ frames.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anim_pca::compress::Decoder;
use cloth_vis::Error;
use glam::Vec3;

use super::cpca::read_cpca;
use super::{anim_error, invalid};

/// What `cloth-vis anim decompress` was asked to do.
#[derive(Clone, Debug)]
pub struct DecompressRequest {
    /// The `.cpca` file.
    pub input: PathBuf,
    /// `.npy` ([F, V, 3] f32), `.glb` (morph-target animation) or a folder (no extension) of
    /// `frame_00000.obj` …
    pub out: PathBuf,
    /// Replace an output folder that holds files (else refused before any work).
    pub force: bool,
    /// Show the bar over decoded frames (stderr, terminals only).
    pub progress: bool,
}

/// What `decompress` wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecompressSummary {
    /// Vertices V.
    pub vertices: usize,
    /// Frames F.
    pub frames: usize,
    /// Triangles written.
    pub triangles: usize,
    /// Wall-clock seconds of decoding all frames (not reading or writing).
    pub decode_seconds: f64,
}

impl DecompressSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        format!(
            "decompress: {} frames x {} vertices, {} triangles, decoded in {:.3} s ({:.0} frames/s)",
            self.frames,
            self.vertices,
            self.triangles,
            self.decode_seconds,
            self.frames as f64 / self.decode_seconds.max(f64::MIN_POSITIVE)
        )
    }
}

/// The kind of output a decompressed animation goes to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OutKind {
    Npy,
    Glb,
    /// A vertex-animation texture (`.exr`, `.png`).
    Vat,
    /// With what to do about an existing folder.
    ObjFolder(atomic_out::ExistingFolder),
}

/// The output kind `out` names, or an error naming it and the supported kinds; an OBJ folder
/// that holds files is refused unless `force`.
fn out_kind(out: &Path, force: bool) -> Result<OutKind, Error> {
    match out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("npy") => Ok(OutKind::Npy),
        Some("glb") => Ok(OutKind::Glb),
        Some("exr" | "png") => Ok(OutKind::Vat),
        None => Ok(OutKind::ObjFolder(super::folder_output(out, force)?)),
        Some(other) => Err(invalid(
            out,
            format!(
                "output extension .{other} is not supported: use .npy ([F, V, 3]), .glb \
                 (morph-target animation), .exr/.png (vertex-animation texture) or a folder \
                 name without extension (OBJ frames)"
            ),
        )),
    }
}

/// Runs `decompress`: read and validate the `.cpca`, decode every frame, write them.
///
/// # Errors
/// An unsupported output extension, refused before reading; a corrupt file (the decoder's
/// message prefixed with its path); a `.glb` output of a file without triangles; write errors
/// naming the output. Nothing is written on error.
pub fn run_decompress(request: &DecompressRequest) -> Result<DecompressSummary, Error> {
    let kind = out_kind(&request.out, request.force)?;
    if matches!(kind, OutKind::ObjFolder(_)) {
        super::refuse_overwriting_input(&request.out, &[&request.input])?;
    } else {
        super::check_output_file(&request.out, &[&request.input])?;
    }
    let (data, _) = read_cpca(&request.input)?;
    let size = (data.frames(), data.vertices(), data.triangles().len());
    let levers = "write .npy instead of OBJ frames, or decode on the GPU where it is used";
    let obj = matches!(kind, OutKind::ObjFolder(_));
    super::output_size::check_frames(&request.out, obj, size, levers, request.force)?;
    if kind == OutKind::Glb && data.frames() > meshio::MAX_GLB_ANIMATION_FRAMES {
        return Err(invalid(
            &request.out,
            format!(
                "{} has {} frames; a .glb morph-target animation holds at most {} \
                 (meshio::MAX_GLB_ANIMATION_FRAMES: its weights grow as F²): write .npy or an \
                 OBJ folder instead",
                request.input.display(),
                data.frames(),
                meshio::MAX_GLB_ANIMATION_FRAMES
            ),
        ));
    }
    if kind == OutKind::Vat {
        let size = (data.frames(), data.vertices());
        super::vat_out::check(&request.input, &request.out, data.triangles(), size)?;
    }
    if kind == OutKind::Glb && data.triangles().is_empty() {
        return Err(invalid(
            &request.input,
            "the file stores no triangles (it was compressed from an .npy clip): write .npy \
             or an OBJ folder instead of .glb"
                .to_owned(),
        ));
    }
    // Streamed into every kind of output: one frame decoded, written, dropped (peak memory
    // O(V), not 2·F·V). A .glb asks for each frame twice (its JSON, written first, holds the
    // morph targets' bounds).
    let decoder = Decoder::new(&data);
    let mut scratch = decoder.scratch();
    let mut decoding = std::time::Duration::ZERO;
    // A .glb asks for every frame but the first twice (bounds, then bytes).
    let calls = if kind == OutKind::Glb {
        2 * data.frames() - 1
    } else {
        data.frames()
    };
    let bar = cloth_vis::run::progress_bar(request.progress, calls as u64, "decoding frames");
    let mut decode = |f: usize, out: &mut [Vec3]| -> Result<(), Error> {
        let t = Instant::now();
        let result = decoder.frame_into(f, out, &mut scratch);
        decoding += t.elapsed();
        bar.inc(1);
        result.map_err(|e| anim_error(&request.input, e))
    };
    let (frames, vertices) = (decoder.frames(), decoder.vertices());
    match kind {
        OutKind::Npy => {
            let mut failure = None;
            let stream = (0..frames).map(|f| {
                let mut out = vec![Vec3::ZERO; vertices];
                if let Err(e) = decode(f, &mut out) {
                    failure.get_or_insert(e);
                }
                out
            });
            meshio::write_npy_frames(&request.out, frames, vertices, stream)?;
            if let Some(e) = failure {
                let _ = std::fs::remove_file(&request.out);
                return Err(e);
            }
        }
        OutKind::Glb => {
            let clip = meshio::GlbClip {
                triangles: data.triangles(),
                uvs: None,
                frame_rate: glb_frame_rate(data.frame_rate()),
                frames,
                vertices,
            };
            meshio::write_glb_animation_with(&request.out, &clip, &mut decode)?;
        }
        OutKind::Vat => {
            let line = super::vat_out::write(
                &request.out,
                data.triangles(),
                glb_frame_rate(data.frame_rate()),
                (frames, vertices),
                |f, p, _| decode(f, p),
            )?;
            eprintln!("{line}");
        }
        OutKind::ObjFolder(existing) => super::obj_frames::write_obj_frames(
            &request.out,
            existing,
            (0..frames).map(|f| {
                let mut out = vec![Vec3::ZERO; vertices];
                decode(f, &mut out).map(|()| out)
            }),
            data.triangles(),
            "cloth-vis anim decompress",
        )?,
    }
    bar.finish_and_clear();
    let decode_seconds = decoding.as_secs_f64();
    Ok(DecompressSummary {
        vertices: data.vertices(),
        frames: data.frames(),
        triangles: data.triangles().len(),
        decode_seconds,
    })
}

/// Frame rate written to a `.glb` when the file's is not a positive number (the loaders'
/// default, 30 fps).
const FALLBACK_FRAME_RATE: f32 = 30.0;

fn glb_frame_rate(rate: f32) -> f32 {
    if rate.is_finite() && rate > 0.0 {
        rate
    } else {
        FALLBACK_FRAME_RATE
    }
}

/// `cloth-vis anim decompress`: the flags of a [`DecompressRequest`].
#[derive(clap::Args)]
pub struct DecompressArgs {
    /// The .cpca file.
    input: PathBuf,
    /// Output: FILE.npy, FILE.glb, FILE.exr/FILE.png (a vertex-animation texture) or a folder
    /// name (OBJ frames).
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Replace an existing output folder that holds files, once the new frames are complete;
    /// write an output estimated above 8 GiB.
    #[arg(long)]
    force: bool,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

impl DecompressArgs {
    /// Decode and write; print the summary line.
    pub fn run(self) -> anyhow::Result<()> {
        let request = DecompressRequest {
            input: self.input,
            out: self.out,
            force: self.force,
            progress: !self.quiet,
        };
        let line = run_decompress(&request)?.line();
        super::print_summary(&line, [request.out.as_path()])
    }
}
