//! The pictures of `cloth-vis anim stats`: the decoded clip coloured by cluster (thesis
//! Figs. 3.12/3.13) and d_f per frame (Fig. 3.15).

use std::path::Path;

use anim_pca::compress::{Compressed, Decoder, Distortion};
use cloth_vis::Error;

/// The decoded clip of `data` as a strip of frames, each vertex coloured by its cluster
/// (thesis Figs. 3.12/3.13), named `what` in errors.
///
/// # Errors
/// [`Error::Request`] when the file has no triangles; rendering errors.
pub fn cluster_strip(
    gpu: &gpu_context::GpuContext,
    data: &Compressed,
    what: &Path,
) -> Result<image::RgbaImage, Error> {
    let frames = Decoder::new(data).decode_all();
    Ok(figures::strip::render_label_strip(
        &gpu.device,
        &gpu.queue,
        &frames,
        data.triangles(),
        data.labels(),
        data.clusters(),
        what,
    )?)
}

/// d_f per frame (thesis Fig. 3.15) as an SVG chart titled after `cpca`.
pub fn error_chart(distortion: &Distortion, cpca: &Path) -> String {
    use figures::chart::{Axis, Series, chart_svg};
    let name = cpca
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    chart_svg(
        &format!("d_f per frame, {name} (d_a = {:.4})", distortion.da),
        ["frame", "d_f (position units)"],
        [Axis::Linear, Axis::Linear],
        &[Series {
            label: "d_f".to_owned(),
            points: distortion
                .df
                .iter()
                .enumerate()
                .map(|(f, &d)| (f as f64, d))
                .collect(),
        }],
    )
}
