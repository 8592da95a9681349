//! `EXT_mesh_gpu_instancing`: a node that holds a mesh may place it many times, once per
//! element of its TRANSLATION, ROTATION and SCALE accessors. The instances are made into
//! world-space triangles like any other placement of the mesh: each instance's matrix
//! T * R * S, under the node's world matrix.

use ::gltf::accessor::{DataType, Dimensions, Iter};
use glam::{Mat4, Quat, Vec3};

use super::accessors::{Reader, POSITIONS};
use super::messages::parse;
use super::nodes::unit_rotation;
use super::MAX_ROTATION_LENGTH_ERROR;
use crate::scene::loader::SceneError;

const EXTENSION: &str = "EXT_mesh_gpu_instancing";

/// The accessors of a node's instances (TRANSLATION, ROTATION, SCALE), each optional.
#[derive(Default)]
struct Attributes {
    translation: Option<usize>,
    rotation: Option<usize>,
    scale: Option<usize>,
}

/// The node's instancing attributes, or `None` where it has no such extension.
fn attributes(file: &str, node: &::gltf::Node) -> Result<Option<Attributes>, SceneError> {
    let Some(ext) = node.extensions().and_then(|e| e.get(EXTENSION)) else {
        return Ok(None);
    };
    let bad = |why: &str| parse(file, format!("node {}: {EXTENSION}: {why}", node.index()));
    let attrs = ext
        .get("attributes")
        .and_then(|a| a.as_object())
        .ok_or_else(|| bad("no attributes object"))?;
    let mut out = Attributes::default();
    for (name, value) in attrs {
        let index = value
            .as_u64()
            .map(|i| i as usize)
            .ok_or_else(|| bad(&format!("attribute {name} is not an accessor index")))?;
        match name.as_str() {
            "TRANSLATION" => out.translation = Some(index),
            "ROTATION" => out.rotation = Some(index),
            "SCALE" => out.scale = Some(index),
            // Application attributes (_ID, _COLOR...) change nothing igi draws.
            _ => {}
        }
    }
    Ok(Some(out))
}

/// How many times the node places its mesh: the instances' count, or 1. Read from the
/// accessors' declared counts, which must agree, before anything is read.
pub(super) fn copies(
    file: &str,
    doc: &::gltf::Document,
    node: &::gltf::Node,
) -> Result<usize, SceneError> {
    match attributes(file, node)? {
        Some(attrs) => count(file, doc, node, &attrs),
        None => Ok(1),
    }
}

/// The instances' count: that of the accessors, which must exist and agree (1 where the
/// extension names none).
fn count(
    file: &str,
    doc: &::gltf::Document,
    node: &::gltf::Node,
    attrs: &Attributes,
) -> Result<usize, SceneError> {
    let bad = |why: String| parse(file, format!("node {}: {EXTENSION}: {why}", node.index()));
    let mut count = None;
    for index in [attrs.translation, attrs.rotation, attrs.scale]
        .into_iter()
        .flatten()
    {
        let acc = doc.accessors().nth(index).ok_or_else(|| {
            bad(format!(
                "accessor {index} does not exist (the file has {})",
                doc.accessors().len()
            ))
        })?;
        match count {
            None => count = Some(acc.count()),
            Some(n) if n != acc.count() => {
                return Err(bad(format!(
                    "its accessors have different counts ({n} and {})",
                    acc.count()
                )))
            }
            _ => {}
        }
    }
    Ok(count.unwrap_or(1))
}

impl Reader {
    /// The node's instance matrices (T * R * S, in the node's space), or `None` where it
    /// has no instancing. [`copies`] was checked against the triangle budget first.
    pub(super) fn instances(
        &mut self,
        doc: &::gltf::Document,
        node: &::gltf::Node,
    ) -> Result<Option<Vec<Mat4>>, SceneError> {
        let Some(attrs) = attributes(&self.file, node)? else {
            return Ok(None);
        };
        let n = count(&self.file, doc, node, &attrs)?;
        let what = |attr: &str| format!("node {} {EXTENSION} {attr}", node.index());
        let accessor = |i: usize| doc.accessors().nth(i).expect("checked by count");
        let translations = match attrs.translation {
            Some(i) => Some(self.vec3s(&accessor(i), &what("TRANSLATION"), POSITIONS)?),
            None => None,
        };
        let scales = match attrs.scale {
            Some(i) => Some(self.vec3s(&accessor(i), &what("SCALE"), POSITIONS)?),
            None => None,
        };
        let rotations = match attrs.rotation {
            Some(i) => Some(self.rotations(&accessor(i), &what("ROTATION"))?),
            None => None,
        };
        let mut out = Vec::with_capacity(n);
        for k in 0..n {
            let t = translations.as_ref().map_or(Vec3::ZERO, |v| v[k]);
            let s = scales.as_ref().map_or(Vec3::ONE, |v| v[k]);
            let r = rotations.as_ref().map_or(Quat::IDENTITY, |v| v[k]);
            out.push(Mat4::from_scale_rotation_translation(s, r, t));
        }
        Ok(Some(out))
    }

    /// A ROTATION accessor: VEC4 of floats, or of normalized signed bytes or shorts (what
    /// the extension allows), each a unit quaternion within [`MAX_ROTATION_LENGTH_ERROR`]
    /// (normalised) or an error.
    fn rotations(&mut self, acc: &::gltf::Accessor, what: &str) -> Result<Vec<Quat>, SceneError> {
        let types = [DataType::F32, DataType::I8, DataType::I16];
        self.check_accessor(acc, what, &types, &[Dimensions::Vec4])?;
        if acc.data_type() != DataType::F32 && !acc.normalized() {
            return Err(parse(
                &self.file,
                format!(
                    "{what} (accessor {}): integer rotations must be normalized",
                    acc.index()
                ),
            ));
        }
        let buffers = &self.buffers;
        let data = |b: ::gltf::Buffer| buffers.get(b.index()).map(|d| d.0.as_slice());
        // Normalized signed integers: max(c / MAX, -1), as the glTF specification says.
        let values: Option<Vec<[f32; 4]>> = match acc.data_type() {
            DataType::F32 => Iter::<[f32; 4]>::new(acc.clone(), data).map(|i| i.collect()),
            DataType::I8 => Iter::<[i8; 4]>::new(acc.clone(), data)
                .map(|i| i.map(|q| q.map(|c| (c as f32 / 127.0).max(-1.0))).collect()),
            _ => Iter::<[i16; 4]>::new(acc.clone(), data).map(|i| {
                i.map(|q| q.map(|c| (c as f32 / 32767.0).max(-1.0)))
                    .collect()
            }),
        };
        let values = values.ok_or_else(|| {
            parse(
                &self.file,
                format!(
                    "{what} (accessor {}): internal error: cannot read the accessor",
                    acc.index()
                ),
            )
        })?;
        values
            .into_iter()
            .enumerate()
            .map(|(k, q)| {
                let bad = |why: String| {
                    parse(&self.file, format!("{what} (accessor {}) element {k}: rotation {q:?} {why}", acc.index()))
                };
                match unit_rotation(q) {
                    Ok(r) if r.is_finite() => Ok(r),
                    Ok(_) => Err(bad("is not finite".into())),
                    Err(length) => Err(bad(format!(
                        "has length {length:.6}, not 1 (a length within {MAX_ROTATION_LENGTH_ERROR} of 1 is normalised)"
                    ))),
                }
            })
            .collect()
    }
}
