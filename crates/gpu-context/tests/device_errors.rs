//! A validation error on the device becomes `GpuError::Validation` at the next read-back instead
//! of wgpu's default panic (issue #12, C7). In its own test binary: the recorded errors are
//! process-wide, and a deliberate error must not reach another test's read-back.

use gpu_context::testing::gpu_or_skip;
use gpu_context::{GpuError, read_buffer, take_device_error};

#[test]
fn a_rejected_pipeline_is_an_error_at_read_back_not_a_panic() {
    let Some(ctx) = gpu_or_skip() else { return };
    let device = &ctx.device;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("output"),
        size: 16,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    // Valid before anything fails: the read-back returns the zeroed buffer.
    assert_eq!(
        read_buffer(device, &ctx.queue, &output, 16).unwrap(),
        vec![0u8; 16]
    );
    // A shader that does not type-check: wgpu reports it asynchronously to the device's
    // handler (its default handler panics); the pipeline built from it is invalid, and so is
    // the dispatch that uses it.
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("broken"),
        source: wgpu::ShaderSource::Wgsl(
            "@group(0) @binding(0) var<storage, read_write> out: array<u32>;\n\
             @compute @workgroup_size(1) fn main() { out[0] = 1.5; }"
                .into(),
        ),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("broken"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.dispatch_workgroups(1, 1, 1);
    }
    ctx.queue.submit([encoder.finish()]);
    match read_buffer(device, &ctx.queue, &output, 16) {
        Err(GpuError::Validation(message)) => {
            assert!(message.contains("broken"), "the label is named: {message}");
        }
        other => panic!("expected a validation error, got {other:?}"),
    }
    // Taken once: the next read-back is clean again.
    assert_eq!(take_device_error(), None);
    assert!(read_buffer(device, &ctx.queue, &output, 16).is_ok());
    assert!(ctx.wait_idle().is_ok());
}
