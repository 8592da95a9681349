//! What the Vulkan driver made of a pass's shader: register count, local (spill) memory,
//! shared memory, instruction count... as the driver reports them through
//! VK_KHR_pipeline_executable_properties. A measuring tool for the traversal (occupancy
//! decides how well a walk hides its memory latency).
//!
//! `cargo run --release -p igi-gpu --example shader_stats -- PASS ENTRY [NAME=VALUE...]`,
//! e.g. `rays any_hit` or `indirect main_coherent COHERENT_LANES=4`. The WGSL is composed
//! as igi composes it, translated to SPIR-V by naga with the checks igi's pipelines use
//! (bounds checks and loop bounding off unless IGI_SHADER_CHECKS=1), and compiled by the
//! driver on a device opened through wgpu with the extension enabled. NVIDIA's driver
//! (580) reports the register count, binary size, local and shared memory; it gives no
//! internal representation (no SASS). llvmpipe lacks the extension: the tool says so and
//! exits with 1. Register counts measured with it are in the lab log (docs/lab/).

use std::ffi::CStr;

use ash::vk;
use wgpu::hal;
use wgpu::hal::api::Vulkan;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [pass, entry, constants @ ..] = args.as_slice() else {
        return Err("usage: shader_stats PASS ENTRY [NAME=VALUE...]".into());
    };
    let source = igi_gpu::passes::SOURCES
        .iter()
        .find(|s| s.name == pass)
        .ok_or_else(|| format!("no pass named {pass}"))?;
    let wgsl = igi_gpu::shader::compose(source);
    let module = naga::front::wgsl::parse_str(&wgsl).map_err(|e| e.emit_to_string(&wgsl))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .subgroup_stages(naga::valid::ShaderStages::COMPUTE)
    .subgroup_operations(naga::valid::SubgroupOperationSet::all())
    .validate(&module)
    .map_err(|e| format!("{e:?}"))?;
    let mut overrides = naga::back::PipelineConstants::default();
    for c in constants {
        let (k, v) = c.split_once('=').ok_or("constants are NAME=VALUE")?;
        overrides.insert(k.to_string(), v.parse::<f64>().map_err(|e| e.to_string())?);
    }
    let (module, info) = naga::back::pipeline_constants::process_overrides(
        &module,
        &info,
        Some((naga::ShaderStage::Compute, entry)),
        &overrides,
    )
    .map_err(|e| format!("{e:?}"))?;
    let checked = std::env::var_os("IGI_SHADER_CHECKS").is_some_and(|v| v == "1");
    let policy = if checked {
        naga::proc::BoundsCheckPolicy::Restrict
    } else {
        naga::proc::BoundsCheckPolicy::Unchecked
    };
    let options = naga::back::spv::Options {
        lang_version: (1, 3),
        flags: naga::back::spv::WriterFlags::empty(),
        bounds_check_policies: naga::proc::BoundsCheckPolicies {
            index: policy,
            buffer: policy,
            image_load: policy,
            binding_array: policy,
        },
        force_loop_bounding: checked,
        ..Default::default()
    };
    let spirv = naga::back::spv::write_vec(
        &module,
        &info,
        &options,
        Some(&naga::back::spv::PipelineOptions {
            shader_stage: naga::ShaderStage::Compute,
            entry_point: entry.clone(),
        }),
    )
    .map_err(|e| e.to_string())?;

    // Descriptor set layouts from the module's bindings.
    let mut sets: Vec<Vec<vk::DescriptorSetLayoutBinding>> = vec![];
    for (_, var) in module.global_variables.iter() {
        let Some(b) = &var.binding else { continue };
        let ty = match var.space {
            naga::AddressSpace::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
            naga::AddressSpace::Storage { .. } => vk::DescriptorType::STORAGE_BUFFER,
            _ => continue,
        };
        let group = b.group as usize;
        if sets.len() <= group {
            sets.resize(group + 1, vec![]);
        }
        sets[group].push(
            vk::DescriptorSetLayoutBinding::default()
                .binding(b.binding)
                .descriptor_type(ty)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE),
        );
    }

    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    desc.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(desc);
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))
        .map_err(|e| format!("no Vulkan adapter: {e}"))?;
    println!("adapter: {:?}", adapter.get_info().name);
    let ext = ash::khr::pipeline_executable_properties::NAME;
    let feature: &'static mut vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR =
        Box::leak(Box::new(
            vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default()
                .pipeline_executable_info(true),
        ));
    // SAFETY: the extension and feature are only added (the driver lists the extension,
    // checked below by the device creation failing otherwise); nothing wgpu set is removed.
    let hal_adapter = unsafe { adapter.as_hal::<Vulkan>() }.ok_or("not a Vulkan adapter")?;
    let listed = unsafe {
        hal_adapter
            .shared_instance()
            .raw_instance()
            .enumerate_device_extension_properties(hal_adapter.raw_physical_device())
    }
    .map_err(|e| e.to_string())?;
    if !listed
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(ash::khr::pipeline_executable_properties::NAME))
    {
        return Err(format!(
            "the driver of {:?} does not offer VK_KHR_pipeline_executable_properties",
            adapter.get_info().name
        ));
    }
    let open = unsafe {
        hal_adapter.open_with_callback(
            wgpu::Features::empty(),
            &wgpu::Limits::default(),
            &wgpu::MemoryHints::Performance,
            Some(Box::new(
                move |args: hal::vulkan::CreateDeviceCallbackArgs| {
                    args.extensions.push(ext);
                    *args.create_info = args.create_info.push_next(feature);
                },
            )),
        )
    }
    .map_err(|e| format!("device without {ext:?}: {e}"))?;
    let device: &ash::Device = open.device.raw_device();
    let raw_instance = hal_adapter.shared_instance().raw_instance();
    let pep = ash::khr::pipeline_executable_properties::Device::new(raw_instance, device);

    unsafe {
        let shader = device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&spirv), None)
            .map_err(|e| e.to_string())?;
        let set_layouts: Vec<vk::DescriptorSetLayout> = sets
            .iter()
            .map(|b| {
                device.create_descriptor_set_layout(
                    &vk::DescriptorSetLayoutCreateInfo::default().bindings(b),
                    None,
                )
            })
            .collect::<Result<_, _>>()
            .map_err(|e| e.to_string())?;
        let layout = device
            .create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts),
                None,
            )
            .map_err(|e| e.to_string())?;
        let name = std::ffi::CString::new(entry.as_str()).map_err(|e| e.to_string())?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(shader)
            .name(&name);
        let create = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout)
            .flags(vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR);
        let pipeline = device
            .create_compute_pipelines(vk::PipelineCache::null(), &[create], None)
            .map_err(|(_, e)| e.to_string())?[0];
        let executables = pep
            .get_pipeline_executable_properties(&vk::PipelineInfoKHR::default().pipeline(pipeline))
            .map_err(|e| e.to_string())?;
        for (i, exe) in executables.iter().enumerate() {
            let text =
                |s: &[std::ffi::c_char]| CStr::from_ptr(s.as_ptr()).to_string_lossy().into_owned();
            println!(
                "{pass}/{entry} executable {i}: {} ({}), subgroup size {}",
                text(&exe.name),
                text(&exe.description),
                exe.subgroup_size
            );
            let info = vk::PipelineExecutableInfoKHR::default()
                .pipeline(pipeline)
                .executable_index(i as u32);
            for s in pep
                .get_pipeline_executable_statistics(&info)
                .map_err(|e| e.to_string())?
            {
                let value = match s.format {
                    vk::PipelineExecutableStatisticFormatKHR::BOOL32 => s.value.b32.to_string(),
                    vk::PipelineExecutableStatisticFormatKHR::INT64 => s.value.i64.to_string(),
                    vk::PipelineExecutableStatisticFormatKHR::UINT64 => s.value.u64.to_string(),
                    _ => s.value.f64.to_string(),
                };
                println!("  {}: {value}  ({})", text(&s.name), text(&s.description));
            }
        }
        device.destroy_pipeline(pipeline, None);
    }
    Ok(())
}
