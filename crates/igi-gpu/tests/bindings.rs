//! Every pass's typed bindings agree with its WGSL: naga reads each composed shader's
//! `@group/@binding` variables, and each declared bind group must list them in binding
//! order with the same names and the same access (parameter block, read-only or
//! read-write storage). Every group a shader declares must have its declaration, so a
//! new binding in a shader fails here until its pass says how it binds it.

use igi_gpu::passes::bindings::{Access, Binding, Bindings, GroupDecl};
use igi_gpu::scene_buffers::SceneBindings;
use std::collections::BTreeMap;

/// The shader's resource bindings, by group, in binding order: (binding, name, access).
fn shader_groups(name: &str, wgsl: &str) -> BTreeMap<u32, Vec<(u32, String, Access)>> {
    let module = naga::front::wgsl::parse_str(wgsl)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(wgsl)));
    let mut groups: BTreeMap<u32, Vec<(u32, String, Access)>> = BTreeMap::new();
    for (_, var) in module.global_variables.iter() {
        let Some(binding) = &var.binding else {
            continue;
        };
        let access = match var.space {
            naga::AddressSpace::Uniform => Access::Params,
            naga::AddressSpace::Storage { access } => {
                if access.contains(naga::StorageAccess::STORE) {
                    Access::Write
                } else {
                    Access::Read
                }
            }
            other => panic!("{name}: binding of unexpected space {other:?}"),
        };
        let var_name = var.name.clone().unwrap_or_default();
        groups
            .entry(binding.group)
            .or_default()
            .push((binding.binding, var_name, access));
    }
    for vars in groups.values_mut() {
        vars.sort_by_key(|v| v.0);
    }
    groups
}

fn check(shader: &str, group: u32, declared: &[Binding], found: &[(u32, String, Access)]) {
    let found_names: Vec<_> = found
        .iter()
        .map(|(b, n, a)| format!("{b}: {n} ({a:?})"))
        .collect();
    let declared_names: Vec<_> = declared
        .iter()
        .enumerate()
        .map(|(b, d)| format!("{b}: {} ({:?})", d.name, d.access))
        .collect();
    assert_eq!(
        declared_names, found_names,
        "{shader}, group {group}: the declared bindings (left) disagree with the WGSL (right)"
    );
}

#[test]
fn every_declared_group_matches_its_shader() {
    let shaders: BTreeMap<&str, String> = igi_gpu::shader::all_shaders().into_iter().collect();
    let declared = igi_gpu::passes::declared_groups();
    for GroupDecl {
        shader,
        group,
        bindings,
    } in &declared
    {
        let wgsl = shaders
            .get(shader)
            .unwrap_or_else(|| panic!("no shader called {shader}"));
        let groups = shader_groups(shader, wgsl);
        let found = groups
            .get(group)
            .unwrap_or_else(|| panic!("{shader} declares no group {group}"));
        check(shader, *group, bindings, found);
    }
    // And every group of every shader has a declaration (group 0 is the scene's).
    for (name, wgsl) in &shaders {
        for (group, found) in shader_groups(name, wgsl) {
            if group == 0 {
                check(name, 0, SceneBindings::BINDINGS, &found);
                continue;
            }
            assert!(
                declared
                    .iter()
                    .any(|d| d.shader == *name && d.group == group),
                "{name}: group {group} ({found:?}) has no typed bindings in passes::declared_groups"
            );
        }
    }
}

/// The check can fail: two read-only bindings swapped, or an access changed, disagree.
#[test]
fn a_swapped_or_mistyped_binding_is_caught() {
    let found = vec![
        (0, "params".to_string(), Access::Params),
        (1, "gbuf_position".to_string(), Access::Read),
        (2, "gbuf_normal".to_string(), Access::Read),
    ];
    let right = [
        Binding {
            name: "params",
            access: Access::Params,
        },
        Binding {
            name: "gbuf_position",
            access: Access::Read,
        },
        Binding {
            name: "gbuf_normal",
            access: Access::Read,
        },
    ];
    check("synthetic", 1, &right, &found);
    let mut swapped = right;
    swapped.swap(1, 2);
    let caught = std::panic::catch_unwind(|| check("synthetic", 1, &swapped, &found));
    assert!(caught.is_err(), "two swapped read-only bindings passed");
    let mut mistyped = right;
    mistyped[2].access = Access::Write;
    let caught = std::panic::catch_unwind(|| check("synthetic", 1, &mistyped, &found));
    assert!(
        caught.is_err(),
        "a read-only binding declared read-write passed"
    );
}
