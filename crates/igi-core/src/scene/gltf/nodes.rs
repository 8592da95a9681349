//! The scene's node trees under their world matrices: the KHR_lights_punctual point
//! lights at their nodes and each mesh primitive's triangles. The tree is walked first
//! and the triangles it would make are counted (against the scene's limit) before any
//! is made; each primitive's data is read once, then placed at every node that uses it.

use std::rc::Rc;

use ::gltf::khr_lights_punctual::Kind as LightKind;
use ::gltf::mesh::Mode;
use ::gltf::scene::Transform;
use ::gltf::Semantic;
use glam::{DQuat, Mat3, Mat4, Quat, Vec2, Vec3, Vec4};

use super::accessors::{Reader, COLORS, NORMALS, POSITIONS, TEXCOORDS};
use super::messages::{fmt3, invalid, mesh_label, parse};
use super::{LUMENS_PER_WATT, MAX_ROTATION_LENGTH_ERROR};
use crate::scene::loader::SceneError;
use crate::scene::{PointLight, TriAttributes, Triangle};

/// A primitive's data as every node that places it uses it: its vertices, its triangles
/// (vertex indices, checked to be in range, of vertices checked to be finite), its
/// material (an index in `out.materials`) and, where that material uses them, the
/// vertices' texture coordinates (the set its texture reads) and colours (COLOR_0), one
/// per vertex as the positions.
pub(super) struct Prepared {
    positions: Rc<[Vec3]>,
    normals: Option<Rc<[Vec3]>>,
    uvs: Option<Rc<[Vec2]>>,
    colors: Option<Rc<[Vec4]>>,
    corners: Vec<[u32; 3]>,
    material: usize,
}

impl Reader {
    /// Places the scene's node trees: lights at their nodes' world positions, and each
    /// mesh's triangles under its node's world matrix.
    pub(super) fn scene(
        &mut self,
        doc: &::gltf::Document,
        scene: &::gltf::Scene,
    ) -> Result<(), SceneError> {
        let placed = self.world_matrices(doc, scene)?;
        self.check_triangle_count(doc, &placed)?;
        for (node, world) in &placed {
            if let Some(mesh) = node.mesh() {
                if node.skin().is_some() || mesh.primitives().any(|p| p.morph_targets().len() > 0) {
                    self.warn.skinned_or_morphed += 1;
                }
                // EXT_mesh_gpu_instancing: the mesh once per instance, else once.
                let worlds = match self.instances(doc, node)? {
                    Some(instances) => instances.iter().map(|m| *world * *m).collect(),
                    None => vec![*world],
                };
                for prim in mesh.primitives() {
                    if let Some(prepared) = self.prepare(&mesh, &prim)? {
                        for world in &worlds {
                            self.place(&prepared, world);
                        }
                    }
                }
            }
            if let Some(light) = node.light() {
                self.light(&light, node.index(), world)?;
            }
        }
        Ok(())
    }

    /// The nodes of the scene's trees that hold a mesh or a light, depth-first, each with
    /// its world matrix (the product of the local ones from its root down). Each node is
    /// visited once: a node reached twice (a cycle, or a node with two parents, which
    /// would place its subtree once per path, a count that doubles with each level) is
    /// an error.
    fn world_matrices<'a>(
        &self,
        doc: &'a ::gltf::Document,
        scene: &::gltf::Scene<'a>,
    ) -> Result<Vec<(::gltf::Node<'a>, Mat4)>, SceneError> {
        // An explicit stack (no recursion, so a deep file cannot overflow ours) and a
        // visited mark (the crate does not reject cycles, which would never end).
        let mut seen = vec![false; doc.nodes().len()];
        let mut stack: Vec<(::gltf::Node, Mat4)> = scene
            .nodes()
            .map(|n| (n, Mat4::IDENTITY))
            .collect::<Vec<_>>();
        stack.reverse();
        let mut placed = Vec::new();
        while let Some((node, parent)) = stack.pop() {
            let i = node.index();
            if std::mem::replace(&mut seen[i], true) {
                return Err(parse(
                    &self.file,
                    format!(
                        "node {i} is reached twice from scene {} (a cycle, or a node with two parents): the node hierarchy must be a tree",
                        scene.index()
                    ),
                ));
            }
            let world = parent * self.local_matrix(&node)?;
            if !world.is_finite() {
                return Err(invalid(
                    &self.file,
                    format!("node {i}: its transform (or a parent's) is not finite"),
                ));
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
            if node.mesh().is_some() || node.light().is_some() {
                placed.push((node, world));
            }
        }
        Ok(placed)
    }

    /// Refuses a tree whose meshes would make more triangles than the scene may still take,
    /// before any is made: the count comes from the accessors' declared counts (degenerate
    /// triangles, dropped later, count too: they cost the same work), summed without
    /// overflow. A file of a few kilobytes that places one mesh at many nodes could
    /// otherwise ask for billions of triangles.
    fn check_triangle_count(
        &self,
        doc: &::gltf::Document,
        placed: &[(::gltf::Node, Mat4)],
    ) -> Result<(), SceneError> {
        // Per mesh: its triangles, and how many nodes place it.
        let mut per_mesh: Vec<(usize, usize)> = vec![(0, 0); doc.meshes().len()];
        let mut total = 0usize;
        for node in placed.iter().map(|(node, _)| node) {
            let Some(mesh) = node.mesh() else {
                continue;
            };
            let Some(entry) = per_mesh.get_mut(mesh.index()) else {
                continue;
            };
            if entry.1 == 0 {
                entry.0 = mesh
                    .primitives()
                    .map(|p| primitive_triangles(&p))
                    .fold(0, usize::saturating_add);
            }
            // A node with EXT_mesh_gpu_instancing places it once per instance.
            let copies = super::instancing::copies(&self.file, doc, node)?;
            entry.1 = entry.1.saturating_add(copies);
            total = total.saturating_add(entry.0.saturating_mul(copies));
        }
        self.budget.check(total, &self.file, || {
            let most = per_mesh
                .iter()
                .enumerate()
                .max_by_key(|(_, (t, n))| t.saturating_mul(*n));
            let detail = match most.and_then(|(m, &(t, n))| Some((doc.meshes().nth(m)?, t, n))) {
                Some((mesh, t, n)) if n > 1 => format!(
                    " ({} placed {n} times by nodes and instances, {t} triangles each)",
                    mesh_label(&mesh)
                ),
                _ => String::new(),
            };
            format!("its node tree would make {total} triangles{detail}")
        })
    }

    /// The node's local matrix: its `matrix`, or translation * rotation * scale. A rotation
    /// whose length is further from 1 than [`MAX_ROTATION_LENGTH_ERROR`] is an error (it
    /// would shear and scale what the node holds); one within it is normalised, so that
    /// exporters' rounding makes an exact rotation. A rotation that is not finite is left
    /// for the caller's check of the world matrix, which names it.
    pub(super) fn local_matrix(&self, node: &::gltf::Node) -> Result<Mat4, SceneError> {
        match node.transform() {
            Transform::Matrix { matrix } => Ok(Mat4::from_cols_array_2d(&matrix)),
            Transform::Decomposed {
                translation,
                rotation,
                scale,
            } => {
                let q = unit_rotation(rotation).map_err(|length| {
                    invalid(
                        &self.file,
                        format!(
                            "node {}: rotation {rotation:?} has length {length:.6}, not 1: glTF node rotations are unit quaternions (a length within {MAX_ROTATION_LENGTH_ERROR} of 1 is normalised)",
                            node.index(),
                        ),
                    )
                })?;
                Ok(Mat4::from_scale_rotation_translation(
                    Vec3::from(scale),
                    q,
                    Vec3::from(translation),
                ))
            }
        }
    }

    /// A KHR_lights_punctual light at node `node`.
    pub(super) fn light(
        &mut self,
        light: &::gltf::khr_lights_punctual::Light,
        node: usize,
        world: &Mat4,
    ) -> Result<(), SceneError> {
        if !matches!(light.kind(), LightKind::Point) {
            self.warn.lights_skipped += 1;
            return Ok(());
        }
        let color = light.color();
        let intensity = light.intensity();
        let valid = intensity.is_finite()
            && intensity >= 0.0
            && color.iter().all(|c| c.is_finite() && *c >= 0.0);
        if !valid {
            return Err(invalid(
                &self.file,
                format!(
                    "light {} (node {node}): color {} and intensity {intensity} must be finite numbers >= 0",
                    light.index(),
                    fmt3(color)
                ),
            ));
        }
        // Candela is lm/sr; at 683 lm/W it is 1/683 W/sr. The range cut-off is ignored:
        // the renderer's point lights fall off with the inverse square only.
        self.out.lights.push(PointLight {
            position: world.w_axis.truncate(),
            intensity: Vec3::from(color) * (intensity / LUMENS_PER_WATT),
        });
        Ok(())
    }

    /// The data of one primitive of `mesh`, read and checked on its first use; `None` for
    /// a primitive that makes no triangles (POINTS, LINES*: skipped with a warning).
    pub(super) fn prepare(
        &mut self,
        mesh: &::gltf::Mesh,
        prim: &::gltf::Primitive,
    ) -> Result<Option<Rc<Prepared>>, SceneError> {
        let key = (mesh.index(), prim.index());
        if let Some(p) = self.shared.primitives.get(&key) {
            return Ok(p.clone());
        }
        let what = format!("{} primitive {}", mesh_label(mesh), prim.index());
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.warn.not_triangles += 1;
            self.shared.primitives.insert(key, None);
            return Ok(None);
        }
        let Some(pos_acc) = prim.get(&Semantic::Positions) else {
            return Err(parse(&self.file, format!("{what} has no POSITION")));
        };
        let file = self.file.clone();
        let count = |acc: &::gltf::Accessor, name: &str| {
            if acc.count() == pos_acc.count() {
                Ok(())
            } else {
                Err(parse(
                    &file,
                    format!(
                        "{what}: {name} has {} elements but POSITION has {}",
                        acc.count(),
                        pos_acc.count()
                    ),
                ))
            }
        };
        let nrm_acc = prim.get(&Semantic::Normals);
        if let Some(acc) = &nrm_acc {
            count(acc, "NORMAL")?;
        }
        let positions = self.vec3s(&pos_acc, &format!("{what} POSITION"), POSITIONS)?;
        let normals = match &nrm_acc {
            Some(acc) => Some(self.vec3s(acc, &format!("{what} NORMAL"), NORMALS)?),
            None => None,
        };
        let material = self.material(prim.material())?;
        // The coordinates the material's texture reads; without them, 0 (said once).
        let uvs = match self.uv_sets[material] {
            Some(set) => match prim.get(&Semantic::TexCoords(set)) {
                Some(acc) => {
                    let name = format!("TEXCOORD_{set}");
                    count(&acc, &name)?;
                    let uvs = self.vec2s(&acc, &format!("{what} {name}"), TEXCOORDS)?;
                    if uvs.iter().any(|uv| !uv.is_finite()) {
                        self.warn.bad_texcoords += 1;
                        Some(
                            uvs.iter()
                                .map(|&uv| if uv.is_finite() { uv } else { Vec2::ZERO })
                                .collect(),
                        )
                    } else {
                        Some(uvs)
                    }
                }
                None => {
                    self.warn.no_texcoords += 1;
                    None
                }
            },
            None => None,
        };
        let colors = match prim.get(&Semantic::Colors(0)) {
            Some(acc) => {
                count(&acc, "COLOR_0")?;
                let colors = self.colors(&acc, &format!("{what} COLOR_0"), COLORS)?;
                self.out.materials[material].vertex_colors = true;
                // Float colours may hold anything: keep them reflectances and opacities.
                let unit = |c: &Vec4| {
                    c.is_finite() && c.cmpge(Vec4::ZERO).all() && c.cmple(Vec4::ONE).all()
                };
                if colors.iter().all(unit) {
                    Some(colors)
                } else {
                    self.warn.bad_colors += 1;
                    let fix = |c: Vec4| {
                        if c.is_finite() {
                            c.clamp(Vec4::ZERO, Vec4::ONE)
                        } else {
                            Vec4::ONE
                        }
                    };
                    Some(colors.iter().map(|&c| fix(c)).collect())
                }
            }
            None => None,
        };
        let nv = positions.len();
        let corners = match prim.indices() {
            Some(acc) => {
                let indices = self.indices(&acc, &format!("{what} indices"))?;
                if let Some((k, &i)) = indices.iter().enumerate().find(|(_, &i)| i as usize >= nv) {
                    return Err(parse(
                        &self.file,
                        format!("{what}: index {i} (element {k} of the indices) out of range: POSITION has {nv} vertices"),
                    ));
                }
                if mode == Mode::Triangles && !indices.len().is_multiple_of(3) {
                    self.warn.leftover_indices += 1;
                }
                triangulate(mode, &indices)
            }
            None => {
                // Vertex counts fit in u32: the scene's triangle limit was checked first.
                let in_order: Vec<u32> = (0..nv as u32).collect();
                if mode == Mode::Triangles && !nv.is_multiple_of(3) {
                    self.warn.leftover_indices += 1;
                }
                triangulate(mode, &in_order)
            }
        };
        for t in &corners {
            if let Some(&i) = t.iter().find(|&&i| !positions[i as usize].is_finite()) {
                return Err(invalid(
                    &self.file,
                    format!(
                        "{what}: a triangle uses vertex {i} whose position {} is not finite",
                        fmt3(positions[i as usize].into())
                    ),
                ));
            }
        }
        let prepared = Rc::new(Prepared {
            positions,
            normals,
            uvs,
            colors,
            corners,
            material,
        });
        self.shared.primitives.insert(key, Some(prepared.clone()));
        Ok(Some(prepared))
    }

    /// Appends the triangles of a primitive under the world matrix `world`.
    pub(super) fn place(&mut self, p: &Prepared, world: &Mat4) {
        // Normals go through the cofactor matrix, det * M^-T: defined even when M is
        // singular, and with the sign of det undone it is the inverse transpose's direction.
        let m3 = Mat3::from_mat4(*world);
        let det = m3.determinant();
        let mirrored = det < 0.0;
        let (c0, c1, c2) = (m3.x_axis, m3.y_axis, m3.z_axis);
        let mut normal_matrix = Mat3::from_cols(c1.cross(c2), c2.cross(c0), c0.cross(c1));
        if mirrored {
            normal_matrix = -normal_matrix;
        }

        let mut count = 0usize;
        for &(mut t) in &p.corners {
            if mirrored {
                // The glTF spec: a negative determinant makes front faces clockwise; keep
                // the geometric normal on the side of the (inverse transposed) normals.
                t.swap(1, 2);
            }
            let v = t.map(|i| world.transform_point3(p.positions[i as usize]));
            // A world transform may make a vertex non-finite: then it is dropped too.
            let Some(ng) = crate::scene::geometric_normal(&v) else {
                self.warn.degenerate += 1;
                continue;
            };
            let mut n = [ng; 3];
            if let Some(normals) = &p.normals {
                for (k, nk) in n.iter_mut().enumerate() {
                    match (normal_matrix * normals[t[k] as usize]).try_normalize() {
                        Some(x) => *nk = x,
                        None => self.warn.bad_normals += 1,
                    }
                }
            }
            if p.uvs.is_some() || p.colors.is_some() {
                // By the corners `t`, so that a mirrored triangle's attributes swap with
                // its vertices. Attributes are one per triangle once any triangle has some.
                let out = &mut self.out;
                out.attributes
                    .resize(out.triangles.len(), TriAttributes::NONE);
                out.attributes.push(TriAttributes {
                    uv: p
                        .uvs
                        .as_ref()
                        .map_or([Vec2::ZERO; 3], |uv| t.map(|i| uv[i as usize])),
                    color: p
                        .colors
                        .as_ref()
                        .map_or([Vec4::ONE; 3], |c| t.map(|i| c[i as usize])),
                });
            }
            self.out.triangles.push(Triangle {
                v,
                n,
                material: p.material as u32,
            });
            count += 1;
        }
        self.out.materials[p.material].triangles += count;
    }
}

/// The triangles a primitive makes, from its accessors' declared counts (nothing is
/// read): what [`triangulate`] would give.
/// A glTF rotation (x, y, z, w) as a unit quaternion: normalised where its length is
/// within [`MAX_ROTATION_LENGTH_ERROR`] of 1 (exporters' rounding), else `Err(length)`
/// (it would shear and scale what it rotates). A rotation that is not finite is returned
/// as it is, for the callers' checks of their matrices, which name it.
pub(super) fn unit_rotation(q: [f32; 4]) -> Result<Quat, f64> {
    let quat = Quat::from_array(q);
    // In f64: the length of any finite f32 quaternion, without overflow.
    let length = DQuat::from_array(q.map(f64::from)).length();
    if !quat.is_finite() {
        Ok(quat)
    } else if (length - 1.0).abs() <= f64::from(MAX_ROTATION_LENGTH_ERROR) {
        Ok(quat.normalize())
    } else {
        Err(length)
    }
}

fn primitive_triangles(prim: &::gltf::Primitive) -> usize {
    let n = match prim.indices() {
        Some(acc) => acc.count(),
        None => prim.get(&Semantic::Positions).map_or(0, |acc| acc.count()),
    };
    match prim.mode() {
        Mode::Triangles => n / 3,
        Mode::TriangleStrip | Mode::TriangleFan => n.saturating_sub(2),
        _ => 0,
    }
}

/// The triangles of a primitive's vertex list, per the glTF spec: TRIANGLES in threes
/// (a remainder ignored), TRIANGLE_STRIP `{i, i + 1 + i % 2, i + 2 - i % 2}` (every
/// triangle counter-clockwise), TRIANGLE_FAN `{i + 1, i + 2, 0}`.
pub(super) fn triangulate(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    let n = idx.len();
    match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| [idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]])
            .collect(),
        Mode::TriangleFan => (0..n.saturating_sub(2))
            .map(|i| [idx[i + 1], idx[i + 2], idx[0]])
            .collect(),
        _ => Vec::new(),
    }
}
