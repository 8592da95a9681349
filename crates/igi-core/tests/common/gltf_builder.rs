//! A small builder of glTF files for the tests (`scene_gltf.rs`, `scene_hostile.rs`): the
//! JSON assembled from arrays, with the binary data as a base64 `data:` URI, an external
//! `.bin` file, or a GLB's BIN chunk.
#![allow(dead_code)] // each test file uses a part of it

/// Standard base64 (with padding), for `data:` URIs.
pub fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in data.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Where [`Gltf`] puts its binary data.
pub enum Bin<'a> {
    /// A base64 `data:` URI in the JSON.
    DataUri,
    /// An external file (the test writes it, or not).
    File(&'a str),
    /// The BIN chunk of a GLB (no uri).
    Glb,
}

/// A glTF document assembled from arrays: one buffer, a view and an accessor per array;
/// meshes, nodes, materials, lights and images given as JSON text.
#[derive(Default)]
pub struct Gltf {
    pub bin: Vec<u8>,
    pub views: Vec<String>,
    pub accessors: Vec<String>,
    pub meshes: Vec<String>,
    pub nodes: Vec<String>,
    pub materials: Vec<String>,
    pub lights: Vec<String>,
    pub images: Vec<String>,
    /// Texture objects; when empty, one `{"source": i}` per image.
    pub textures: Vec<String>,
    pub samplers: Vec<String>,
    /// Extension names for `extensionsUsed` (KHR_lights_punctual is added with lights)
    /// and `extensionsRequired`.
    pub extensions_used: Vec<String>,
    pub extensions_required: Vec<String>,
    /// The scene's root nodes; `[0]` when empty.
    pub roots: Vec<usize>,
}

impl Gltf {
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    pub fn accessor(&mut self, json: String) -> usize {
        self.accessors.push(json);
        self.accessors.len() - 1
    }

    /// An accessor of `count` elements of `ty` ("VEC2"...) and `component` (5120 BYTE ...
    /// 5126 FLOAT) over `bytes` in a view of its own; `more` adds fields
    /// (`, "normalized": true`).
    pub fn typed(
        &mut self,
        bytes: &[u8],
        component: u32,
        ty: &str,
        count: usize,
        more: &str,
    ) -> usize {
        let view = self.view(bytes);
        self.accessor(format!(
            r#"{{"bufferView": {view}, "componentType": {component}, "count": {count}, "type": "{ty}"{more}}}"#
        ))
    }

    /// A VEC2 FLOAT accessor (texture coordinates).
    pub fn vec2(&mut self, data: &[[f32; 2]]) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        self.typed(&bytes, 5126, "VEC2", data.len(), "")
    }

    /// A VEC4 FLOAT accessor (colours).
    pub fn vec4(&mut self, data: &[[f32; 4]]) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        self.typed(&bytes, 5126, "VEC4", data.len(), "")
    }

    /// A VEC3 FLOAT accessor; with `min`/`max` (of the finite values) when `bounds`, as
    /// POSITION needs.
    pub fn vec3(&mut self, data: &[[f32; 3]], bounds: bool) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let view = self.view(&bytes);
        let mut extra = String::new();
        if bounds {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in data {
                for k in 0..3 {
                    if p[k].is_finite() {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
            }
            extra = format!(
                r#", "min": [{}, {}, {}], "max": [{}, {}, {}]"#,
                lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
            );
        }
        self.accessor(format!(
            r#"{{"bufferView": {view}, "componentType": 5126, "count": {}, "type": "VEC3"{extra}}}"#,
            data.len()
        ))
    }

    pub fn positions(&mut self, data: &[[f32; 3]]) -> usize {
        self.vec3(data, true)
    }

    pub fn normals(&mut self, data: &[[f32; 3]]) -> usize {
        self.vec3(data, false)
    }

    /// A SCALAR UNSIGNED_SHORT accessor.
    pub fn indices(&mut self, data: &[u16]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessor(format!(
            r#"{{"bufferView": {view}, "componentType": 5123, "count": {}, "type": "SCALAR"}}"#,
            data.len()
        ))
    }

    /// A mesh of the given primitives (JSON objects).
    pub fn mesh(&mut self, primitives: &[String]) -> usize {
        self.meshes
            .push(format!(r#"{{"primitives": [{}]}}"#, primitives.join(", ")));
        self.meshes.len() - 1
    }

    /// A node: `json` is the inside of its object (`"mesh": 0, "translation": [...]`).
    pub fn node(&mut self, json: &str) -> usize {
        self.nodes.push(format!("{{{json}}}"));
        self.nodes.len() - 1
    }

    pub fn material(&mut self, json: &str) -> usize {
        self.materials.push(json.to_string());
        self.materials.len() - 1
    }

    pub fn light(&mut self, json: &str) -> usize {
        self.lights.push(json.to_string());
        self.lights.len() - 1
    }

    /// The JSON document, its buffer as `bin` says.
    pub fn json(&self, bin: Bin) -> String {
        let buffer = match bin {
            Bin::DataUri => format!(
                r#"{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}"#,
                self.bin.len(),
                base64(&self.bin)
            ),
            Bin::File(name) => format!(r#"{{"byteLength": {}, "uri": "{name}"}}"#, self.bin.len()),
            Bin::Glb => format!(r#"{{"byteLength": {}}}"#, self.bin.len()),
        };
        let roots: Vec<String> = if self.roots.is_empty() {
            vec!["0".into()]
        } else {
            self.roots.iter().map(|r| r.to_string()).collect()
        };
        let mut fields = vec![
            r#""asset": {"version": "2.0"}"#.to_string(),
            r#""scene": 0"#.to_string(),
            format!(r#""scenes": [{{"nodes": [{}]}}]"#, roots.join(", ")),
            format!(r#""nodes": [{}]"#, self.nodes.join(", ")),
            format!(r#""meshes": [{}]"#, self.meshes.join(", ")),
            format!(r#""accessors": [{}]"#, self.accessors.join(", ")),
            format!(r#""bufferViews": [{}]"#, self.views.join(", ")),
            format!(r#""buffers": [{buffer}]"#),
        ];
        if !self.materials.is_empty() {
            fields.push(format!(r#""materials": [{}]"#, self.materials.join(", ")));
        }
        if !self.images.is_empty() {
            let textures: Vec<String> = if self.textures.is_empty() {
                (0..self.images.len())
                    .map(|i| format!(r#"{{"source": {i}}}"#))
                    .collect()
            } else {
                self.textures.clone()
            };
            fields.push(format!(r#""images": [{}]"#, self.images.join(", ")));
            fields.push(format!(r#""textures": [{}]"#, textures.join(", ")));
        }
        if !self.samplers.is_empty() {
            fields.push(format!(r#""samplers": [{}]"#, self.samplers.join(", ")));
        }
        let mut used: Vec<String> = self.extensions_used.clone();
        if !self.lights.is_empty() {
            used.push("KHR_lights_punctual".to_string());
        }
        let quoted = |v: &[String]| {
            v.iter()
                .map(|e| format!("\"{e}\""))
                .collect::<Vec<_>>()
                .join(", ")
        };
        if !used.is_empty() {
            fields.push(format!(r#""extensionsUsed": [{}]"#, quoted(&used)));
        }
        if !self.extensions_required.is_empty() {
            fields.push(format!(
                r#""extensionsRequired": [{}]"#,
                quoted(&self.extensions_required)
            ));
        }
        if !self.lights.is_empty() {
            fields.push(format!(
                r#""extensions": {{"KHR_lights_punctual": {{"lights": [{}]}}}}"#,
                self.lights.join(", ")
            ));
        }
        format!("{{\n  {}\n}}\n", fields.join(",\n  "))
    }

    /// A `.gltf` file with the buffer as a base64 `data:` URI.
    pub fn gltf(&self) -> Vec<u8> {
        self.json(Bin::DataUri).into_bytes()
    }

    /// A `.glb` file: the 12-byte header (magic, version 2, total length), the JSON chunk
    /// (padded with spaces) and the BIN chunk (padded with zeros), each chunk preceded by
    /// its length and type.
    pub fn glb(&self) -> Vec<u8> {
        let mut json = self.json(Bin::Glb).into_bytes();
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }
}

/// The unit quad in the z = 0 plane, counter-clockwise seen from +z.
pub const QUAD: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];
pub const QUAD_INDICES: [u16; 6] = [0, 1, 2, 0, 2, 3];

/// A primitive (JSON) of positions `pos`, indices `idx` and optional `more` fields.
pub fn primitive(pos: usize, idx: Option<usize>, more: &str) -> String {
    let idx = idx.map_or(String::new(), |i| format!(r#", "indices": {i}"#));
    format!(r#"{{"attributes": {{"POSITION": {pos}}}{idx}{more}}}"#)
}

/// A builder with the quad as mesh 0 (indexed, material `material` when given).
pub fn quad(material: Option<usize>) -> Gltf {
    let mut g = Gltf::default();
    let p = g.positions(&QUAD);
    let i = g.indices(&QUAD_INDICES);
    let more = material.map_or(String::new(), |m| format!(r#", "material": {m}"#));
    g.mesh(&[primitive(p, Some(i), &more)]);
    g
}

/// The quad's positions as a sparse accessor over zeros, vertices `indices` replaced by
/// `QUAD[1..]` (`indices` of u8, u16 or u32 as `component` 5121, 5123 or 5125 says).
pub fn sparse_quad(indices: &[u32], component: u32) -> Gltf {
    let mut g = Gltf::default();
    let idx: Vec<u8> = match component {
        5121 => indices.iter().map(|&x| x as u8).collect(),
        5123 => indices
            .iter()
            .flat_map(|&x| (x as u16).to_le_bytes())
            .collect(),
        _ => indices.iter().flat_map(|x| x.to_le_bytes()).collect(),
    };
    let vals: Vec<u8> = QUAD[1..]
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let (iv, vv) = (g.view(&idx), g.view(&vals));
    let p = g.accessor(format!(
        r#"{{"componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0], "sparse": {{"count": 3, "indices": {{"bufferView": {iv}, "componentType": {component}}}, "values": {{"bufferView": {vv}}}}}}}"#
    ));
    let i = g.indices(&QUAD_INDICES);
    g.mesh(&[primitive(p, Some(i), "")]);
    g.node(r#""mesh": 0"#);
    g
}
