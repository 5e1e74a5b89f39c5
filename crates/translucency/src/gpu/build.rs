//! Building the pass: pipelines, textures and the bind groups that read them, once.

use gpu_context::layout::{bind_group, bind_group_layout, binding};
use gpu_context::{RenderPipelineDesc, pipeline};
use render::PassContext;
use wgpu::util::DeviceExt;

use super::{
    BLUR_SHADER, BlurUniform, COMMON_SHADER, EVAL_SHADER, PIPELINE_SHADER, ParamsUniform,
    PipelineParams, REDUCE_GROUPS, REDUCE_SHADER, Targets, TranslucencyPass, Vertex,
};
use crate::cube;
use crate::error::{TranslucencyError, bad_parameter};

/// Stacked face textures: six faces of `size`² one above the other.
fn stacked(
    device: &wgpu::Device,
    label: &str,
    size: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size,
            height: 6 * size,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

pub(super) fn view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor::default())
}

const RENDER: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);
const STORAGE: wgpu::TextureUsages = wgpu::TextureUsages::STORAGE_BINDING
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

impl TranslucencyPass {
    /// Build every pipeline and texture for the frame `ctx` and the sizes in `params`.
    ///
    /// # Errors
    /// Sizes beyond the device's limits, a bad window, or a device that cannot blend the
    /// frame's `Rgba32Float` colour (L^e is added).
    pub fn new(
        device: &wgpu::Device,
        ctx: &PassContext<'_>,
        params: PipelineParams,
    ) -> Result<Self, TranslucencyError> {
        params.validate(device)?;
        if !device
            .features()
            .contains(wgpu::Features::FLOAT32_BLENDABLE)
        {
            return Err(bad_parameter(
                "adapter",
                "no FLOAT32_BLENDABLE",
                "L^e is blended into the Rgba32Float frame",
            ));
        }
        let vis = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let unfilterable = binding::texture(
            wgpu::TextureSampleType::Float { filterable: false },
            wgpu::TextureViewDimension::D2,
        );
        let params_layout =
            bind_group_layout(device, "translucency params", vis, &[binding::uniform()]);
        let peel_layout = bind_group_layout(device, "translucency peel", vis, &[unfilterable]);
        let sh_layout = bind_group_layout(
            device,
            "translucency sh",
            wgpu::ShaderStages::COMPUTE,
            &[unfilterable, binding::storage_read(), binding::storage_rw()],
        );
        let sh_final_layout = bind_group_layout(
            device,
            "translucency sh final",
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::storage_rw()],
        );
        let storage_r32 = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::R32Float,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let blur_layout = bind_group_layout(
            device,
            "translucency blur",
            wgpu::ShaderStages::COMPUTE,
            &[unfilterable, storage_r32, binding::uniform()],
        );
        let eval_layout = bind_group_layout(
            device,
            "translucency eval",
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[
                binding::uniform(),
                binding::storage_read(),
                unfilterable,
                unfilterable,
            ],
        );

        let module = pipeline::shader_module(
            device,
            "translucency.wgsl",
            &format!("{COMMON_SHADER}\n{PIPELINE_SHADER}"),
        );
        let vertex_layout = [wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x3],
        }];
        let only_params = pipeline::pipeline_layout(device, "translucency", &[&params_layout]);
        let with_peel =
            pipeline::pipeline_layout(device, "translucency peel", &[&params_layout, &peel_layout]);
        let offscreen = |label, layout, vertex, fragment, format, compare| {
            RenderPipelineDesc {
                label,
                layout,
                module: &module,
                vertex,
                fragment: Some(fragment),
                buffers: &vertex_layout,
                color: Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                }),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(compare),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                samples: 1,
                cull_mode: None,
            }
            .build(device)
        };
        let cube_pipeline = offscreen(
            "translucency cube map",
            &only_params,
            "vs_cube",
            "fs_cube",
            wgpu::TextureFormat::Rgba32Float,
            wgpu::CompareFunction::Greater,
        );
        let distance_pipeline = offscreen(
            "translucency light distance",
            &only_params,
            "vs_light",
            "fs_distance",
            wgpu::TextureFormat::R32Float,
            wgpu::CompareFunction::Less,
        );
        let peel_pipeline = offscreen(
            "translucency peel",
            &with_peel,
            "vs_light",
            "fs_peel",
            wgpu::TextureFormat::R32Float,
            wgpu::CompareFunction::Less,
        );

        let reduce = pipeline::shader_module(device, "reduce.wgsl", REDUCE_SHADER);
        let sh_partial = pipeline::compute_pipeline(
            device,
            "translucency sh partial",
            &pipeline::pipeline_layout(device, "sh partial", &[&sh_layout]),
            &reduce,
            "sh_partial",
        );
        let sh_final = pipeline::compute_pipeline(
            device,
            "translucency sh final",
            &pipeline::pipeline_layout(device, "sh final", &[&sh_layout, &sh_final_layout]),
            &reduce,
            "sh_final",
        );
        let blur_module = pipeline::shader_module(device, "blur.wgsl", BLUR_SHADER);
        let blur_pl = pipeline::pipeline_layout(device, "blur", &[&blur_layout]);
        let blur_h = pipeline::compute_pipeline(device, "blur h", &blur_pl, &blur_module, "blur_h");
        let blur_v = pipeline::compute_pipeline(device, "blur v", &blur_pl, &blur_module, "blur_v");

        let eval_module = pipeline::shader_module(
            device,
            "translucency eval",
            &format!("{}\n{COMMON_SHADER}\n{EVAL_SHADER}", render::VIEW_SHADER),
        );
        let eval = RenderPipelineDesc {
            label: "translucency eval",
            layout: &pipeline::pipeline_layout(
                device,
                "translucency eval",
                &[ctx.view_layout, &eval_layout],
            ),
            module: &eval_module,
            vertex: "vs_eval",
            fragment: Some("fs_eval"),
            buffers: &vertex_layout,
            color: Some(wgpu::ColorTargetState {
                format: ctx.format.color,
                blend: Some(wgpu::BlendState {
                    color: wgpu::BlendComponent {
                        src_factor: wgpu::BlendFactor::One,
                        dst_factor: wgpu::BlendFactor::One,
                        operation: wgpu::BlendOperation::Add,
                    },
                    alpha: wgpu::BlendComponent {
                        src_factor: wgpu::BlendFactor::Zero,
                        dst_factor: wgpu::BlendFactor::One,
                        operation: wgpu::BlendOperation::Add,
                    },
                }),
                write_mask: wgpu::ColorWrites::ALL,
            }),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: ctx.format.depth_stencil,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Equal),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            samples: ctx.format.samples,
            cull_mode: None,
        }
        .build(device);

        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency params"),
            size: std::mem::size_of::<ParamsUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params_group = bind_group(
            device,
            "translucency params",
            &params_layout,
            &[params_buffer.as_entire_binding()],
        );
        let window_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency window"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let coefficients = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency E_lm and M"),
            size: (27 + 48) * 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let sh_final_group = bind_group(
            device,
            "translucency sh final",
            &sh_final_layout,
            &[
                window_buffer.as_entire_binding(),
                coefficients.as_entire_binding(),
            ],
        );
        let blur_size = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency blur faces"),
            size: std::mem::size_of::<BlurUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });

        // Textures and the groups reading them.
        let cube = stacked(
            device,
            "translucency cube map",
            params.cube_size,
            wgpu::TextureFormat::Rgba32Float,
            RENDER | wgpu::TextureUsages::COPY_DST,
        );
        let cube_depth = stacked(
            device,
            "translucency cube depth",
            params.cube_size,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let ls = params.light_map_size;
        let first = stacked(
            device,
            "translucency first layer",
            ls,
            wgpu::TextureFormat::R32Float,
            RENDER,
        );
        let blurred_tmp = stacked(
            device,
            "translucency blur tmp",
            ls,
            wgpu::TextureFormat::R32Float,
            STORAGE,
        );
        let blurred = stacked(
            device,
            "translucency first layer blurred",
            ls,
            wgpu::TextureFormat::R32Float,
            STORAGE,
        );
        let second = stacked(
            device,
            "translucency second layer",
            ls,
            wgpu::TextureFormat::R32Float,
            RENDER,
        );
        let light_depth = stacked(
            device,
            "translucency light depth",
            ls,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let weights: Vec<f32> = cube::projection_weights(params.cube_size as usize)
            .iter()
            .flat_map(|w| w.map(|v| v as f32))
            .collect();
        let weights = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("translucency Y_lm·Δω"),
            contents: bytemuck::cast_slice(&weights),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let partials = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency partial sums"),
            size: REDUCE_GROUPS * 27 * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let (cube_v, first_v, tmp_v, blurred_v, second_v) = (
            view(&cube),
            view(&first),
            view(&blurred_tmp),
            view(&blurred),
            view(&second),
        );
        let sh_group = bind_group(
            device,
            "translucency sh",
            &sh_layout,
            &[
                wgpu::BindingResource::TextureView(&cube_v),
                weights.as_entire_binding(),
                partials.as_entire_binding(),
            ],
        );
        let peel_group = bind_group(
            device,
            "translucency peel",
            &peel_layout,
            &[wgpu::BindingResource::TextureView(&first_v)],
        );
        let blur_h_group = bind_group(
            device,
            "translucency blur h",
            &blur_layout,
            &[
                wgpu::BindingResource::TextureView(&first_v),
                wgpu::BindingResource::TextureView(&tmp_v),
                blur_size.as_entire_binding(),
            ],
        );
        let blur_v_group = bind_group(
            device,
            "translucency blur v",
            &blur_layout,
            &[
                wgpu::BindingResource::TextureView(&tmp_v),
                wgpu::BindingResource::TextureView(&blurred_v),
                blur_size.as_entire_binding(),
            ],
        );
        let eval_group = bind_group(
            device,
            "translucency eval",
            &eval_layout,
            &[
                params_buffer.as_entire_binding(),
                coefficients.as_entire_binding(),
                wgpu::BindingResource::TextureView(&blurred_v),
                wgpu::BindingResource::TextureView(&second_v),
            ],
        );
        Ok(Self {
            params,
            cube_pipeline,
            distance_pipeline,
            peel_pipeline,
            sh_partial,
            sh_final,
            blur_h,
            blur_v,
            eval,
            params_buffer,
            params_group,
            window_buffer,
            coefficients,
            sh_final_group,
            blur_uniform: blur_size,
            targets: Targets {
                cube,
                cube_depth,
                first,
                blurred,
                second,
                light_depth,
                sh_group,
                peel_group,
                blur_h_group,
                blur_v_group,
                eval_group,
            },
            mesh: None,
            light_faces: Vec::new(),
        })
    }
}
