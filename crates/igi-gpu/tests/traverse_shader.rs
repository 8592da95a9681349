//! traverse.wgsl (the GPU ray-tracing layer that replaces OptiX in Marques and Santos'
//! IGI) parses and validates with naga, composed as every tracing pass composes it, and
//! its constants agree with the CPU builder and traversal of igi-core.

mod common;

use common::wgsl_constant;
use igi_gpu::shader::ParamsBinding;
use naga::valid::{Capabilities, ValidationFlags, Validator};

const SCENE: &str = include_str!("../src/shaders/scene.wgsl");
const TRAVERSE: &str = include_str!("../src/shaders/traverse.wgsl");

/// A kernel that calls every public function of traverse.wgsl.
const KERNEL: &str = r#"
#import traverse

@group(1) @binding(0) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let o = vec3<f32>(f32(gid.x), 0.5, -3.0);
    var stack: WalkStack;
    let h = trace_closest(&stack, o, vec3<f32>(0.0, 0.0, 1.0), 1e30);
    let a = trace_any(&stack, o, vec3<f32>(0.0, 1.0, 0.0), 1.0) || trace_segment(&stack, o, vec3<f32>(1.0, 0.0, 0.0), true);
    let p = offset_ray_origin(o, vec3<f32>(0.0, 1.0, 0.0), 0.0);
    let s = shadow_segment(o, vec3<f32>(0.0, 1.0, 0.0), p, vec3<f32>(1.0, 0.0, 0.0), 0.25);
    out[gid.x] = vec4<f32>(h.t + f32(h.tri) + h.u + h.v, select(0.0, 1.0, a), p.x + s.origin.y, s.dir.z);
}
"#;

fn parse_and_validate(src: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("does not parse:\n{}", e.emit_to_string(src)));
    Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("does not validate:\n{}", e.emit_to_string(src)));
    // Also without optional capabilities: traverse.wgsl must need none.
    Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("needs an optional capability:\n{}", e.emit_to_string(src)));
    module
}

/// The kernel after traverse.wgsl and what it imports (scene.wgsl), as every tracing pass
/// composes them.
fn composed() -> String {
    igi_gpu::shader::try_compose("kernel", KERNEL, ParamsBinding::Uniform).unwrap()
}

#[test]
fn traverse_wgsl_validates() {
    parse_and_validate(&composed());
}

#[test]
fn traverse_wgsl_matches_the_shared_module() {
    // The shader assembly of igi-gpu composes the same files, and traverse.wgsl needs
    // scene.wgsl and texture.wgsl (the alpha-mask test of its leaves).
    assert_eq!(igi_gpu::shader::module("traverse"), Some(TRAVERSE));
    assert_eq!(igi_gpu::shader::module("scene"), Some(SCENE));
    assert_eq!(
        igi_gpu::shader::resolve::imports("traverse", TRAVERSE),
        Ok(vec!["scene", "texture"])
    );
    assert!(composed().starts_with(SCENE));
}

#[test]
fn constants_match_the_cpu_twin() {
    let module = parse_and_validate(&composed());
    assert_eq!(
        wgsl_constant(&module, "STACK_SIZE"),
        naga::Literal::U32(igi_core::bvh::MAX_DEPTH),
        "the traversal stack must hold MAX_DEPTH entries"
    );
    assert_eq!(
        wgsl_constant(&module, "NO_HIT"),
        naga::Literal::U32(igi_core::bvh::NO_HIT)
    );
    let f = |name: &str| match wgsl_constant(&module, name) {
        naga::Literal::F32(x) => x,
        l => panic!("{name}: {l:?}"),
    };
    // The bits the CPU uses (igi-core/src/bvh/traverse.rs).
    assert_eq!(f("BOX_TFAR_SCALE"), 1.0 + 3.0 * f32::EPSILON);
    assert_eq!(f("DIR_EPS"), 1e-30);
    assert_eq!(f("PARALLEL_INV"), 1e30);
    assert_eq!(f("PARALLEL_SLACK"), 1.0 / 1_048_576.0);
    assert_eq!(f("SLAB_PAD"), 1.0 / 2_097_152.0);
    assert_eq!(f("SEGMENT_PAD"), 1.0 / 2_097_152.0);
    assert_eq!(f("OFFSET_ORIGIN"), 1.0 / 32.0);
    assert_eq!(f("OFFSET_FLOAT_SCALE"), 1.0 / 65536.0);
    assert_eq!(f("OFFSET_INT_SCALE"), 256.0);
}

#[test]
fn hit_is_16_bytes_like_the_cpu_hit() {
    let module = parse_and_validate(&composed());
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("Hit"))
        .expect("struct Hit");
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("Hit is not a struct")
    };
    assert_eq!(layouter[handle].size, 16);
    assert_eq!(*span as usize, std::mem::size_of::<igi_core::bvh::Hit>());
    let offsets: Vec<(String, u32)> = members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
        .collect();
    assert_eq!(
        offsets,
        [("t", 0), ("tri", 4), ("u", 8), ("v", 12)].map(|(n, o)| (n.to_string(), o))
    );
}
