//! Offscreen targets on whatever adapter exists (lavapipe in CI): clear, read back, compare.

use gpu_context::OffscreenTarget;

/// The shared GPU-or-skip harness (fails under CI, visible skip otherwise).
use gpu_context::testing::gpu_or_skip as context;

#[test]
fn cleared_target_reads_back_exact_hdr_values_and_depth() {
    let Some(ctx) = context() else { return };
    eprintln!("adapter: {}", ctx.summary());
    let target = OffscreenTarget::new(&ctx.device, 37, 5).unwrap();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    {
        let color = target.color_view();
        let depth = target.depth_view();
        let _pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("clear"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 1234.5,
                        g: 0.25,
                        b: -2.0,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.375),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
    }
    ctx.queue.submit([encoder.finish()]);
    let image = target.read_color(&ctx.device, &ctx.queue).unwrap();
    assert_eq!((image.width(), image.height()), (37, 5));
    // 37 texels × 16 bytes is not a multiple of 256: row padding must be stripped.
    assert!(
        image
            .pixels()
            .iter()
            .all(|p| *p == [1234.5, 0.25, -2.0, 1.0])
    );
    let depth = target.read_depth(&ctx.device, &ctx.queue).unwrap();
    assert_eq!(depth.len(), 37 * 5);
    assert!(depth.iter().all(|&d| d == 0.375));
}

#[test]
fn zero_and_oversized_targets_are_rejected() {
    let Some(ctx) = context() else { return };
    let err = OffscreenTarget::new(&ctx.device, 0, 4).unwrap_err();
    assert!(err.to_string().contains("offscreen width of 0"), "{err}");
    let err = OffscreenTarget::new(&ctx.device, 4, u32::MAX).unwrap_err();
    assert!(err.to_string().contains("offscreen height"), "{err}");
}
