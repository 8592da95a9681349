//! Every composed shader parses and validates with naga (a broken shader fails here, not
//! in front of a user), so does every shared module composed with only its own imports
//! (a module that relies on what its includer declares fails here), and every host/GPU
//! struct has the size and field offsets that the WGSL declares.

mod common;

use common::wgsl_constant;
use igi_gpu::layout::{
    BvhNode, DisplayParams, FrameParams, GpuLight, GpuMaterial, GpuTriAttributes, TriShading, Vpl,
};
use igi_gpu::shader::{compose_for, try_compose, ParamsBinding, MODULES, SOURCES};
use std::mem::{offset_of, size_of};

fn parse_and_validate(name: &str, src: &str) -> naga::Module {
    validate_with(name, src, false)
}

/// Parses and validates with naga's default capabilities, plus subgroup operations in
/// compute shaders where `subgroups` (only passes that declare them may use them).
fn validate_with(name: &str, src: &str, subgroups: bool) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}.wgsl does not parse:\n{}", e.emit_to_string(src)));
    let mut capabilities = naga::valid::Capabilities::default();
    if subgroups {
        capabilities |= naga::valid::Capabilities::SUBGROUP;
    }
    let mut validator =
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities);
    if subgroups {
        validator
            .subgroup_stages(naga::valid::ShaderStages::COMPUTE)
            .subgroup_operations(naga::valid::SubgroupOperationSet::all());
    }
    validator
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}.wgsl does not validate:\n{}", e.emit_to_string(src)));
    module
}

/// Every pass's shader, as GPUs get it (uniform parameter blocks) and as software
/// adapters do (read-only storage ones).
#[test]
fn every_pass_shader_validates() {
    let passes = SOURCES;
    assert!(passes.len() >= 4);
    for binding in ParamsBinding::ALL {
        for pass in passes {
            let name = format!("{} ({binding:?} params)", pass.name);
            validate_with(&name, &compose_for(pass, binding), pass.subgroups);
        }
    }
}

/// Each module with only what it imports, as GPUs and as software adapters get it: a
/// module that used an identifier it neither declares nor imports would not parse.
#[test]
fn every_module_validates_with_its_own_imports() {
    assert!(MODULES.len() >= 10);
    for binding in ParamsBinding::ALL {
        for (name, wgsl) in MODULES {
            let composed =
                try_compose(name, wgsl, binding).unwrap_or_else(|e| panic!("{name}.wgsl: {e}"));
            parse_and_validate(&format!("{name} ({binding:?} params)"), &composed);
        }
    }
}

/// Every module is registered once, and some pass imports it (directly or not).
#[test]
fn every_module_is_named_once_and_used() {
    for (i, (name, _)) in MODULES.iter().enumerate() {
        assert!(
            MODULES[..i].iter().all(|(n, _)| n != name),
            "{name} is registered twice"
        );
        let used = SOURCES.iter().any(|pass| {
            let mut pending: Vec<&str> = vec![pass.wgsl];
            let mut seen: Vec<&str> = Vec::new();
            while let Some(src) = pending.pop() {
                for import in igi_gpu::shader::resolve::imports("", src).unwrap() {
                    if import == *name {
                        return true;
                    }
                    if !seen.contains(&import) {
                        seen.push(import);
                        pending.extend(igi_gpu::shader::module(import));
                    }
                }
            }
            false
        });
        assert!(used, "no pass imports {name}.wgsl");
    }
}

/// What each `.w` of the G-buffer and of the mirror record means is written in
/// gbuffer.wgsl alone: no other frame shader reads a `.w` or writes a record with a `vec4`
/// of its own (the ray bench's ray records are not the G-buffer).
#[test]
fn only_gbuffer_wgsl_packs_and_unpacks_the_records() {
    let frame_shaders = SOURCES
        .iter()
        .filter(|pass| !pass.name.starts_with("rays"))
        .map(|pass| (pass.name, pass.wgsl))
        .chain(MODULES.iter().copied().filter(|(name, _)| *name != "rays"));
    let records = [
        "gbuf_position[",
        "gbuf_normal[",
        "gbuf_geometric[",
        "gbuf_albedo[",
        "mirror_position[",
        "mirror_normal[",
        "mirror_geometric[",
        "mirror_weight[",
    ];
    for (name, wgsl) in frame_shaders {
        // Shaders that neither bind nor import the records (the traversal, textures)
        // have vec4s of their own.
        let touches_records = records.iter().any(|r| wgsl.contains(&r[..r.len() - 1]))
            || wgsl.contains("#import gbuffer");
        if name == "gbuffer" || !touches_records {
            continue;
        }
        for (i, line) in wgsl.lines().enumerate() {
            let code = line.split("//").next().unwrap();
            let reads_w = code.match_indices(".w").any(|(at, _)| {
                !code[at + 2..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
            });
            let writes_vec4 = records.iter().any(|r| code.contains(r)) && code.contains("= vec4");
            assert!(
                !reads_w && !writes_vec4,
                "{name}.wgsl line {}: use gbuffer.wgsl's functions: {line}",
                i + 1
            );
        }
    }
}

/// Software adapters get no uniform buffers at all (lavapipe recompiles shaders whose
/// branches depend on uniform values every time they are bound, see `ParamsBinding`),
/// and GPUs get the blocks as uniform buffers still.
#[test]
fn software_adapters_get_no_uniform_buffers() {
    for pass in SOURCES {
        let uniforms = |binding| {
            let module = naga::front::wgsl::parse_str(&compose_for(pass, binding)).unwrap();
            module
                .global_variables
                .iter()
                .filter(|(_, g)| g.space == naga::AddressSpace::Uniform)
                .count()
        };
        assert_eq!(uniforms(ParamsBinding::Storage), 0, "{}", pass.name);
        assert!(uniforms(ParamsBinding::Uniform) > 0, "{}", pass.name);
    }
}

/// The storage buffers of the pass that declares the most, which is what a device must
/// allow per shader stage: `GpuContext` refuses an adapter with fewer up front, by the
/// number it is told, so that number must be the shaders' own, for GPUs and for software
/// adapters (whose parameter blocks are storage buffers too).
#[test]
fn storage_buffers_per_stage_is_what_the_shaders_declare() {
    for binding in ParamsBinding::ALL {
        let most = SOURCES
            .iter()
            .map(|pass| {
                let module = naga::front::wgsl::parse_str(&compose_for(pass, binding)).unwrap();
                let storage = module
                    .global_variables
                    .iter()
                    .filter(|(_, g)| matches!(g.space, naga::AddressSpace::Storage { .. }))
                    .count() as u32;
                (storage, pass.name)
            })
            .max()
            .unwrap();
        assert_eq!(
            most.0,
            igi_gpu::context::storage_buffers_per_stage(binding),
            "the {} pass declares the most storage buffers ({binding:?} params)",
            most.1
        );
    }
}

/// (size, [(member name, offset)]) of the WGSL struct `name`.
fn wgsl_layout(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    for (handle, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let naga::TypeInner::Struct { members, span } = &ty.inner {
                let _ = layouter[handle];
                return (
                    *span,
                    members
                        .iter()
                        .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                        .collect(),
                );
            }
        }
    }
    panic!("no struct {name} in the WGSL");
}

macro_rules! check_layout {
    ($module:expr, $wgsl:literal, $rust:ty, [$($field:ident),* $(,)?]) => {{
        let (size, members) = wgsl_layout($module, $wgsl);
        assert_eq!(size as usize, size_of::<$rust>(), "size of {}", $wgsl);
        $(
            let offset = members
                .iter()
                .find(|(n, _)| n == stringify!($field))
                .unwrap_or_else(|| panic!("{} has no member {}", $wgsl, stringify!($field)))
                .1;
            assert_eq!(offset as usize, offset_of!($rust, $field), "{}.{}", $wgsl, stringify!($field));
        )*
    }};
}

#[test]
fn host_structs_match_wgsl() {
    let (name, src) = igi_gpu::shader::all_shaders().remove(0);
    let module = parse_and_validate(name, &src);
    check_layout!(
        &module,
        "BvhNode",
        BvhNode,
        [a_min, a_index, a_max, a_count, b_min, b_index, b_max, b_count]
    );
    check_layout!(&module, "TriShading", TriShading, [n0, material, n1, n2]);
    check_layout!(
        &module,
        "Material",
        GpuMaterial,
        [
            diffuse,
            texture,
            mirror,
            flags,
            uv_row0,
            alpha_factor,
            uv_row1,
            alpha_cutoff
        ]
    );
    check_layout!(
        &module,
        "TriAttributes",
        GpuTriAttributes,
        [uv01, uv2, color0, color1, color2]
    );
    check_layout!(&module, "PointLight", GpuLight, [position, intensity]);
    check_layout!(
        &module,
        "Vpl",
        Vpl,
        [position, valid, normal, bounce, flux, albedo]
    );
    check_layout!(
        &module,
        "FrameParams",
        FrameParams,
        [
            cam_eye,
            width,
            cam_forward,
            height,
            cam_right,
            tan_half_fov_y,
            cam_up,
            aspect,
            total_power,
            light_count,
            path_count,
            bounces,
            min_dist,
            geometry_bound,
            mirror_depth,
            halton_base,
            output,
            light_power_sum,
            low_width,
            low_height,
            downsample,
            interleave_n,
            interleave_m,
            pattern,
            seed,
            accumulate_index,
            upsample_sigma,
            normal_power,
            upsample_depth,
            depth_threshold,
            normal_threshold,
            jitter_x,
            jitter_y,
            count_rays,
            depth_scale,
            ray_offset_floor
        ]
    );
}

#[test]
fn display_params_match_wgsl() {
    let (name, src) = igi_gpu::shader::all_shaders()
        .into_iter()
        .find(|(n, _)| *n == "display")
        .expect("display shader");
    let module = parse_and_validate(name, &src);
    check_layout!(
        &module,
        "DisplayParams",
        DisplayParams,
        [
            viewport,
            image_width,
            image_height,
            exposure,
            encode_srgb,
            dot_radius
        ]
    );
}

/// The value of the WGSL constant `name` (a u32 literal).
fn wgsl_u32(module: &naga::Module, name: &str) -> u32 {
    match wgsl_constant(module, name) {
        naga::Literal::U32(v) => v,
        l => panic!("{name} is not a u32: {l:?}"),
    }
}

#[test]
fn host_constants_match_wgsl() {
    let shaders = igi_gpu::shader::all_shaders();
    let module = |pass: &str| {
        let (name, src) = shaders.iter().find(|(n, _)| *n == pass).unwrap();
        parse_and_validate(name, src)
    };
    for (pass, name, host) in [
        ("vpl", "COMPACT_GROUP", igi_gpu::passes::vpl::COMPACT_GROUP),
        ("vpl", "SHOOT_GROUP", igi_gpu::passes::vpl::SHOOT_GROUP),
        (
            "direct",
            "CHAIN_GROUP",
            igi_gpu::passes::direct::CHAIN_GROUP,
        ),
        ("direct", "MAX_SUBSETS", igi_gpu::frame::MAX_SUBSETS),
    ] {
        assert_eq!(wgsl_u32(&module(pass), name), host, "{pass}.wgsl {name}");
    }
}
