//! # cloth-vis
//!
//! The facade of the cloth-vis workspace: scene files, the effect graph that builds only the
//! stages a scene asks for, the stages themselves (geometry, environment, light directions,
//! visibility, lighting, render, BTF), file input through `meshio`, and the demo. The
//! `cloth-vis` binary (`cloth-vis render SCENE.toml --out DIR [--frames A..B]`,
//! `cloth-vis demo --out DIR`, `cloth-vis visibility`, `cloth-vis inspect`, …) is a thin
//! layer over this library: its subcommands live in the binary's `commands/` folder and are
//! not library API; `cloth-vis visibility` runs a one-object scene through the same stages.
//! It draws through the shared frame of crate `render`
//! (one renderer per run, reused for every frame of a sequence) and holds no renderer itself.
//!
//! It implements the lighting side of paper 000 (thesis §4.4): per-vertex colours
//! c_i = ρ/π Σ_j M_ij I_j ω_j from a lightsphere of directions l_j with environment radiance
//! I_j (§3.3, §3.4, §5), with M from occlusion-gpu for `self-shadowing` and
//! M_ij = max(0, n_i·l_j) for plain `lighting` (see [`lighting`] and [`shadowing`]).
//!
//! Domain crates never depend on this one; it only ties them together.
//!
//! # Examples
//!
//! Plan a scene without running it — a scene that does not ask for `lighting` never builds the
//! light-direction or lighting stages:
//!
//! ```
//! use cloth_vis::{Plan, Scene, Stage};
//! let scene = Scene::from_toml(
//!     r#"
//!     [[object]]
//!     name = "cloth"
//!     source = "synth:cloth"
//!     "#,
//!     std::path::Path::new("."),
//!     "example",
//! )?;
//! let plan = Plan::for_scene(&scene)?;
//! assert_eq!(plan.stages(), &[Stage::Geometry, Stage::Render]);
//! # Ok::<(), cloth_vis::Error>(())
//! ```

pub mod btf_env;
mod btf_scene;
pub mod btf_stage;
pub mod camera;
pub mod deform;
pub mod demo;
pub mod effects;
mod error;
pub mod fins_stage;
mod frame_effects;
mod image_checks;
pub mod inputs;
pub mod lighting;
pub mod live;
pub mod object;
pub mod plan;
pub mod report;
pub mod run;
mod run_sequence;
pub mod scene;
pub mod shadow_volumes;
pub mod shadowing;
pub mod static_shadowing;
pub mod translucency_stage;

pub use demo::{DEMO_SCENE, demo_scene, run_demo};
pub use effects::Effect;
pub use error::Error;
pub use plan::{Plan, Stage};
pub use report::RunReport;
pub use run::{RunOptions, RunOutput, folder_output, run_scene};
pub use scene::Scene;
