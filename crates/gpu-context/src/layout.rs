//! One-line bind-group layouts and bind groups (after bevy's `BindGroupLayoutEntries`).
//!
//! A layout entry in raw wgpu is eleven lines; here it is one [`wgpu::BindingType`] from
//! [`binding`], numbered in order by [`sequential`]:
//!
//! ```no_run
//! # fn demo(device: &wgpu::Device, uniform: &wgpu::Buffer, data: &wgpu::Buffer) {
//! use gpu_context::layout::{binding, bind_group, bind_group_layout};
//! let layout = bind_group_layout(
//!     device,
//!     "frame",
//!     wgpu::ShaderStages::VERTEX_FRAGMENT,
//!     &[binding::uniform(), binding::storage_read()],
//! );
//! let group = bind_group(
//!     device,
//!     "frame",
//!     &layout,
//!     &[uniform.as_entire_binding(), data.as_entire_binding()],
//! );
//! # }
//! ```

/// Binding types in one call each.
pub mod binding {
    /// A uniform buffer.
    pub fn uniform() -> wgpu::BindingType {
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        }
    }

    /// A read-only storage buffer.
    pub fn storage_read() -> wgpu::BindingType {
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        }
    }

    /// A read-write storage buffer.
    pub fn storage_rw() -> wgpu::BindingType {
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        }
    }

    /// A sampled texture of `dimension` whose texels read as `sample_type`.
    pub fn texture(
        sample_type: wgpu::TextureSampleType,
        dimension: wgpu::TextureViewDimension,
    ) -> wgpu::BindingType {
        wgpu::BindingType::Texture {
            sample_type,
            view_dimension: dimension,
            multisampled: false,
        }
    }

    /// A depth texture (2-D, compared or loaded).
    pub fn depth_texture() -> wgpu::BindingType {
        texture(
            wgpu::TextureSampleType::Depth,
            wgpu::TextureViewDimension::D2,
        )
    }

    /// A sampler of the given kind.
    pub fn sampler(kind: wgpu::SamplerBindingType) -> wgpu::BindingType {
        wgpu::BindingType::Sampler(kind)
    }
}

/// Layout entries numbered 0, 1, 2, … in the order given, all visible to `visibility`.
pub fn sequential(
    visibility: wgpu::ShaderStages,
    types: &[wgpu::BindingType],
) -> Vec<wgpu::BindGroupLayoutEntry> {
    types
        .iter()
        .zip(0u32..)
        .map(|(ty, binding)| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: *ty,
            count: None,
        })
        .collect()
}

/// A bind-group layout whose bindings are `types`, numbered in order.
pub fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    visibility: wgpu::ShaderStages,
    types: &[wgpu::BindingType],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &sequential(visibility, types),
    })
}

/// A bind group whose resources are bound to 0, 1, 2, … in the order given.
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
        .iter()
        .zip(0u32..)
        .map(|(resource, binding)| wgpu::BindGroupEntry {
            binding,
            resource: resource.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_are_numbered_in_order_with_one_visibility() {
        let entries = sequential(
            wgpu::ShaderStages::COMPUTE,
            &[
                binding::uniform(),
                binding::storage_read(),
                binding::storage_rw(),
            ],
        );
        let numbers: Vec<u32> = entries.iter().map(|e| e.binding).collect();
        assert_eq!(numbers, [0, 1, 2]);
        assert!(
            entries
                .iter()
                .all(|e| e.visibility == wgpu::ShaderStages::COMPUTE && e.count.is_none())
        );
        assert_eq!(entries[2].ty, binding::storage_rw());
    }
}
