//! The `cloth-vis` command line: one subcommand per file in [`commands`], each with its clap
//! arguments and the work it does through the library (`cloth_vis`) and the domain crates.

use std::path::Path;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod commands;

/// Real-time cloth appearance: self-shadowing under HDR light, BTFs, shadows, animation PCA.
#[derive(Parser)]
#[command(name = "cloth-vis", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene file: only the effects it names are built; images and a run report go to DIR.
    Render(commands::render::RenderArgs),
    /// Render the embedded demo scene (synthetic cloth under a procedural sky) into DIR.
    Demo(commands::render::DemoArgs),
    /// Animation from mesh clips by PCA (thesis §3).
    Anim {
        #[command(subcommand)]
        command: commands::anim::AnimCommand,
    },
    /// Measured materials (BTFs, thesis §5.3–5.5): a synthetic woven BTF, per-view PCA
    /// compression, error statistics.
    Btf {
        #[command(subcommand)]
        command: commands::btf::BtfCommand,
    },
    /// Visibility matrix M and ambient term a_i of a mesh or an animation (paper 000).
    Visibility(commands::visibility::VisibilityArgs),
    /// Bake ambient occlusion (and radiance, bent normals) into your own .glb/.gltf/.obj/.ply:
    /// the asset with everything it had, plus linear vertex colour.
    Bake(commands::bake::BakeArgs),
    /// Static self-shadowing from per-vertex visibility maps: hemicube, single plane or
    /// hemisphere, under an environment and point lights (thesis §4.3).
    Hemicube(commands::hemicube::HemicubeArgs),
    /// The shadow a mesh casts on a ground plane as an [N, N] mask: z-fail shadow volumes
    /// (or exact rays), optional LOD casters (thesis §2.4.1, §4.2, §5.5.1).
    Shadows(commands::shadows::ShadowsArgs),
    /// The SH9 irradiance of an environment map (R&H's matrix, eq. 10 of seed 004) as f32
    /// [9, 3], with the irradiance along the six axes.
    Sh(commands::translucency::ShArgs),
    /// A mesh with real-time subsurface scattering by spherical harmonics (seed 004): per
    /// frame cube map, SH projection, light distance map with a peeled layer, eq. 12.
    Translucency(commands::translucency::TranslucencyArgs),
    /// Load a mesh or an animation and print what the loader found (counts, quirks, time).
    Inspect(commands::inspect::InspectArgs),
    /// Open a scene, a mesh, an animation or `demo` in a window: orbit, effect toggles, level,
    /// environment turn, exposure, animation with per-frame self-shadowing; `--frames N
    /// --screenshot FILE [--events FILE]` for scripts.
    #[cfg(feature = "viewer")]
    View(commands::view::ViewArgs),
}

fn main() -> ExitCode {
    quiet_headless_device_select();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    // Ctrl-C or SIGTERM mid-write removes the temporary files: no partial output survives.
    if let Err(e) = atomic_out::remove_temporaries_on_signal() {
        log::warn!("{e}; an interrupted run may leave .tmp files beside its outputs");
    }
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => args.run(),
        Command::Demo(args) => args.run(),
        Command::Anim { command } => command.run(),
        Command::Btf { command } => command.run(),
        Command::Visibility(args) => args.run(),
        Command::Bake(args) => args.run(),
        Command::Hemicube(args) => args.run(),
        Command::Shadows(args) => args.run(),
        Command::Sh(args) => args.run(),
        Command::Translucency(args) => args.run(),
        Command::Inspect(args) => args.run(),
        #[cfg(feature = "viewer")]
        Command::View(args) => args.run(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A closed pipe (`cloth-vis inspect … | head`) is not an error of ours.
        Err(e)
            if e.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe) =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {}", message(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes joined by ": ", leaving out a cause whose text the message
/// already holds (many errors of the workspace quote their source in their own message).
fn message(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text.push_str(": ");
            text.push_str(&cause);
        }
    }
    text
}

/// Mesa's device-select Vulkan layer (installed with `mesa-vulkan-drivers`, lavapipe's
/// package) connects to Wayland while it lists the devices, and where there is no session
/// (CI, render nodes, ssh, containers) libwayland prints "error: XDG_RUNTIME_DIR is invalid or
/// not set in the environment." to stderr, twice per GPU command, worded like one of our own
/// errors. The layer only reorders the devices, and `gpu_context` picks its adapter itself, so
/// where that connection cannot succeed the layer is switched off (`NODEVICE_SELECT=1`),
/// unless the user steers it (`MESA_VK_DEVICE_SELECT`, `DRI_PRIME`, or `NODEVICE_SELECT`
/// itself).
fn quiet_headless_device_select() {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_dir());
    if runtime_dir
        || ["NODEVICE_SELECT", "MESA_VK_DEVICE_SELECT", "DRI_PRIME"]
            .into_iter()
            .any(set)
    {
        return;
    }
    // SAFETY: the first statement of `main`, before any thread exists (the signal handler
    // and rayon's pool start after it), so nothing reads the environment concurrently.
    #[allow(unsafe_code)]
    unsafe {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
}

#[cfg(test)]
mod cli_tests {
    use clap::CommandFactory;

    use super::Cli;

    /// Every subcommand, depth first, with its path of names.
    fn walk(command: &clap::Command, path: String, out: &mut Vec<(String, clap::Command)>) {
        for sub in command.get_subcommands() {
            let name = format!("{path} {}", sub.get_name());
            out.push((name.clone(), sub.clone()));
            walk(sub, name, out);
        }
    }

    /// clap's own consistency checks (no two arguments share a flag or a short), and `-o`
    /// for `--out` wherever a command writes to `--out`: the habit of every compiler and
    /// converter a user comes from.
    #[test]
    fn every_out_flag_has_the_short_o() {
        Cli::command().debug_assert();
        let mut all = Vec::new();
        walk(&Cli::command(), "cloth-vis".to_owned(), &mut all);
        let mut outs = 0;
        for (name, command) in &all {
            for arg in command.get_arguments() {
                if arg.get_long() == Some("out") {
                    outs += 1;
                    assert_eq!(arg.get_short(), Some('o'), "{name} --out");
                } else {
                    assert_ne!(arg.get_short(), Some('o'), "{name}: -o is not --out");
                }
            }
        }
        assert!(outs >= 16, "{outs} --out flags");
    }

    /// `-o FILE` parses as `--out FILE`, in a command and in a nested one.
    #[test]
    fn dash_o_is_out() {
        for args in [
            &["visibility", "bunny.ply", "-o", "ao.npy"][..],
            &["anim", "decompress", "clip.cpca", "-o", "ao.npy"],
        ] {
            let matches = Cli::command()
                .try_get_matches_from(std::iter::once("cloth-vis").chain(args.iter().copied()))
                .unwrap_or_else(|e| panic!("{args:?}: {e}"));
            let mut sub = matches.subcommand().unwrap().1;
            while let Some((_, deeper)) = sub.subcommand() {
                sub = deeper;
            }
            let out = sub.get_one::<std::path::PathBuf>("out");
            assert_eq!(out, Some(&std::path::PathBuf::from("ao.npy")), "{args:?}");
        }
    }
}
