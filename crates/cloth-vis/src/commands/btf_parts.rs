//! `cloth-vis btf render --part NAME=FILE.btfpca`: garment parts (thesis §5.6) — the faces of
//! each named material (OBJ `usemtl`, glTF material) wear their own BTF, every other face
//! `--btf`, all in one GPU frame with one depth buffer.

use std::time::Instant;

use btf::BtfPca;

use super::btf_render::{RenderRequest, RenderSummary, one_light};
use super::invalid as request;
use cloth_vis::Error;

/// `btf render --part NAME=FILE ...`: each face material its own BTF, one frame.
pub(super) fn run_parts(
    request_: &RenderRequest,
    gpu: Option<&gpu_context::GpuContext>,
    pca: &BtfPca,
    object: &cloth_vis::object::WorldObject,
    camera: &render::Camera,
    params: &btf::render::RenderParams,
) -> Result<RenderSummary, Error> {
    let start = Instant::now();
    let gpu = gpu.ok_or_else(|| {
        request(
            &request_.out,
            "--part draws every part in one GPU frame; drop --cpu".to_owned(),
        )
    })?;
    let materials = meshio::load_face_materials(&request_.mesh)?.ok_or_else(|| {
        request(
            &request_.mesh,
            "has no face materials (--part needs an OBJ with usemtl or a glTF with materials)"
                .to_owned(),
        )
    })?;
    if materials.per_triangle.len() != object.triangles.len() {
        return Err(request(
            &request_.mesh,
            format!(
                "{} face materials for {} triangles",
                materials.per_triangle.len(),
                object.triangles.len()
            ),
        ));
    }
    let mut pcas = Vec::with_capacity(request_.parts.len());
    let mut ids = Vec::with_capacity(request_.parts.len());
    for (name, file) in &request_.parts {
        let id = materials.index_of(name).ok_or_else(|| {
            request(
                &request_.mesh,
                format!(
                    "--part {name}=…: the mesh has no material {name:?} (it has {})",
                    if materials.names.is_empty() {
                        "none".to_owned()
                    } else {
                        materials
                            .names
                            .iter()
                            .map(|n| format!("{n:?}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ),
            )
        })?;
        if ids.contains(&Some(id)) {
            return Err(request(
                &request_.out,
                format!("--part {name} is given twice"),
            ));
        }
        ids.push(Some(id));
        pcas.push(BtfPca::read(file)?);
    }
    let mut parts: Vec<(&BtfPca, cloth_vis::object::WorldObject)> = Vec::new();
    for (pca_part, id) in pcas.iter().zip(&ids) {
        let name = materials.names[id.unwrap_or(0) as usize].clone();
        if let Some(o) =
            cloth_vis::btf_stage::material_part(object, &materials.per_triangle, *id, &name)
        {
            parts.push((pca_part, o));
        }
    }
    // Every other face (other materials, or none) wears --btf.
    let mut others: Vec<Option<u32>> = materials
        .per_triangle
        .iter()
        .copied()
        .filter(|m| !ids.contains(m))
        .collect();
    others.sort_unstable();
    others.dedup();
    for id in others {
        if let Some(o) =
            cloth_vis::btf_stage::material_part(object, &materials.per_triangle, id, "rest")
        {
            parts.push((pca, o));
        }
    }
    let (lit, env) = match (
        request_.light.env_lighting(),
        one_light(&request_.light, request_.radiance),
    ) {
        (Some(lighting), _) => {
            let mut ws = Vec::with_capacity(parts.len());
            let mut cost = None;
            for (p, _) in &parts {
                let (w, c) = cloth_vis::btf_env::env_weights(p, object, &lighting)?;
                ws.push(w);
                cost.get_or_insert(c);
            }
            (cloth_vis::btf_stage::Lit::Environment(ws), cost)
        }
        (None, Some(light)) => (cloth_vis::btf_stage::Lit::Light(light), None),
        (None, None) => {
            return Err(request(&request_.out, "no light to render with".to_owned()));
        }
    };
    let refs: Vec<(&BtfPca, &cloth_vis::object::WorldObject)> =
        parts.iter().map(|(p, o)| (*p, o)).collect();
    let frame_start = Instant::now();
    let image = cloth_vis::btf_stage::render_parts(gpu, &refs, &lit, camera, params)?;
    let env = env.map(|c| cloth_vis::btf_env::EnvCost {
        render_ms: frame_start.elapsed().as_secs_f64() * 1e3,
        ..c
    });
    let picture = if env.is_some() {
        cloth_vis::btf_stage::single_auto_exposed(&image)
    } else {
        cloth_vis::btf_stage::single(&image)
    };
    let seconds = start.elapsed().as_secs_f64();
    figures::strip::write_png(&request_.out, &picture)?;
    Ok(RenderSummary {
        mesh: (object.positions.len(), object.triangles.len()),
        size: [picture.width(), picture.height()],
        backend: "gpu",
        seconds,
        fins: None,
        env,
    })
}
