//! The reader's state ([`Reader`]), its buffers (GLB chunk, `data:` URIs and files) and
//! the checks of buffer views and accessors that the gltf crate's readers assume.

use std::collections::HashMap;
use std::path::PathBuf;

use ::gltf::accessor::{DataType, Dimensions};
use glam::Vec3;

use super::document::{percent_decode, Warnings};
use super::messages::{parse, quote, quote_message};
use super::{GltfMesh, MAX_VIEWLESS_COUNT};
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
    /// Image index -> average linear colour (`None`: could not be decoded).
    pub(super) textures: HashMap<usize, Option<Vec3>>,
    /// Images whose `Image::source()` would panic in the gltf crate (found by fuzzing:
    /// neither `uri` nor `bufferView`, or a `bufferView` without `mimeType`), with why.
    pub(super) bad_images: HashMap<usize, &'static str>,
    pub(super) warn: Warnings,
    /// The triangles the scene may still take (the loader's limit, less earlier meshes').
    pub(super) budget: TriangleBudget,
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

    /// Checks what the gltf crate's reader of `acc` assumes: its type (the reader asserts
    /// the element size), a count of at least 1 (it computes `count - 1`), its byte
    /// ranges, and those of its sparse part.
    pub(super) fn check_accessor(
        &self,
        acc: &::gltf::Accessor,
        what: &str,
        types: &[DataType],
        dims: Dimensions,
    ) -> Result<(), SceneError> {
        let label = format!("{what} (accessor {})", acc.index());
        if !types.contains(&acc.data_type()) || acc.dimensions() != dims {
            let expected: Vec<String> = types.iter().map(|t| format!("{t:?}")).collect();
            return Err(parse(
                &self.file,
                format!(
                    "{label} is {:?} of {:?}; expected {dims:?} of {}",
                    acc.dimensions(),
                    acc.data_type(),
                    expected.join(" or ")
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
            None if count > MAX_VIEWLESS_COUNT => {
                return Err(parse(
                    &self.file,
                    format!("{label} has no bufferView and a count of {count} (at most {MAX_VIEWLESS_COUNT})"),
                ))
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
}
