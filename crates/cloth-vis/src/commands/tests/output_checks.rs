//! Every command that writes a file refuses one it could not write before its work: a folder
//! standing at the output is named at once, before the (here missing) input is even opened,
//! and nothing is left behind.

use std::path::Path;

use super::common::{cli, text};

#[test]
fn an_unwritable_output_is_refused_before_the_input_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let taken = |name: &str| {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.join("kept")).unwrap();
        path
    };
    let missing = dir.path().join("missing.ply");
    let missing = text(&missing);
    let cases: Vec<(Vec<&str>, std::path::PathBuf)> = vec![
        (vec!["visibility", missing], taken("ao.npy")),
        (vec!["visibility", missing, "--render"], taken("ao.png")),
        (vec!["hemicube", missing], taken("hc.npy")),
        (vec!["bake", missing], taken("baked.ply")),
        (
            vec!["shadows", missing, "--ground", "0", "--light-pos", "0,1,0"],
            taken("mask.npy"),
        ),
        (vec!["sh", "missing.hdr"], taken("sh.npy")),
        (
            vec!["translucency", missing, "--light-pos", "0,1,0"],
            taken("t.npy"),
        ),
        (vec!["anim", "compress", "missing"], taken("clip.cpca")),
        (
            vec!["anim", "decompress", "missing.cpca"],
            taken("frames.npy"),
        ),
        (vec!["anim", "jumpmap", "missing"], taken("run.glb")),
        (vec!["btf", "compress", "missing"], taken("w.btfpca")),
        (
            vec!["btf", "fins", "compress", "missing"],
            taken("f.finpca"),
        ),
        (
            vec![
                "btf",
                "render",
                missing,
                "--btf",
                "w.btfpca",
                "--light-dir",
                "0,1,0",
            ],
            taken("w.png"),
        ),
    ];
    for (args, out) in &cases {
        let mut args = args.clone();
        // `--render` takes the image; the others write `-o`.
        if args.last() != Some(&"--render") {
            args.push("-o");
        }
        args.push(text(out));
        let run = cli(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} was accepted");
        assert!(
            stderr.contains(&format!(
                "{}: cannot replace it: it is a folder",
                out.display()
            )),
            "{args:?}: {stderr}"
        );
        assert!(
            !stderr.contains("missing"),
            "{args:?} read its input first: {stderr}"
        );
        assert_eq!(std::fs::read_dir(out).unwrap().count(), 1, "{args:?}");
    }
    // Nothing else appeared: no temporary file, no output.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), cases.len());
}

/// A place where no file can be created is refused before the work too, with the write's own
/// error. (A read-only folder is the everyday case, but root, which CI runs as, may write
/// there anyway: /proc, which takes no new folders from anyone, stands in.)
#[test]
fn an_output_in_a_folder_that_takes_no_files_is_refused_first() {
    let run = cli(&["visibility", "missing.ply", "-o", "/proc/cloth-vis/ao.npy"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("/proc/cloth-vis/ao.npy: cannot create the folders of it"),
        "{stderr}"
    );
    assert!(!stderr.contains("missing.ply"), "{stderr}");
}

/// Every command that writes ends with `wrote A, B`: each output it wrote, as given, in the
/// order of its flags (the main output first), and each of them there.
#[test]
fn a_command_that_writes_names_its_outputs_last() {
    let dir = tempfile::tempdir().unwrap();
    let at = |name: &str| dir.path().join(name);
    // A square over a larger one: something to occlude and to shadow, in under a second.
    let input = at("squares.obj");
    std::fs::write(
        &input,
        "v -0.25 1 -0.5\nv 0.75 1 -0.5\nv 0.75 1 0.5\nv -0.25 1 0.5\n\
         v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n\
         f 1 2 3\nf 1 3 4\nf 5 7 6\nf 5 8 7\n",
    )
    .unwrap();
    let input = text(&input);
    let (ao, hc, mask, baked) = (at("ao.npy"), at("hc.npy"), at("mask.npy"), at("baked.obj"));
    let (fins, finpca) = (at("fins"), at("fins.finpca"));
    let cases: Vec<(Vec<&str>, Vec<&Path>)> = vec![
        (
            vec!["visibility", input, "--backend", "cpu", "-o", text(&ao)],
            vec![&ao],
        ),
        (
            vec![
                "hemicube",
                input,
                "--builder",
                "cpu",
                "--res",
                "8",
                "-o",
                text(&hc),
            ],
            vec![&hc],
        ),
        (
            vec![
                "shadows",
                input,
                "--ground",
                "0",
                "--light-pos",
                "0,3,0",
                "--cpu",
                "--grid",
                "16",
                "-o",
                text(&mask),
            ],
            vec![&mask],
        ),
        (vec!["bake", input, "-o", text(&baked)], vec![&baked]),
        (
            vec![
                "btf",
                "fins",
                "synth",
                "--size",
                "8x8",
                "--quiet",
                "-o",
                text(&fins),
            ],
            vec![&fins],
        ),
        (
            vec!["btf", "fins", "compress", text(&fins), "-o", text(&finpca)],
            vec![&finpca],
        ),
    ];
    for (args, outputs) in &cases {
        let run = cli(args);
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(
            run.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let names: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(
            stdout.lines().last(),
            Some(format!("wrote {}", names.join(", ")).as_str()),
            "{args:?}: {stdout}"
        );
        assert!(outputs.iter().all(|p| p.exists()), "{args:?}");
    }
}
