//! Typed bindings. Each bind group of a pass is a struct of named buffer fields, declared
//! with [`bindings!`](crate::bindings!) in the order of its WGSL `@binding` numbers, each field with its
//! access (a parameter block, read-only or read-write storage). The struct makes the bind
//! group layout and the bind group, so the two cannot disagree, and a caller names every
//! buffer it binds: two read-only buffers swapped no longer validate by position alone.
//! `tests/bindings.rs` reads every shader's `@group/@binding` variables with naga and
//! fails when a declaration disagrees with its WGSL in name, order or access.
//!
//! What a bind group binds, with its access, is also what the frame's recorder reads to
//! decide which passes can run side by side (`frame::recorder`).

use crate::shader::ParamsBinding;

/// How a pass uses a buffer it binds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// A parameter block: `var<uniform>` in the WGSL (a read-only storage buffer on
    /// software adapters, see [`ParamsBinding`]).
    Params,
    /// `var<storage, read>`.
    Read,
    /// `var<storage, read_write>`.
    Write,
}

impl Access {
    /// Whether the buffer is only read.
    pub fn reads_only(self) -> bool {
        self != Access::Write
    }

    /// The layout's buffer type on a device whose parameter blocks are bound as `params`.
    pub fn buffer_type(self, params: ParamsBinding) -> wgpu::BufferBindingType {
        match self {
            Access::Params => params.buffer_type(),
            Access::Read => wgpu::BufferBindingType::Storage { read_only: true },
            Access::Write => wgpu::BufferBindingType::Storage { read_only: false },
        }
    }
}

/// One binding of a bind group: the WGSL variable's name and its access.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub name: &'static str,
    pub access: Access,
}

/// A bind group's declaration: which shader declares it, as which group, and its
/// bindings in `@binding` order (binding i is `bindings[i]`).
#[derive(Clone, Copy, Debug)]
pub struct GroupDecl {
    /// The shader's name in `shader::SOURCES`.
    pub shader: &'static str,
    pub group: u32,
    pub bindings: &'static [Binding],
}

/// A bind group's buffers by name, as a struct made by [`bindings!`](crate::bindings!).
pub trait Bindings<'a> {
    /// The bindings in `@binding` order.
    const BINDINGS: &'static [Binding];
    /// The buffers in the same order.
    fn buffers(&self) -> Vec<&'a wgpu::Buffer>;
}

/// Declares a bind group as a struct of `&wgpu::Buffer` fields named as the WGSL
/// variables, in `@binding` order, each with its [`Access`]:
///
/// ```ignore
/// bindings! {
///     /// What the filter reads and writes.
///     pub struct FilterBindings {
///         params: Params,
///         gbuf_position: Read,
///         filter_out: Write,
///     }
/// }
/// ```
#[macro_export]
macro_rules! bindings {
    ($(#[$meta:meta])* pub struct $name:ident {
        $($(#[$field_meta:meta])* $field:ident: $access:ident),* $(,)?
    }) => {
        $(#[$meta])*
        pub struct $name<'a> {
            $($(#[$field_meta])* pub $field: &'a wgpu::Buffer,)*
        }

        impl<'a> $crate::passes::bindings::Bindings<'a> for $name<'a> {
            const BINDINGS: &'static [$crate::passes::bindings::Binding] = &[
                $($crate::passes::bindings::Binding {
                    name: stringify!($field),
                    access: $crate::passes::bindings::Access::$access,
                },)*
            ];

            fn buffers(&self) -> Vec<&'a wgpu::Buffer> {
                vec![$(self.$field,)*]
            }
        }
    };
}

/// A bind group with what it binds: each buffer and its access, for the recorder.
pub struct Bound<'a> {
    pub group: wgpu::BindGroup,
    pub uses: Vec<(&'a wgpu::Buffer, Access)>,
}

/// The layout of a bind group of `bindings`, visible to `stages`.
pub fn layout_of(
    device: &wgpu::Device,
    label: &str,
    bindings: &[Binding],
    stages: wgpu::ShaderStages,
) -> wgpu::BindGroupLayout {
    let params = ParamsBinding::of(device);
    let entries: Vec<_> = bindings
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupLayoutEntry {
            binding: i as u32,
            visibility: stages,
            ty: wgpu::BindingType::Buffer {
                ty: b.access.buffer_type(params),
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// The compute-stage layout of the bind group `B`.
pub fn compute_layout<'a, B: Bindings<'a>>(
    device: &wgpu::Device,
    label: &str,
) -> wgpu::BindGroupLayout {
    layout_of(device, label, B::BINDINGS, wgpu::ShaderStages::COMPUTE)
}

/// The bind group of `bindings` (each buffer whole) in `layout`, made by
/// [`compute_layout`] or [`layout_of`] for the same struct.
pub fn bind<'a, B: Bindings<'a>>(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    bindings: &B,
) -> Bound<'a> {
    let buffers = bindings.buffers();
    let entries: Vec<_> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    });
    let uses = buffers
        .into_iter()
        .zip(B::BINDINGS)
        .map(|(b, d)| (b, d.access))
        .collect();
    Bound { group, uses }
}
