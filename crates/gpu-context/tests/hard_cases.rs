//! The hard cases gpu-context defends: read-back of rows that are not a multiple of wgpu's
//! 256-byte copy pitch, empty read-backs, writes that fail half-way (nothing left behind), and
//! image buffers of the wrong size.

use gpu_context::testing::gpu_or_skip;
use gpu_context::{GpuError, HdrImage, read_buffer, read_hdr_image, write_rgba8_png};

#[test]
fn odd_row_pitch_reads_back_exactly() {
    let Some(ctx) = gpu_or_skip() else { return };
    // 37 texels × 16 bytes = 592 bytes per row: padded to 768 on the GPU side.
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("odd pitch"),
        size: wgpu::Extent3d {
            width: 37,
            height: 3,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let texels: Vec<[f32; 4]> = (0..37 * 3)
        .map(|i| [i as f32, -(i as f32), 1e30, f32::MIN_POSITIVE])
        .collect();
    ctx.queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(37 * 16),
            rows_per_image: Some(3),
        },
        texture.size(),
    );
    let image = read_hdr_image(&ctx.device, &ctx.queue, &texture).unwrap();
    assert_eq!((image.width(), image.height()), (37, 3));
    assert_eq!(image.pixels(), texels.as_slice());
}

#[test]
fn an_empty_buffer_read_back_is_empty_not_an_error() {
    let Some(ctx) = gpu_or_skip() else { return };
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    assert!(
        read_buffer(&ctx.device, &ctx.queue, &buffer, 0)
            .unwrap()
            .is_empty()
    );
}

#[test]
fn failed_writes_leave_nothing_and_name_the_file() {
    let dir = std::env::temp_dir().join(format!("gpu-context-hard-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A PNG whose buffer does not match its size.
    let path = dir.join("short.png");
    let err = write_rgba8_png(&path, &[0; 7], 2, 2).unwrap_err();
    assert!(
        matches!(&err, GpuError::Write { path: p, .. } if p == &path),
        "{err}"
    );
    assert!(!path.exists());
    // A complete file that cannot be renamed into place (the target is a folder): the
    // temporary file is removed. (A writer failing halfway is atomic-out's hard case.)
    let path = dir.join("folder.png");
    std::fs::create_dir(&path).unwrap();
    let err = write_rgba8_png(&path, &[0; 16], 2, 2).unwrap_err();
    let GpuError::Write { path: p, reason } = &err else {
        panic!("expected a write error, got {err}");
    };
    assert!(p == &path && reason.contains("rename"), "{err}");
    let image = HdrImage::new(1, 1, vec![[1.0; 4]]).unwrap();
    let err = image.write_exr(&path).unwrap_err();
    assert!(
        matches!(&err, GpuError::Write { path: p, .. } if p == &path),
        "{err}"
    );
    std::fs::remove_dir(&path).unwrap();
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn image_sizes_that_overflow_or_disagree_are_refused() {
    assert!(HdrImage::new(3, 3, vec![[0.0; 4]; 8]).is_err());
    assert!(HdrImage::new(0, 5, Vec::new()).is_ok());
}
