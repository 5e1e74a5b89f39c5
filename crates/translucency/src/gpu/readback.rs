//! Read-backs for tests and pictures, and the SH reduction of any cube map.

use gpu_context::{read_buffer, read_texture};

use super::{REDUCE_GROUPS, TranslucencyPass};
use crate::cube::CubeMap;
use crate::error::{TranslucencyError, bad_parameter};
use crate::sh::{SH_COUNT, Sh9};

impl TranslucencyPass {
    /// Read back this frame's cube map (pass 1) — for tests and pictures.
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_cube_map(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<CubeMap, TranslucencyError> {
        let bytes = read_texture(
            device,
            queue,
            &self.targets.cube,
            16,
            wgpu::TextureAspect::All,
        )?;
        let rgba: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        CubeMap::new(
            self.params.cube_size as usize,
            rgba.iter().map(|t| [t[0], t[1], t[2]]).collect(),
        )
    }

    /// Project any cube map of this pass's face size with the GPU reduction (pass 2 alone):
    /// what `cloth-vis sh --gpu` runs, and the check of the reduction against the f64 sum.
    /// It overwrites this frame's cube map.
    ///
    /// # Errors
    /// A face size other than [`super::PipelineParams::cube_size`]; a failed read-back.
    pub fn project_on_gpu(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cube: &CubeMap,
    ) -> Result<Sh9, TranslucencyError> {
        let size = self.params.cube_size;
        if cube.size() != size as usize {
            return Err(bad_parameter(
                "cube face size",
                cube.size(),
                "must equal the pass's cube_size",
            ));
        }
        let rgba: Vec<[f32; 4]> = cube
            .texels()
            .iter()
            .map(|t| [t[0], t[1], t[2], 1.0])
            .collect();
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.targets.cube,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&rgba),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(16 * size),
                rows_per_image: Some(6 * size),
            },
            wgpu::Extent3d {
                width: size,
                height: 6 * size,
                depth_or_array_layers: 1,
            },
        );
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("translucency sh only"),
        });
        self.record_sh(&mut encoder);
        queue.submit([encoder.finish()]);
        self.read_coefficients(device, queue)
    }

    pub(super) fn record_sh(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("translucency sh"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.sh_partial);
        pass.set_bind_group(0, &self.targets.sh_group, &[]);
        pass.dispatch_workgroups(REDUCE_GROUPS as u32, 1, 1);
        pass.set_pipeline(&self.sh_final);
        pass.set_bind_group(1, &self.sh_final_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// Read back this frame's E_lm as the GPU reduced them (before the window).
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_coefficients(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Sh9, TranslucencyError> {
        let bytes = read_buffer(device, queue, &self.coefficients, 27 * 4)?;
        let v: &[f32] = bytemuck::cast_slice(&bytes);
        let mut sh = Sh9::default();
        for k in 0..SH_COUNT {
            for c in 0..3 {
                sh.coeffs[k][c] = f64::from(v[3 * k + c]);
            }
        }
        Ok(sh)
    }

    /// Read back the light map's layers — (first blurred, second), each `size` × 6·`size`,
    /// 1e30 where empty — for tests.
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_light_layers(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<(Vec<f32>, Vec<f32>), TranslucencyError> {
        let read = |t: &wgpu::Texture| {
            read_texture(device, queue, t, 4, wgpu::TextureAspect::All)
                .map(|b| bytemuck::cast_slice::<u8, f32>(&b).to_vec())
        };
        Ok((read(&self.targets.blurred)?, read(&self.targets.second)?))
    }

    /// The unblurred first layer (for tests of the blur).
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_first_layer_raw(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<f32>, TranslucencyError> {
        let b = read_texture(
            device,
            queue,
            &self.targets.first,
            4,
            wgpu::TextureAspect::All,
        )?;
        Ok(bytemuck::cast_slice::<u8, f32>(&b).to_vec())
    }
}
