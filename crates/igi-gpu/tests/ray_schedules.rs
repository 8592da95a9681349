//! The two schedules of the ray kernel's any hit (`RaySchedule`, raybench.rs): one ray
//! per thread (rays.wgsl) and refilled subgroups (rays_refill.wgsl, Aila and Laine's
//! persistent threads with dynamic fetch) must answer every ray as the CPU twin's
//! `Bvh::trace_any` does, whatever the batch size and however many rays each lane takes;
//! and the automatic choice must tell a coherent batch from an incoherent one.

mod common;

use glam::Vec3;
use igi_core::bvh::Bvh;
use igi_core::rays::{random_rays, random_segments, RayRecord};
use igi_core::scene::builtin::builtin_scene;
use igi_gpu::raybench::{coherent_fraction, refill_offered, RayBench, RayQuery, RaySchedule};

/// The Cornell box with three spheres in it (about 3,900 triangles: a tree some 12
/// levels deep, so that walks differ in length).
fn test_scene() -> igi_core::scene::Scene {
    let mut scene = builtin_scene("cornell-box").expect("built-in scene");
    let (lo, hi) = Bvh::build(&scene.triangles).bounds();
    let size = hi - lo;
    for (k, at) in [(0.3, 0.25, 0.4), (0.7, 0.5, 0.6), (0.45, 0.7, 0.3)]
        .into_iter()
        .enumerate()
    {
        let centre = lo + size * Vec3::new(at.0, at.1, at.2);
        let r = 0.12 * size.min_element() * (1.0 + 0.3 * k as f32);
        scene
            .triangles
            .extend(common::icosphere(r, 3, 0).into_iter().map(|mut t| {
                t.v = t.v.map(|v| v + centre);
                t
            }));
    }
    scene
}

fn cpu_answers(bvh: &Bvh, rays: &[RayRecord]) -> Vec<u32> {
    rays.iter()
        .map(|r| u32::from(bvh.trace_any(Vec3::from(r.origin), Vec3::from(r.dir), r.tmax)))
        .collect()
}

#[test]
fn both_schedules_answer_like_the_cpu_twin() {
    let Some(ctx) = common::gpu() else { return };
    let mut schedules = vec![RaySchedule::PerThread];
    if refill_offered(&ctx) {
        schedules.push(RaySchedule::Refill);
    } else {
        eprintln!(
            "refill schedule skipped: adapter '{}' does not run it (a software adapter, or \
             no subgroup operations: raybench::refill_offered)",
            ctx.info.name
        );
    }
    let scene = test_scene();
    let bvh = Bvh::build(&scene.triangles);
    let mut bench = RayBench::new(&ctx, &scene, &bvh).expect("ray bench");
    // 4 workgroups of 64 threads: each lane of the refill schedule takes dozens of rays.
    bench.set_refill_groups(4);
    // Segments between surface points, rays without an end, a batch that is not a
    // multiple of anything, and zero directions (answered free at once).
    let mut rays = random_segments(&scene, 20_011, 5);
    rays.extend(random_rays(&scene, 10_007, 6));
    for k in (0..rays.len()).step_by(997) {
        rays[k].dir = [0.0; 3];
    }
    let cpu = cpu_answers(&bvh, &rays);
    let occluded = cpu.iter().filter(|&&a| a == 1).count();
    assert!(
        occluded > rays.len() / 10 && occluded < rays.len() * 9 / 10,
        "{occluded} of {} occluded: too one-sided to mean anything",
        rays.len()
    );
    for schedule in schedules {
        let timing = bench
            .trace(&ctx, &rays, RayQuery::AnyHit, schedule, 1)
            .expect("trace");
        let differ: Vec<usize> = (0..rays.len())
            .filter(|&i| timing.results[i] != cpu[i])
            .collect();
        assert!(
            differ.is_empty(),
            "{}: {} of {} rays answered unlike the CPU twin (first: {:?})",
            schedule.name(),
            differ.len(),
            rays.len(),
            &differ[..differ.len().min(10)]
        );
        assert_eq!(timing.hits as usize, occluded);
    }
}

#[test]
fn refill_is_picked_for_incoherent_batches_only() {
    let Some(ctx) = common::gpu() else { return };
    let scene = test_scene();
    let bvh = Bvh::build(&scene.triangles);
    let (lo, hi) = bvh.bounds();
    let random = random_segments(&scene, 5_000, 1);
    // A coherent batch as the renderer's frame set orders it: a row of neighbouring
    // surface points, each to one light, then the next light.
    let points: Vec<Vec3> = (0..2_000)
        .map(|k| lo + (hi - lo) * Vec3::new(0.2 + 0.3 * k as f32 / 2_000.0, 0.001, 0.5))
        .collect();
    let coherent: Vec<RayRecord> = [Vec3::new(0.5, 0.95, 0.5), Vec3::new(0.3, 0.9, 0.7)]
        .iter()
        .flat_map(|&l| {
            points
                .iter()
                .map(move |&p| RayRecord::segment(p, lo + (hi - lo) * l))
        })
        .collect();
    assert!(coherent_fraction(&random, lo, hi) < 0.05);
    assert!(coherent_fraction(&coherent, lo, hi) > 0.95);
    assert_eq!(
        RaySchedule::auto(&ctx, coherent_fraction(&coherent, lo, hi)),
        RaySchedule::PerThread
    );
    let expected = if refill_offered(&ctx) {
        RaySchedule::Refill
    } else {
        RaySchedule::PerThread
    };
    assert_eq!(
        RaySchedule::auto(&ctx, coherent_fraction(&random, lo, hi)),
        expected
    );
}
