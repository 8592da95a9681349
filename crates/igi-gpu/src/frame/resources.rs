//! The frame's buffers, declared once: [`DECLARATIONS`] names each buffer, says what
//! sizes it and what it holds, and drives its allocation, its label, the frame's byte
//! count ([`super::Renderer::frame_bytes`], the bench's memory figure) and the readback
//! of a buffer by name (the CPU twins' tests). The G-buffer's records and what each
//! component holds are documented once, in `shaders/gbuffer.wgsl`.

use super::MAX_SUBSETS;
use crate::context::{GpuContext, GpuError, SMALLER_FRAME};
use crate::layout::Vpl;

/// A buffer of the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Buf {
    /// The frame's parameters (`FrameParams`).
    Params,
    /// The same parameters for the passes over the mirrored hits, whose image is the
    /// full-resolution one (no downsampling).
    MirrorParams,
    /// The VPL count and what it came from (`VplHeader`).
    VplHeader,
    /// An empty VPL list and header bound to the direct pass's first walk, which gathers
    /// nothing: binding the ones VPL shooting writes would keep the two passes apart.
    NoVpls,
    NoVplHeader,
    /// What the direct pass's later walks bind where its first walk binds the G-buffer,
    /// the mirror record and the mirror list, which only the first walk writes: buffers
    /// no other pass binds, so that the later walks run beside the gathers that read the
    /// first walk's outputs ([`CHAIN_SCRATCH`] of them).
    ChainScratch,
    /// A slot per light path and bounce, as VPL shooting writes them.
    VplSlots,
    /// The dense VPL list after compaction.
    Vpls,
    /// Direct + specular radiance, and the VPL light at hits seen in a mirror seen in a
    /// mirror (the chains' walks add it).
    Direct,
    /// The G-buffer of the primary hits.
    GbufPosition,
    GbufNormal,
    GbufGeometric,
    GbufAlbedo,
    /// The first diffuse hit of each pixel's mirror chain: the same four records.
    MirrorPosition,
    MirrorNormal,
    MirrorGeometric,
    MirrorWeight,
    /// E at the mirrored hits (full resolution), as the mirror gather leaves it.
    MirrorIrradiance,
    /// The same after the discontinuity buffer (interleaved frames).
    MirrorFiltered,
    /// E at the indirect term's resolution, as the indirect gather leaves it.
    Irradiance,
    /// After the discontinuity buffer (the indirect term's resolution).
    FilteredLow,
    /// After the fused filter (full resolution).
    Filtered,
    /// The composed linear radiance, averaged over accumulated frames.
    Color,
    /// The pixels with a mirrored hit: a counter per interleaving subset, then a bucket of
    /// pixels per subset (direct.wgsl's mirror_list).
    MirrorList,
    /// The pixels whose mirror chain the direct pass's later walks follow: a counter, then
    /// the pixels (direct.wgsl's chain_list).
    ChainList,
}

/// Copies of [`Buf::ChainScratch`]: one per binding of the first walk that the later
/// walks do not write.
pub const CHAIN_SCRATCH: usize = 9;

/// What sizes a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Size {
    /// Made with the renderer: this many bytes.
    Fixed(u64),
    /// One record of 16 bytes per pixel of the image.
    Pixels,
    /// [`Buf::MirrorList`]'s counters and buckets for the image.
    MirrorList,
    /// [`Buf::ChainList`]'s counter and pixels for the image.
    ChainList,
    /// One VPL per slot (paths x bounces).
    VplSlots,
}

/// A buffer's declaration.
#[derive(Clone, Copy, Debug)]
pub struct Declaration {
    pub buf: Buf,
    /// Its label on the device and its name for [`super::Renderer::read_frame_buffer`].
    pub label: &'static str,
    pub size: Size,
    /// How many copies (1 but for the chain walks' scratch).
    pub copies: usize,
}

const fn one(buf: Buf, label: &'static str, size: Size) -> Declaration {
    Declaration {
        buf,
        label,
        size,
        copies: 1,
    }
}

/// Every buffer of the frame, in the order they are made.
pub const DECLARATIONS: &[Declaration] = &[
    one(
        Buf::Params,
        "frame params",
        Size::Fixed(std::mem::size_of::<crate::layout::FrameParams>() as u64),
    ),
    one(
        Buf::MirrorParams,
        "mirror filter params",
        Size::Fixed(std::mem::size_of::<crate::layout::FrameParams>() as u64),
    ),
    one(Buf::VplHeader, "vpl header", Size::Fixed(16)),
    one(
        Buf::NoVpls,
        "no vpls",
        Size::Fixed(std::mem::size_of::<Vpl>() as u64),
    ),
    one(Buf::NoVplHeader, "no vpl header", Size::Fixed(16)),
    Declaration {
        buf: Buf::ChainScratch,
        label: "chain walk scratch",
        size: Size::Fixed(16),
        copies: CHAIN_SCRATCH,
    },
    one(Buf::VplSlots, "vpl slots", Size::VplSlots),
    one(Buf::Vpls, "vpls", Size::VplSlots),
    one(Buf::Direct, "direct", Size::Pixels),
    one(Buf::GbufPosition, "gbuffer position", Size::Pixels),
    one(Buf::GbufNormal, "gbuffer normal", Size::Pixels),
    one(Buf::GbufGeometric, "gbuffer geometric normal", Size::Pixels),
    one(Buf::GbufAlbedo, "gbuffer albedo", Size::Pixels),
    one(Buf::MirrorPosition, "mirror position", Size::Pixels),
    one(Buf::MirrorNormal, "mirror normal", Size::Pixels),
    one(
        Buf::MirrorGeometric,
        "mirror geometric normal",
        Size::Pixels,
    ),
    one(Buf::MirrorWeight, "mirror weight", Size::Pixels),
    one(Buf::MirrorIrradiance, "mirror irradiance", Size::Pixels),
    one(
        Buf::MirrorFiltered,
        "mirror irradiance after discontinuity",
        Size::Pixels,
    ),
    one(Buf::Irradiance, "irradiance", Size::Pixels),
    one(
        Buf::FilteredLow,
        "irradiance after discontinuity",
        Size::Pixels,
    ),
    one(Buf::Filtered, "irradiance full resolution", Size::Pixels),
    one(Buf::Color, "color", Size::Pixels),
    one(Buf::MirrorList, "mirror list", Size::MirrorList),
    one(Buf::ChainList, "mirror chain list", Size::ChainList),
];

/// The declaration of `buf`.
pub fn declaration(buf: Buf) -> &'static Declaration {
    DECLARATIONS
        .iter()
        .find(|d| d.buf == buf)
        .expect("every buffer is declared")
}

/// How many buffers hold one record per pixel.
pub fn pixel_buffers() -> usize {
    DECLARATIONS
        .iter()
        .filter(|d| d.size == Size::Pixels)
        .map(|d| d.copies)
        .sum()
}

impl Size {
    /// Bytes of one copy for a `width` x `height` image and `slots` VPL slots (at least
    /// 16: empty arrays still need a binding).
    pub fn bytes(self, width: u32, height: u32, slots: u64) -> u64 {
        let (w, h) = (width as u64, height as u64);
        let subsets = MAX_SUBSETS as u64;
        let bytes = match self {
            Size::Fixed(b) => b,
            Size::Pixels => w * h * 16,
            // A counter per subset, then n x m buckets of ceil(w / n) ceil(h / m) pixels,
            // at most (w + 63) (h + 63) for at most 64 subsets.
            Size::MirrorList => (subsets + (w + subsets - 1) * (h + subsets - 1)) * 4,
            Size::ChainList => (1 + w * h) * 4,
            Size::VplSlots => slots * std::mem::size_of::<Vpl>() as u64,
        };
        bytes.max(16)
    }

    /// Which allocation the buffer belongs to.
    fn group(self) -> Group {
        match self {
            Size::Fixed(_) => Group::Fixed,
            Size::VplSlots => Group::VplSlots,
            _ => Group::Image,
        }
    }
}

/// The buffers are made in three groups, each when what sizes it is known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Group {
    Fixed,
    Image,
    VplSlots,
}

/// Buffers of one group, by declaration.
struct Allocated {
    buffers: Vec<(Buf, Vec<wgpu::Buffer>)>,
}

impl Allocated {
    fn make(
        device: &wgpu::Device,
        group: Group,
        width: u32,
        height: u32,
        slots: u64,
        usage: impl Fn(Buf) -> wgpu::BufferUsages,
    ) -> Allocated {
        let buffers = DECLARATIONS
            .iter()
            .filter(|d| d.size.group() == group)
            .map(|d| {
                let size = d.size.bytes(width, height, slots);
                let copies = (0..d.copies)
                    .map(|_| {
                        device.create_buffer(&wgpu::BufferDescriptor {
                            label: Some(d.label),
                            size,
                            usage: usage(d.buf),
                            mapped_at_creation: false,
                        })
                    })
                    .collect();
                (d.buf, copies)
            })
            .collect();
        Allocated { buffers }
    }

    fn get(&self, buf: Buf) -> Option<&[wgpu::Buffer]> {
        self.buffers
            .iter()
            .find(|(b, _)| *b == buf)
            .map(|(_, copies)| copies.as_slice())
    }

    fn bytes(&self) -> u64 {
        self.buffers
            .iter()
            .flat_map(|(_, copies)| copies)
            .map(|b| b.size())
            .sum()
    }
}

/// Bytes of the declarations of `group` for the given sizes.
fn group_bytes(group: Group, width: u32, height: u32, slots: u64) -> u64 {
    DECLARATIONS
        .iter()
        .filter(|d| d.size.group() == group)
        .map(|d| d.copies as u64 * d.size.bytes(width, height, slots))
        .sum()
}

/// The usage of every frame buffer but the parameter blocks.
fn storage_usage() -> wgpu::BufferUsages {
    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST
}

/// The frame's buffers: the fixed ones, and those sized by the image and by the VPL
/// slots once a frame has asked for them.
pub struct FrameBuffers {
    fixed: Allocated,
    image: Option<((u32, u32), Allocated)>,
    vpl_slots: Option<(u64, Allocated)>,
}

impl FrameBuffers {
    /// The fixed buffers; parameter blocks with `params_usage`.
    pub fn new(device: &wgpu::Device, params_usage: wgpu::BufferUsages) -> FrameBuffers {
        let fixed = Allocated::make(device, Group::Fixed, 0, 0, 0, |buf| match buf {
            Buf::Params | Buf::MirrorParams => params_usage,
            _ => storage_usage(),
        });
        FrameBuffers {
            fixed,
            image: None,
            vpl_slots: None,
        }
    }

    /// The buffer `buf` (its first copy). Panics for a buffer whose group is not made
    /// yet: the frame makes them before it records a pass.
    pub fn get(&self, buf: Buf) -> &wgpu::Buffer {
        &self.copies(buf)[0]
    }

    /// Every copy of `buf`.
    pub fn copies(&self, buf: Buf) -> &[wgpu::Buffer] {
        [
            Some(&self.fixed),
            self.image.as_ref().map(|(_, a)| a),
            self.vpl_slots.as_ref().map(|(_, a)| a),
        ]
        .into_iter()
        .flatten()
        .find_map(|a| a.get(buf))
        .unwrap_or_else(|| panic!("{buf:?} is not allocated yet"))
    }

    /// The image size of the image-sized buffers, once made.
    pub fn image_size(&self) -> Option<(u32, u32)> {
        self.image.as_ref().map(|(size, _)| *size)
    }

    /// VPL slots of the VPL buffers, once made.
    pub fn vpl_slots(&self) -> Option<u64> {
        self.vpl_slots.as_ref().map(|(slots, _)| *slots)
    }

    /// Whether the buffers of `buf`'s group are made.
    pub fn has(&self, buf: Buf) -> bool {
        match declaration(buf).size.group() {
            Group::Fixed => true,
            Group::Image => self.image.is_some(),
            Group::VplSlots => self.vpl_slots.is_some(),
        }
    }

    /// Bytes of every buffer made.
    pub fn bytes(&self) -> u64 {
        self.fixed.bytes()
            + self.image.as_ref().map_or(0, |(_, a)| a.bytes())
            + self.vpl_slots.as_ref().map_or(0, |(_, a)| a.bytes())
    }

    /// The image-sized buffers for `width` x `height`: made again when the size changes,
    /// the old ones freed first (the new set may need their memory).
    pub fn ensure_image(
        &mut self,
        ctx: &GpuContext,
        width: u32,
        height: u32,
    ) -> Result<(), GpuError> {
        if self.image_size() == Some((width, height)) {
            return Ok(());
        }
        self.image = None;
        let made = ctx.allocate(
            || {
                format!(
                    "the {} frame buffers of a {width}x{height} image",
                    pixel_buffers()
                )
            },
            group_bytes(Group::Image, width, height, 0),
            SMALLER_FRAME,
            || {
                Allocated::make(&ctx.device, Group::Image, width, height, 0, |_| {
                    storage_usage()
                })
            },
        )?;
        self.image = Some(((width, height), made));
        Ok(())
    }

    /// The VPL buffers for at least `slots` slots (made again, larger, when a frame needs
    /// more).
    pub fn ensure_vpl_slots(&mut self, ctx: &GpuContext, slots: u64) -> Result<(), GpuError> {
        if self.vpl_slots().is_some_and(|s| s >= slots) {
            return Ok(());
        }
        let bytes = Size::VplSlots.bytes(0, 0, slots);
        if bytes > ctx.max_storage_binding() {
            return Err(GpuError::Limit(format!(
                "{slots} VPL slots need {} MiB, more than this adapter's max_storage_buffer_binding_size of {} MiB: ask for fewer VPLs or bounces",
                bytes >> 20,
                ctx.max_storage_binding() >> 20
            )));
        }
        self.vpl_slots = None;
        let made = ctx.allocate(
            || format!("the VPL buffers for {slots} VPL slots"),
            group_bytes(Group::VplSlots, 0, 0, slots),
            "fewer VPLs or bounces need less",
            || {
                Allocated::make(&ctx.device, Group::VplSlots, 0, 0, slots, |_| {
                    storage_usage()
                })
            },
        )?;
        self.vpl_slots = Some((slots, made));
        Ok(())
    }

    /// The buffer labelled `label` (see [`DECLARATIONS`]), if it is made.
    pub fn by_label(&self, label: &str) -> Option<&wgpu::Buffer> {
        let d = DECLARATIONS.iter().find(|d| d.label == label)?;
        self.has(d.buf).then(|| self.get(d.buf))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_buffer_is_declared_once_with_its_own_label() {
        for (i, a) in DECLARATIONS.iter().enumerate() {
            for b in &DECLARATIONS[i + 1..] {
                assert_ne!(a.buf, b.buf, "{:?} declared twice", a.buf);
                assert_ne!(a.label, b.label, "label {:?} used twice", a.label);
            }
        }
        assert_eq!(pixel_buffers(), 15);
    }

    #[test]
    fn the_image_group_holds_the_pixel_records_and_both_lists() {
        let (w, h) = (800u64, 600u64);
        let bytes = group_bytes(Group::Image, w as u32, h as u32, 0);
        let lists = (64 + (w + 63) * (h + 63)) * 4 + (1 + w * h) * 4;
        assert_eq!(bytes, 15 * w * h * 16 + lists);
    }
}
