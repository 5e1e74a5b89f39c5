//! Shader-module and pipeline builders, and a per-thread count of what was built.
//!
//! The count is what proves that a renderer builds its pipelines once: a test renders a
//! sequence of frames and asserts that [`PipelineStats::on_this_thread`] did not grow after
//! the first (wgpu creates pipelines on the calling thread, so a per-thread count is exact
//! while other tests run in parallel).

use std::cell::Cell;

thread_local! {
    static SHADER_MODULES: Cell<u64> = const { Cell::new(0) };
    static RENDER_PIPELINES: Cell<u64> = const { Cell::new(0) };
    static COMPUTE_PIPELINES: Cell<u64> = const { Cell::new(0) };
}

/// How many shader modules and pipelines this thread has built through this module.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PipelineStats {
    /// Shader modules compiled ([`shader_module`]).
    pub shader_modules: u64,
    /// Render pipelines built ([`RenderPipelineDesc::build`]).
    pub render_pipelines: u64,
    /// Compute pipelines built ([`compute_pipeline`]).
    pub compute_pipelines: u64,
}

impl PipelineStats {
    /// The counts of the calling thread.
    pub fn on_this_thread() -> Self {
        Self {
            shader_modules: SHADER_MODULES.with(Cell::get),
            render_pipelines: RENDER_PIPELINES.with(Cell::get),
            compute_pipelines: COMPUTE_PIPELINES.with(Cell::get),
        }
    }
}

fn bump(counter: &'static std::thread::LocalKey<Cell<u64>>) {
    counter.with(|c| c.set(c.get() + 1));
}

/// Compile WGSL `source` into a shader module (counted).
pub fn shader_module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    bump(&SHADER_MODULES);
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

/// A pipeline layout of the given bind-group layouts, no immediates.
pub fn pipeline_layout(
    device: &wgpu::Device,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    })
}

/// A compute pipeline running `entry` of `module` (counted).
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    bump(&COMPUTE_PIPELINES);
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A triangle-list render pipeline with the fields our passes vary; the rest are wgpu's
/// defaults (counter-clockwise front faces, no blending unless `color.blend` says so).
#[derive(Clone, Debug)]
pub struct RenderPipelineDesc<'a> {
    /// Debug label.
    pub label: &'a str,
    /// Pipeline layout.
    pub layout: &'a wgpu::PipelineLayout,
    /// Module holding both entry points.
    pub module: &'a wgpu::ShaderModule,
    /// Vertex entry point.
    pub vertex: &'a str,
    /// Fragment entry point; `None` for depth-only passes.
    pub fragment: Option<&'a str>,
    /// Vertex buffer layouts.
    pub buffers: &'a [wgpu::VertexBufferLayout<'a>],
    /// Colour target (format, blend, write mask); `None` for depth-only passes.
    pub color: Option<wgpu::ColorTargetState>,
    /// Depth/stencil state.
    pub depth_stencil: Option<wgpu::DepthStencilState>,
    /// MSAA sample count (1 = none).
    pub samples: u32,
    /// Face culling (`None` draws both faces).
    pub cull_mode: Option<wgpu::Face>,
}

impl RenderPipelineDesc<'_> {
    /// Build the pipeline (counted).
    pub fn build(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        bump(&RENDER_PIPELINES);
        let buffers: Vec<Option<wgpu::VertexBufferLayout<'_>>> =
            self.buffers.iter().cloned().map(Some).collect();
        let targets = [self.color.clone()];
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(self.label),
            layout: Some(self.layout),
            vertex: wgpu::VertexState {
                module: self.module,
                entry_point: Some(self.vertex),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: self.cull_mode,
                ..Default::default()
            },
            depth_stencil: self.depth_stencil.clone(),
            multisample: wgpu::MultisampleState {
                count: self.samples,
                ..Default::default()
            },
            fragment: self.fragment.map(|entry| wgpu::FragmentState {
                module: self.module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: if self.color.is_some() { &targets } else { &[] },
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}
