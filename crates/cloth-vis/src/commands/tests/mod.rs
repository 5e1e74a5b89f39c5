//! Tests of the subcommands' requests (their checks before work, their outputs against
//! library and closed-form references) and, through the built binary, of their flags.

mod common;

mod anim_compress;
mod anim_jumpmap;
mod anim_search;
mod bake_cmd;
mod hemicube_cmd;
mod inspect_cmd;
mod output_checks;
mod render_outputs;
mod shadows_cmd;
mod translucency_cmd;
mod visibility_cmd;
mod visibility_outputs;
