//! The reader's state ([`Reader`]), its buffers (GLB chunk, `data:` URIs and files), the
//! checks of buffer views and accessors that the gltf crate's readers assume, and the
//! reading of each accessor, once however many primitives use it: floats, or the integers
//! of KHR_mesh_quantization turned into the values they stand for ([`Components`]).

use std::collections::HashMap;
use std::path::PathBuf;
use std::rc::Rc;

use ::gltf::accessor::{DataType, Dimensions, Item, Iter};
use glam::{Vec2, Vec3, Vec4};

use super::document::{percent_decode, Warnings};
use super::materials::ImageSource;
use super::messages::{parse, quote, quote_message};
use super::nodes::Prepared;
use super::{GltfMesh, MAX_VIEWLESS_ELEMENTS};
use crate::scene::loader::{read_regular_file, SceneError, TriangleBudget};

pub(super) struct Reader {
    pub(super) file: String,
    /// The glTF file's directory: relative URIs start there.
    pub(super) dir: PathBuf,
    /// File name without extension, for names of unnamed materials.
    pub(super) stem: String,
    pub(super) buffers: Vec<::gltf::buffer::Data>,
    pub(super) out: GltfMesh,
    /// glTF material index (`None`: default material) -> index in `out.materials`.
    pub(super) materials: HashMap<Option<usize>, usize>,
    /// Per entry of `out.materials`: the texture coordinate set its base colour texture
    /// reads (`None`: no texture), so that primitives read that TEXCOORD_n.
    pub(super) uv_sets: Vec<Option<u32>>,
    /// Image index -> index in `out.textures` (`None`: could not be decoded).
    pub(super) textures: HashMap<usize, Option<u32>>,
    /// Images whose `Image::source()` would panic in the gltf crate (found by fuzzing:
    /// neither `uri` nor `bufferView`, or a `bufferView` without `mimeType`), with why.
    pub(super) bad_images: HashMap<usize, &'static str>,
    pub(super) warn: Warnings,
    /// The triangles the scene may still take (the loader's limit, less earlier meshes').
    pub(super) budget: TriangleBudget,
    pub(super) shared: Shared,
    pub(super) stats: ReadStats,
}

/// What many nodes or primitives may share, read once: accessors by index, primitives by
/// (mesh, primitive) index, image averages by source. A file whose thousand nodes place
/// one mesh reads its data once, and only its triangles are made per node.
#[derive(Default)]
pub(super) struct Shared {
    /// By accessor index and the [`Components`] it was read as (which types it may have).
    pub(super) vec2s: HashMap<(usize, &'static str), Rc<[Vec2]>>,
    pub(super) vec3s: HashMap<(usize, &'static str), Rc<[Vec3]>>,
    pub(super) vec4s: HashMap<(usize, &'static str), Rc<[Vec4]>>,
    pub(super) indices: HashMap<usize, Rc<[u32]>>,
    /// `None`: a primitive of mode POINTS or LINES*, skipped.
    pub(super) primitives: HashMap<(usize, usize), Option<Rc<Prepared>>>,
    /// Image source -> index in `out.textures` (`None`: could not be decoded).
    pub(super) images: HashMap<ImageSource, Option<u32>>,
    /// Elements of accessors without a buffer view read so far (see
    /// [`MAX_VIEWLESS_ELEMENTS`]).
    pub(super) viewless: usize,
}

/// How much work reading a file took, counted so that tests can check that shared data is
/// read once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct ReadStats {
    pub(super) accessors_read: usize,
    pub(super) images_decoded: usize,
}

/// The component types an attribute may have: FLOAT, and the integer types of glTF 2.0
/// and KHR_mesh_quantization (which gltfpack writes by default), each read as the value it
/// stands for. The gltf crate's own readers (`read_positions`...) take floats only.
#[derive(Clone, Copy, Debug)]
pub(super) struct Components {
    /// Names the rule in caches and messages.
    pub(super) name: &'static str,
    /// Integer types that may be normalized: read as c / MAX, and for signed types
    /// max(c / MAX, -1), as the glTF specification says.
    pub(super) normalized: &'static [DataType],
    /// Integer types that may be read as their plain values.
    pub(super) plain: &'static [DataType],
}

const ALL_INTS: &[DataType] = &[DataType::I8, DataType::U8, DataType::I16, DataType::U16];

/// POSITION (and instance TRANSLATION and SCALE): with KHR_mesh_quantization, bytes and
/// shorts, signed or not, normalized or not.
pub(super) const POSITIONS: Components = Components {
    name: "positions",
    normalized: ALL_INTS,
    plain: ALL_INTS,
};

/// NORMAL: with KHR_mesh_quantization, normalized signed bytes and shorts.
pub(super) const NORMALS: Components = Components {
    name: "normals",
    normalized: &[DataType::I8, DataType::I16],
    plain: &[],
};

/// TEXCOORD_n: normalized unsigned bytes and shorts (glTF 2.0); with KHR_mesh_quantization
/// also signed ones, and plain integers of all four.
pub(super) const TEXCOORDS: Components = Components {
    name: "texcoords",
    normalized: ALL_INTS,
    plain: ALL_INTS,
};

/// COLOR_n: normalized unsigned bytes and shorts (glTF 2.0).
pub(super) const COLORS: Components = Components {
    name: "colors",
    normalized: &[DataType::U8, DataType::U16],
    plain: &[],
};

/// An accessor's elements of `N` components as f32, integers converted as `normalized`
/// says (the caller checked the type, so the gltf crate's reader sees the size it expects).
fn convert<'a, 's, const N: usize>(
    acc: &::gltf::Accessor<'a>,
    data: impl Clone + Fn(::gltf::Buffer<'a>) -> Option<&'s [u8]>,
    normalized: bool,
) -> Option<Vec<[f32; N]>>
where
    [f32; N]: Item,
    [i8; N]: Item,
    [u8; N]: Item,
    [i16; N]: Item,
    [u16; N]: Item,
{
    fn read<'a, 's, T: Copy, const N: usize>(
        acc: &::gltf::Accessor<'a>,
        data: impl Clone + Fn(::gltf::Buffer<'a>) -> Option<&'s [u8]>,
        f: impl Fn(T) -> f32,
    ) -> Option<Vec<[f32; N]>>
    where
        [T; N]: Item,
    {
        Iter::<[T; N]>::new(acc.clone(), data).map(|i| i.map(|e| e.map(&f)).collect())
    }
    match (acc.data_type(), normalized) {
        (DataType::I8, true) => read(acc, data, |c: i8| (c as f32 / 127.0).max(-1.0)),
        (DataType::U8, true) => read(acc, data, |c: u8| c as f32 / 255.0),
        (DataType::I16, true) => read(acc, data, |c: i16| (c as f32 / 32767.0).max(-1.0)),
        (DataType::U16, true) => read(acc, data, |c: u16| c as f32 / 65535.0),
        (DataType::I8, false) => read(acc, data, |c: i8| c as f32),
        (DataType::U8, false) => read(acc, data, |c: u8| c as f32),
        (DataType::I16, false) => read(acc, data, |c: i16| c as f32),
        (DataType::U16, false) => read(acc, data, |c: u16| c as f32),
        _ => read(acc, data, |c: f32| c),
    }
}

impl Reader {
    /// Where a `file:` or relative URI points (as the gltf crate resolves it).
    pub(super) fn resolve_uri(&self, uri: &str) -> Result<PathBuf, String> {
        if let Some(rest) = uri
            .strip_prefix("file://")
            .or_else(|| uri.strip_prefix("file:"))
        {
            Ok(PathBuf::from(rest))
        } else if uri.contains(':') {
            Err(format!(
                "URI '{}' has an unsupported scheme (data:, file: and relative paths are read)",
                quote(uri)
            ))
        } else {
            percent_decode(uri)
                .map(|p| self.dir.join(p))
                .ok_or_else(|| format!("URI '{}' is not valid percent-encoded UTF-8", quote(uri)))
        }
    }

    /// Reads every buffer: the GLB's BIN chunk, `data:` URIs (by the gltf crate) and files
    /// (here, so that an error names the file).
    pub(super) fn load_buffers(
        &mut self,
        doc: &::gltf::Document,
        mut blob: Option<Vec<u8>>,
    ) -> Result<(), SceneError> {
        use ::gltf::buffer::Source;
        for buffer in doc.buffers() {
            let i = buffer.index();
            let data = match buffer.source() {
                Source::Bin => blob.take().ok_or_else(|| {
                    parse(
                        &self.file,
                        format!("buffer {i} has no uri, so it is the GLB's BIN chunk, but the file has none"),
                    )
                })?,
                Source::Uri(uri) if uri.starts_with("data:") => {
                    ::gltf::buffer::Data::from_source(buffer.source(), None)
                        .map_err(|e| {
                            parse(
                                &self.file,
                                format!(
                                    "buffer {i}: cannot decode its data: URI: {}",
                                    quote_message(&e.to_string())
                                ),
                            )
                        })?
                        .0
                }
                Source::Uri(uri) => {
                    let p = self
                        .resolve_uri(uri)
                        .map_err(|m| parse(&self.file, format!("buffer {i}: {m}")))?;
                    let data = read_regular_file(&p).map_err(|source| SceneError::Read {
                        what: "glTF buffer",
                        path: p.clone(),
                        context: Some(format!("buffer {i} of {}", self.file)),
                        error: source,
                    })?;
                    self.out.files.push(p);
                    data
                }
            };
            if data.len() < buffer.length() {
                return Err(parse(
                    &self.file,
                    format!(
                        "buffer {i}: byteLength is {} but its data has only {} bytes",
                        buffer.length(),
                        data.len()
                    ),
                ));
            }
            self.buffers.push(::gltf::buffer::Data(data));
        }
        Ok(())
    }

    /// Checks that `view` lies in its buffer's data.
    pub(super) fn check_view(
        &self,
        view: &::gltf::buffer::View,
        label: &str,
    ) -> Result<(), SceneError> {
        let b = view.buffer().index();
        let buf_len = self.buffers.get(b).map_or(0, |d| d.0.len());
        let view_end = view.offset().checked_add(view.length());
        if view_end.is_none_or(|e| e > buf_len) {
            return Err(parse(
                &self.file,
                format!(
                    "{label}: buffer view {} (bytes {} + {}) lies outside buffer {b} ({buf_len} bytes)",
                    view.index(),
                    view.offset(),
                    view.length()
                ),
            ));
        }
        Ok(())
    }

    /// Checks that `count` elements of `size` bytes from `offset` in `view` (with its
    /// stride) lie in the view, and the view in its buffer's data: the gltf crate's
    /// readers slice and assert on these.
    pub(super) fn check_range(
        &self,
        view: &::gltf::buffer::View,
        offset: usize,
        count: usize,
        size: usize,
        label: &str,
    ) -> Result<(), SceneError> {
        self.check_view(view, label)?;
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(parse(
                &self.file,
                format!(
                    "{label}: buffer view {} has byteStride {stride}, smaller than one element ({size} bytes)",
                    view.index()
                ),
            ));
        }
        let end = count
            .checked_sub(1)
            .and_then(|c| c.checked_mul(stride))
            .and_then(|x| x.checked_add(size))
            .and_then(|x| x.checked_add(offset));
        if end.is_none_or(|e| e > view.length()) {
            return Err(parse(
                &self.file,
                format!(
                    "{label}: {count} elements of {size} bytes (stride {stride}) from byte {offset} do not fit in buffer view {} ({} bytes)",
                    view.index(),
                    view.length()
                ),
            ));
        }
        Ok(())
    }

    /// Checks what the gltf crate's reader of `acc` assumes: its type (one of `dims` of one
    /// of `types`: the reader asserts the element size), a count of at least 1 (it computes
    /// `count - 1`), its byte ranges, and those of its sparse part.
    pub(super) fn check_accessor(
        &self,
        acc: &::gltf::Accessor,
        what: &str,
        types: &[DataType],
        dims: &[Dimensions],
    ) -> Result<(), SceneError> {
        let label = format!("{what} (accessor {})", acc.index());
        if !types.contains(&acc.data_type()) || !dims.contains(&acc.dimensions()) {
            let list = |v: Vec<String>| v.join(" or ");
            return Err(parse(
                &self.file,
                format!(
                    "{label} is {:?} of {:?}; expected {} of {}",
                    acc.dimensions(),
                    acc.data_type(),
                    list(dims.iter().map(|d| format!("{d:?}")).collect()),
                    list(types.iter().map(|t| format!("{t:?}")).collect()),
                ),
            ));
        }
        let count = acc.count();
        if count == 0 {
            return Err(parse(&self.file, format!("{label} has count 0")));
        }
        let size = acc.size();
        match acc.view() {
            Some(view) => self.check_range(&view, acc.offset(), count, size, &label)?,
            None if count > MAX_VIEWLESS_ELEMENTS.saturating_sub(self.shared.viewless) => {
                let before = match self.shared.viewless {
                    0 => String::new(),
                    n => format!(", {n} of them taken by the accessors read before"),
                };
                return Err(parse(
                    &self.file,
                    format!(
                        "{label} has no bufferView and a count of {count}: such accessors (zeros, or sparse values over zeros) cost memory that no bytes of the file pay for, and a file may have at most {MAX_VIEWLESS_ELEMENTS} of their elements in all{before}"
                    ),
                ));
            }
            None => {}
        }
        if let Some(sparse) = acc.sparse() {
            let n = sparse.count();
            if n == 0 || n > count {
                return Err(parse(
                    &self.file,
                    format!(
                        "{label}: sparse count {n} must be from 1 to the accessor's count {count}"
                    ),
                ));
            }
            let indices = sparse.indices();
            self.check_range(
                &indices.view(),
                indices.offset(),
                n,
                indices.index_type().size(),
                &format!("{label} sparse indices"),
            )?;
            self.check_sparse_indices(&sparse, count, &label)?;
            let values = sparse.values();
            self.check_range(
                &values.view(),
                values.offset(),
                n,
                size,
                &format!("{label} sparse values"),
            )?;
        }
        Ok(())
    }

    /// Checks that the sparse indices of an accessor of `count` elements are strictly
    /// increasing and below `count`, as the glTF spec requires. The gltf crate's reader
    /// walks them in step with the elements and applies only those it meets in order: an
    /// index out of order or out of range silently left the rest of the values unapplied.
    /// The indices' byte range is checked (`check_range`) before.
    pub(super) fn check_sparse_indices(
        &self,
        sparse: &::gltf::accessor::sparse::Sparse,
        count: usize,
        label: &str,
    ) -> Result<(), SceneError> {
        let indices = sparse.indices();
        let view = indices.view();
        let size = indices.index_type().size();
        let stride = view.stride().unwrap_or(size);
        let data = self
            .buffers
            .get(view.buffer().index())
            .map_or(&[][..], |d| &d.0[..]);
        let start = view.offset().saturating_add(indices.offset());
        let mut previous: Option<u32> = None;
        for k in 0..sparse.count() {
            let at = start.saturating_add(k.saturating_mul(stride));
            let i = match data.get(at..at.saturating_add(size)) {
                Some(&[x]) => u32::from(x),
                Some(&[x, y]) => u32::from(u16::from_le_bytes([x, y])),
                Some(&[x, y, z, w]) => u32::from_le_bytes([x, y, z, w]),
                _ => {
                    return Err(parse(
                        &self.file,
                        format!("{label} sparse indices: element {k} lies outside its buffer"),
                    ))
                }
            };
            if i as usize >= count {
                return Err(parse(
                    &self.file,
                    format!(
                        "{label} sparse indices: element {k} is {i}, out of range: the accessor has {count} elements"
                    ),
                ));
            }
            if let Some(p) = previous.filter(|&p| i <= p) {
                return Err(parse(
                    &self.file,
                    format!(
                        "{label} sparse indices: element {k} is {i}, not greater than element {} ({p}): the glTF spec requires strictly increasing indices",
                        k - 1
                    ),
                ));
            }
            previous = Some(i);
        }
        Ok(())
    }

    /// The elements of an accessor of `N` components (one of `dims`) as f32, of a component
    /// type that `components` allows, integers converted to the values they stand for;
    /// `what` names it in messages ("mesh 0 primitive 1 POSITION").
    fn floats<const N: usize>(
        &mut self,
        acc: &::gltf::Accessor,
        what: &str,
        components: Components,
        dims: &[Dimensions],
    ) -> Result<Vec<[f32; N]>, SceneError>
    where
        [f32; N]: Item,
        [i8; N]: Item,
        [u8; N]: Item,
        [i16; N]: Item,
        [u16; N]: Item,
    {
        let mut types = vec![DataType::F32];
        for t in components.normalized.iter().chain(components.plain) {
            if !types.contains(t) {
                types.push(*t);
            }
        }
        self.check_accessor(acc, what, &types, dims)?;
        let ty = acc.data_type();
        // FLOAT ignores `normalized` (which the spec does not allow on it).
        let normalized = ty != DataType::F32 && acc.normalized();
        let allowed = match normalized {
            _ if ty == DataType::F32 => true,
            true => components.normalized.contains(&ty),
            false => components.plain.contains(&ty),
        };
        if !allowed {
            let how = if normalized {
                "may not be normalized"
            } else {
                "must be normalized"
            };
            return Err(parse(
                &self.file,
                format!(
                    "{what} (accessor {}): {ty:?} components {how} here (glTF 2.0 and KHR_mesh_quantization)",
                    acc.index()
                ),
            ));
        }
        let buffers = &self.buffers;
        let data = |b: ::gltf::Buffer| buffers.get(b.index()).map(|d| d.0.as_slice());
        let values =
            convert::<N>(acc, data, normalized).ok_or_else(|| self.unreadable(acc, what))?;
        self.read_once(acc);
        Ok(values)
    }

    /// The elements of a VEC3 accessor (POSITION, NORMAL, instance TRANSLATION and SCALE)
    /// of the types `components` allows, checked and read on first use; `what` names it in
    /// messages ("mesh 0 primitive 1 POSITION").
    pub(super) fn vec3s(
        &mut self,
        acc: &::gltf::Accessor,
        what: &str,
        components: Components,
    ) -> Result<Rc<[Vec3]>, SceneError> {
        let key = (acc.index(), components.name);
        if let Some(v) = self.shared.vec3s.get(&key) {
            return Ok(v.clone());
        }
        let values: Rc<[Vec3]> = self
            .floats::<3>(acc, what, components, &[Dimensions::Vec3])?
            .into_iter()
            .map(Vec3::from)
            .collect();
        self.shared.vec3s.insert(key, values.clone());
        Ok(values)
    }

    /// The elements of a VEC2 accessor (TEXCOORD_n), as [`Self::vec3s`].
    pub(super) fn vec2s(
        &mut self,
        acc: &::gltf::Accessor,
        what: &str,
        components: Components,
    ) -> Result<Rc<[Vec2]>, SceneError> {
        let key = (acc.index(), components.name);
        if let Some(v) = self.shared.vec2s.get(&key) {
            return Ok(v.clone());
        }
        let values: Rc<[Vec2]> = self
            .floats::<2>(acc, what, components, &[Dimensions::Vec2])?
            .into_iter()
            .map(Vec2::from)
            .collect();
        self.shared.vec2s.insert(key, values.clone());
        Ok(values)
    }

    /// The elements of a VEC3 or VEC4 accessor (COLOR_n) as RGBA (alpha 1 for VEC3), as
    /// [`Self::vec3s`].
    pub(super) fn colors(
        &mut self,
        acc: &::gltf::Accessor,
        what: &str,
        components: Components,
    ) -> Result<Rc<[Vec4]>, SceneError> {
        let key = (acc.index(), components.name);
        if let Some(v) = self.shared.vec4s.get(&key) {
            return Ok(v.clone());
        }
        let dims = [Dimensions::Vec3, Dimensions::Vec4];
        let values: Rc<[Vec4]> = if acc.dimensions() == Dimensions::Vec3 {
            self.floats::<3>(acc, what, components, &dims)?
                .into_iter()
                .map(|c| Vec3::from(c).extend(1.0))
                .collect()
        } else {
            self.floats::<4>(acc, what, components, &dims)?
                .into_iter()
                .map(Vec4::from)
                .collect()
        };
        self.shared.vec4s.insert(key, values.clone());
        Ok(values)
    }

    /// The elements of a SCALAR accessor of unsigned integers (indices), as [`Self::vec3s`].
    pub(super) fn indices(
        &mut self,
        acc: &::gltf::Accessor,
        what: &str,
    ) -> Result<Rc<[u32]>, SceneError> {
        if let Some(v) = self.shared.indices.get(&acc.index()) {
            return Ok(v.clone());
        }
        let types = [DataType::U8, DataType::U16, DataType::U32];
        self.check_accessor(acc, what, &types, &[Dimensions::Scalar])?;
        let buffers = &self.buffers;
        let data = |b: ::gltf::Buffer| buffers.get(b.index()).map(|d| d.0.as_slice());
        let values: Option<Rc<[u32]>> = match acc.data_type() {
            DataType::U8 => Iter::<u8>::new(acc.clone(), data).map(|i| i.map(u32::from).collect()),
            DataType::U16 => {
                Iter::<u16>::new(acc.clone(), data).map(|i| i.map(u32::from).collect())
            }
            _ => Iter::<u32>::new(acc.clone(), data).map(|i| i.collect()),
        };
        let values = values.ok_or_else(|| self.unreadable(acc, what))?;
        self.read_once(acc);
        self.shared.indices.insert(acc.index(), values.clone());
        Ok(values)
    }

    /// Counts a read accessor, and the elements of one without a buffer view.
    fn read_once(&mut self, acc: &::gltf::Accessor) {
        self.stats.accessors_read += 1;
        if acc.view().is_none() {
            self.shared.viewless += acc.count();
        }
    }

    /// The gltf crate found no data for an accessor that [`Self::check_accessor`] passed.
    fn unreadable(&self, acc: &::gltf::Accessor, what: &str) -> SceneError {
        parse(
            &self.file,
            format!(
                "{what} (accessor {}): internal error: cannot read the accessor",
                acc.index()
            ),
        )
    }
}
