//! Ray sets for measuring the ray-tracing layer alone (`igi bench rays`), and the ray file
//! format another ray tracer can read to trace the very same rays.
//!
//! # Ray file format
//! A flat array of rays, no header, little-endian IEEE-754 `f32`, 32 bytes a ray:
//!
//! | offset | field | |
//! |---|---|---|
//! | 0 | origin x, y, z | already offset off the surface it leaves |
//! | 12 | tmin | always 0 |
//! | 16 | direction x, y, z | unit length |
//! | 28 | tmax | segment length for shadow rays; 3.4e38 ("infinity") for closest-hit rays |
//!
//! Surface points are offset with the method of Wächter and Binder (Ray Tracing Gems,
//! ch. 6, [`crate::bvh::offset_ray_origin`]) and at least the scene's offset floor: a
//! shadow segment runs from x moved off its surface towards y, to y moved off its surface
//! towards x, so neither end surface can occlude it.

use crate::bvh::offset_ray_origin;
use crate::sampling::hash_u32;
use crate::scene::Scene;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use std::path::Path;

/// One ray as stored in a ray file (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RayRecord {
    pub origin: [f32; 3],
    pub tmin: f32,
    pub dir: [f32; 3],
    pub tmax: f32,
}

/// tmax of a ray without an end.
pub const RAY_INFINITY: f32 = 3.4e38;

impl RayRecord {
    /// The shadow segment from a to b (both already offset).
    pub fn segment(a: Vec3, b: Vec3) -> RayRecord {
        let d = b - a;
        let len = d.length();
        RayRecord {
            origin: a.to_array(),
            tmin: 0.0,
            dir: (d / len.max(f32::MIN_POSITIVE)).to_array(),
            tmax: len,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum RayFileError {
    #[error("cannot read ray file '{0}': {1}")]
    Read(String, String),
    #[error(
        "ray file '{0}' has {1} bytes, not a multiple of 32 (origin, tmin, direction, tmax as f32)"
    )]
    Size(String, u64),
    #[error("ray file '{0}' holds no rays")]
    Empty(String),
    #[error("ray {1} of '{0}' is not finite or has a zero direction")]
    Bad(String, usize),
    #[error("cannot write ray file '{0}': {1}")]
    Write(String, String),
}

/// Write rays in the documented format (through a temporary file and a rename).
pub fn write_rays(path: &Path, rays: &[RayRecord]) -> Result<(), RayFileError> {
    let bytes: &[u8] = bytemuck::cast_slice(rays);
    crate::image::write_atomically(path, |file| {
        std::io::Write::write_all(file, bytes).map_err(|e| e.to_string())
    })
    .map_err(|e| {
        // The image writer's error names the path too: keep its reason alone.
        let reason = match e {
            crate::image::ImageError::Write { reason, .. } => reason,
            other => other.to_string(),
        };
        RayFileError::Write(path.display().to_string(), reason)
    })
}

/// Read and check a ray file.
pub fn read_rays(path: &Path) -> Result<Vec<RayRecord>, RayFileError> {
    let name = path.display().to_string();
    // A FIFO or device is refused, not read (which could block forever).
    let bytes = crate::scene::loader::read_regular_file(path)
        .map_err(|e| RayFileError::Read(name.clone(), e.to_string()))?;
    if bytes.len() % 32 != 0 {
        return Err(RayFileError::Size(name, bytes.len() as u64));
    }
    if bytes.is_empty() {
        return Err(RayFileError::Empty(name));
    }
    let rays: Vec<RayRecord> = bytes
        .chunks_exact(32)
        .map(|c| {
            let f: Vec<f32> = c
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            RayRecord {
                origin: [f[0], f[1], f[2]],
                tmin: f[3],
                dir: [f[4], f[5], f[6]],
                tmax: f[7],
            }
        })
        .collect();
    for (i, r) in rays.iter().enumerate() {
        let ok = r
            .origin
            .iter()
            .chain(&r.dir)
            .chain([&r.tmin, &r.tmax])
            .all(|v| v.is_finite())
            && Vec3::from(r.dir) != Vec3::ZERO;
        if !ok {
            return Err(RayFileError::Bad(name, i));
        }
    }
    Ok(rays)
}

/// The most rays [`random_segments`] and [`random_rays`] make at once (and `igi bench
/// rays` traces): 8 GiB of rays, which are generated, held and uploaded whole, with their
/// results beside them; more would run out of host or GPU memory on any current machine.
pub const MAX_RAYS: usize = 1 << 28;

/// Whether a ray set of `count` rays can be made here: at most [`MAX_RAYS`], and the host
/// memory for generating it (the surface points and the rays) can be had now. The reason
/// otherwise, so that a huge count is one clear error instead of an aborted allocation
/// (or, where the system overcommits memory and any reservation succeeds, the OOM
/// killer): on Linux the need is compared with MemAvailable of /proc/meminfo.
pub fn check_ray_count(count: usize) -> Result<(), String> {
    check_ray_count_within(count, available_memory())
}

/// The memory the system can give without swapping (MemAvailable, Linux), in bytes.
fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// [`check_ray_count`] with the available memory given (None: unknown).
fn check_ray_count_within(count: usize, available: Option<u64>) -> Result<(), String> {
    if count > MAX_RAYS {
        return Err(format!(
            "at most {MAX_RAYS} rays ({} GiB of rays at 32 bytes a ray)",
            (MAX_RAYS * 32) >> 30
        ));
    }
    // Two sets of surface points (position and normal, 24 bytes each) and the rays.
    let bytes = count * (2 * 24 + 32);
    if let Some(available) = available.filter(|&a| bytes as u64 > a) {
        return Err(format!(
            "the {} MiB that {count} rays need are more than the {} MiB of memory available here",
            bytes >> 20,
            available >> 20
        ));
    }
    let mut probe: Vec<u8> = Vec::new();
    probe.try_reserve_exact(bytes).map_err(|_| {
        format!(
            "cannot allocate the {} MiB that {count} rays need here",
            bytes >> 20
        )
    })
}

/// A small deterministic generator (hash of a counter) for ray sets.
struct Uniform {
    state: u32,
}

impl Uniform {
    fn next(&mut self) -> f32 {
        self.state = hash_u32(self.state.wrapping_add(0x9e37_79b9));
        (self.state >> 8) as f32 / (1u32 << 24) as f32
    }
}

/// Area-uniform random points on the scene's surfaces: (point, unit geometric normal).
fn surface_points(scene: &Scene, count: usize, seed: u32) -> Vec<(Vec3, Vec3)> {
    let mut cdf = Vec::with_capacity(scene.triangles.len());
    let mut total = 0.0f64;
    for t in &scene.triangles {
        total += t.area() as f64;
        cdf.push(total);
    }
    let mut rng = Uniform {
        state: hash_u32(seed ^ 0x5eed),
    };
    (0..count)
        .map(|_| {
            let target = rng.next() as f64 * total;
            let i = cdf.partition_point(|&c| c < target).min(cdf.len() - 1);
            let t = &scene.triangles[i];
            let (mut u, mut v) = (rng.next(), rng.next());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = t.v[0] + u * (t.v[1] - t.v[0]) + v * (t.v[2] - t.v[0]);
            (p, t.cross().normalize())
        })
        .collect()
}

/// Shadow segments between pairs of area-uniform random surface points, each end moved
/// off its surface on the side facing the other end.
pub fn random_segments(scene: &Scene, count: usize, seed: u32) -> Vec<RayRecord> {
    let a = surface_points(scene, count, seed);
    let b = surface_points(scene, count, seed.wrapping_add(1));
    let floor = scene.ray_offset_floor();
    a.iter()
        .zip(&b)
        .map(|(&(pa, na), &(pb, nb))| {
            let d = pb - pa;
            let na = if na.dot(d) < 0.0 { -na } else { na };
            let nb = if nb.dot(d) > 0.0 { -nb } else { nb };
            RayRecord::segment(
                offset_ray_origin(pa, na, floor),
                offset_ray_origin(pb, nb, floor),
            )
        })
        .collect()
}

/// Closest-hit rays from area-uniform random surface points in uniform random directions
/// (origin moved off the surface on the side the ray leaves to).
pub fn random_rays(scene: &Scene, count: usize, seed: u32) -> Vec<RayRecord> {
    let points = surface_points(scene, count, seed);
    let floor = scene.ray_offset_floor();
    let mut rng = Uniform {
        state: hash_u32(seed ^ 0xd1ec),
    };
    points
        .iter()
        .map(|&(p, n)| {
            let d = crate::sampling::uniform_sphere(rng.next(), rng.next());
            let n = if n.dot(d) < 0.0 { -n } else { n };
            RayRecord {
                origin: offset_ray_origin(p, n, floor).to_array(),
                tmin: 0.0,
                dir: d.to_array(),
                tmax: RAY_INFINITY,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_file_round_trips_and_rejects_junk() {
        let dir = std::env::temp_dir().join(format!("igi-rays-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = crate::scene::builtin::builtin_scene("cornell-box").unwrap();
        let rays = random_segments(&scene, 100, 1);
        let path = dir.join("r.bin");
        write_rays(&path, &rays).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().len(), 3200);
        assert_eq!(read_rays(&path).unwrap(), rays);
        // Little-endian f32 at the documented offsets.
        let bytes = std::fs::read(&path).unwrap();
        let tmax = f32::from_le_bytes(bytes[28..32].try_into().unwrap());
        assert_eq!(tmax, rays[0].tmax);
        std::fs::write(&path, [0u8; 33]).unwrap();
        assert!(read_rays(&path)
            .unwrap_err()
            .to_string()
            .contains("multiple of 32"));
        std::fs::write(&path, []).unwrap();
        assert!(read_rays(&path).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn huge_counts_are_refused_before_allocating() {
        assert!(check_ray_count(1 << 20).is_ok());
        assert!(
            check_ray_count_within(MAX_RAYS, None).is_ok() || cfg!(target_pointer_width = "32")
        );
        // More than the memory available (1 GiB here): refused, though the probe's
        // reservation might succeed where the system overcommits.
        let e = check_ray_count_within(1 << 24, Some(1 << 30)).unwrap_err();
        assert!(e.contains("1280 MiB") && e.contains("1024 MiB"), "{e}");
        assert!(check_ray_count_within(1 << 23, Some(1 << 30)).is_ok());
        let e = check_ray_count(u32::MAX as usize).unwrap_err();
        assert!(e.contains(&format!("at most {MAX_RAYS} rays")), "{e}");
        assert!(check_ray_count(usize::MAX).is_err());
    }

    #[cfg(unix)]
    #[test]
    fn a_ray_file_that_is_not_a_regular_file_is_refused_and_said_once() {
        let dir = std::env::temp_dir().join(format!("igi-rays-special-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("rays.bin");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        let (tx, rx) = std::sync::mpsc::channel();
        let path = fifo.clone();
        std::thread::spawn(move || tx.send(read_rays(&path).map_err(|e| e.to_string())));
        let e = rx
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("read_rays blocked on a FIFO")
            .unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        // Writing where a directory is: the path named once.
        let e = write_rays(&dir, &[RayRecord::default()])
            .unwrap_err()
            .to_string();
        let name = format!("'{}'", dir.display());
        assert_eq!(e.matches(&name).count(), 1, "{e}");
        assert!(e.contains("not a regular file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn random_sets_are_well_formed() {
        let scene = crate::scene::builtin::builtin_scene("cornell-box").unwrap();
        for r in random_segments(&scene, 500, 3) {
            assert!((Vec3::from(r.dir).length() - 1.0).abs() < 1e-5 && r.tmax > 0.0);
        }
        for r in random_rays(&scene, 500, 3) {
            assert!((Vec3::from(r.dir).length() - 1.0).abs() < 1e-5 && r.tmax == RAY_INFINITY);
        }
    }
}
