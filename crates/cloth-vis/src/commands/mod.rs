//! The subcommands of `cloth-vis`, one file each with its clap arguments. They are private to
//! the binary: the library (`cloth_vis`) offers scenes, stages and the run; these files turn
//! flags into requests, check them before any work, and print one summary line.

pub mod anim;
pub mod bake;
pub mod btf;
pub mod btf_fins;
mod btf_parts;
pub mod btf_render;
pub mod cpca;
mod cpca_bits;
mod cpca_decompress;
mod cpca_figures;
mod cpca_search;
pub mod env_args;
pub mod hemicube;
pub mod inspect;
pub mod jumpmap;
mod jumpmap_maps;
mod obj_frames;
mod output_size;
pub mod parse;
pub mod render;
pub mod shadows;
pub mod translucency;
pub mod up_axis;
mod vat_out;
#[cfg(feature = "viewer")]
pub mod view;
#[cfg(feature = "viewer")]
mod view_hud;
#[cfg(feature = "viewer")]
mod view_motion;
#[cfg(feature = "viewer")]
mod view_window;
pub mod visibility;

#[cfg(test)]
mod tests;

use std::io::Write as _;

use gpu_context::{GpuContext, GpuOptions};

/// A GPU context when a usable adapter exists, for paths that fall back to the CPU without one.
pub fn optional_gpu() -> Option<GpuContext> {
    GpuContext::new(&GpuOptions::default()).ok()
}

/// A GPU context for the output `path` that `flag` asks for, or the request refused naming the
/// flag, the file and gpu-context's reason (no adapter, or adapters that lack what is needed,
/// with what to install).
pub fn required_gpu(path: &std::path::Path, flag: &str) -> Result<GpuContext, cloth_vis::Error> {
    GpuContext::new(&GpuOptions::default())
        .map_err(|e| invalid(path, format!("{flag} renders on the GPU: {e}")))
}

pub use cloth_vis::folder_output;

/// A request refused before any work: [`cloth_vis::Error::Request`] naming `path`.
pub fn invalid(path: &std::path::Path, message: String) -> cloth_vis::Error {
    cloth_vis::Error::Request {
        path: path.to_owned(),
        message,
    }
}

/// A `stats` command given its two files the wrong way round: the compressed file (`.ext`)
/// where the original goes and something else after it. Refused with the order spelled out
/// and the command that was meant, instead of the reader's complaint about the wrong kind of
/// file.
pub fn refuse_swapped_stats(
    command: &str,
    original: &std::path::Path,
    compressed: &std::path::Path,
    ext: &str,
) -> Result<(), cloth_vis::Error> {
    let is_compressed =
        |p: &std::path::Path| visibility::lower_extension(p).as_deref() == Some(ext) && !p.is_dir();
    if is_compressed(original) && !is_compressed(compressed) {
        return Err(invalid(
            original,
            format!(
                "this .{ext} is given where the original goes; the order is `cloth-vis \
                 {command} ORIGINAL FILE.{ext}`: `cloth-vis {command} {} {}`",
                compressed.display(),
                original.display()
            ),
        ));
    }
    Ok(())
}

/// An `anim-pca` error about the file `path` (its message names the parameter and value).
pub fn anim_error(path: &std::path::Path, e: anim_pca::AnimPcaError) -> cloth_vis::Error {
    invalid(path, e.to_string())
}

/// Refuses an output path that names an input (the same file, however spelled: through
/// `..`, a symlink or a hard link), before any work — `visibility bunny.ply --out bunny.ply`
/// would otherwise overwrite the mesh it reads.
///
/// # Errors
/// [`cloth_vis::Error::Request`] naming the output and the input.
pub fn refuse_overwriting_input(
    output: &std::path::Path,
    inputs: &[&std::path::Path],
) -> Result<(), cloth_vis::Error> {
    let Ok(out) = std::fs::canonicalize(output) else {
        // The output does not exist yet: it cannot be an existing input.
        return Ok(());
    };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == out) {
            return Err(cloth_vis::Error::Request {
                path: output.to_owned(),
                message: format!(
                    "this output is the input {}; write somewhere else",
                    input.display()
                ),
            });
        }
    }
    Ok(())
}

/// [`refuse_overwriting_input`], then whether the file could be written at all
/// ([`atomic_out::check_writable`]): a folder standing at the path, a read-only folder or a
/// file system that takes no new files is refused before the work, not after minutes of it.
/// The check leaves nothing behind.
///
/// # Errors
/// [`cloth_vis::Error::Request`] for an input named as the output; the write's error
/// (naming the output and the step) for a path that could not be written.
pub fn check_output_file(
    output: &std::path::Path,
    inputs: &[&std::path::Path],
) -> Result<(), cloth_vis::Error> {
    refuse_overwriting_input(output, inputs)?;
    atomic_out::check_writable(output)?;
    Ok(())
}

/// Loader options for an animation input: the glTF clip `--clip` names, defaults otherwise.
pub fn animation_options(
    clip: &meshio::ClipSelector,
    topology: Option<&std::path::Path>,
) -> meshio::AnimationOptions {
    meshio::AnimationOptions {
        clip: clip.clone(),
        topology: topology.map(std::path::Path::to_owned),
        ..meshio::AnimationOptions::default()
    }
}

/// Print a command's one summary line on stdout.
pub fn print_line(line: &str) -> anyhow::Result<()> {
    writeln!(std::io::stdout().lock(), "{line}")?;
    Ok(())
}

/// Print a command's summary line, then `wrote A, B` naming every file or folder it wrote
/// (the last line of every command that writes, so that a script or a reader sees where the
/// results went without reading the flags again); the summary alone when it wrote nothing.
pub fn print_summary<'a>(
    line: &str,
    outputs: impl IntoIterator<Item = &'a std::path::Path>,
) -> anyhow::Result<()> {
    print_line(&with_wrote(line.to_owned(), outputs))
}

/// `line`, then (when there are outputs) [`wrote_line`] on a line of its own.
pub fn with_wrote<'a>(
    line: String,
    outputs: impl IntoIterator<Item = &'a std::path::Path>,
) -> String {
    match wrote_line(outputs) {
        Some(wrote) => format!("{line}\n{wrote}"),
        None => line,
    }
}

/// `wrote A, B`: the outputs' paths as given; `None` for no output.
pub fn wrote_line<'a>(outputs: impl IntoIterator<Item = &'a std::path::Path>) -> Option<String> {
    let names: Vec<String> = outputs
        .into_iter()
        .map(|p| p.display().to_string())
        .collect();
    (!names.is_empty()).then(|| format!("wrote {}", names.join(", ")))
}

/// A spinner on stderr for one long step whose length is unknown (a clustered PCA fit, one
/// loading an animation): `message` and the elapsed time, ticking on its own thread.
/// indicatif draws nothing when stderr is not a terminal, so pipelines and tests stay clean;
/// `show = false` (`--quiet`) hides it everywhere.
pub fn spinner(show: bool, message: String) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new_spinner();
    if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
        bar.set_style(style);
    }
    bar.set_message(message);
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
}

/// A bar over the (vertex, direction) cells of each computation `stage` runs next, fed by the
/// engine from inside the call (chunks of rows on the cpu backend, batches of directions as the
/// GPU finishes them); hidden (and the stage left silent) when `show` is false. Finish it with
/// `finish_and_clear` after the call.
pub fn engine_bar(
    show: bool,
    stage: &mut cloth_vis::shadowing::VisibilityStage,
    message: String,
) -> indicatif::ProgressBar {
    if !show {
        stage.set_progress(None);
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(0);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% ({elapsed}, {eta})")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message);
    let feed = bar.clone();
    stage.set_progress(Some(std::sync::Arc::new(move |done, total| {
        feed.set_length(total);
        // Worker threads may report slightly out of order: never step back.
        feed.set_position(done.max(feed.position()));
    })));
    bar
}
