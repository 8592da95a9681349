//! The viewer's fly camera (the paper's interactive walk through a lit interior, section
//! 5): yaw and pitch about the scene camera's up vector, movement along the view. Plain
//! CPU math, tested without a window.

use glam::Vec3;
use igi_core::scene::Camera;

/// Largest pitch, short of straight up or down where yaw is undefined.
const MAX_PITCH: f32 = 89.0 * std::f32::consts::PI / 180.0;

/// Radians of turn per pixel of mouse movement.
pub const LOOK_RADIANS_PER_PIXEL: f32 = 0.003;

/// Keys held this frame, as movement directions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Movement {
    pub forward: bool,
    pub back: bool,
    pub left: bool,
    pub right: bool,
    pub up: bool,
    pub down: bool,
    /// Five times faster.
    pub fast: bool,
}

impl Movement {
    pub fn any(&self) -> bool {
        self.forward || self.back || self.left || self.right || self.up || self.down
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub position: Vec3,
    /// Radians about `up`, 0 = the scene camera's horizontal direction.
    pub yaw: f32,
    /// Radians above the horizontal plane.
    pub pitch: f32,
    pub fov_y_deg: f32,
    /// Distance from the eye to the target written in [`FlyCamera::camera`] (the scene
    /// camera's), so a printed camera reads like the scene file's.
    focus: f32,
    /// Unit up (the scene camera's), and the horizontal frame yaw turns in.
    up: Vec3,
    ahead: Vec3,
    side: Vec3,
}

impl FlyCamera {
    pub fn new(camera: &Camera) -> FlyCamera {
        let up = camera.up.normalize();
        let view = camera.target - camera.eye;
        let dir = view.normalize();
        // The view direction's horizontal part: the axis of yaw 0. The scene loader
        // rejects an up parallel to the view, so it is not zero.
        let ahead = (dir - up * dir.dot(up))
            .try_normalize()
            .unwrap_or_else(|| up.any_orthonormal_vector());
        FlyCamera {
            position: camera.eye,
            yaw: 0.0,
            pitch: dir
                .dot(up)
                .clamp(-1.0, 1.0)
                .asin()
                .clamp(-MAX_PITCH, MAX_PITCH),
            fov_y_deg: camera.fov_y_deg,
            focus: view.length(),
            up,
            ahead,
            side: ahead.cross(up),
        }
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        (cp * (cy * self.ahead + sy * self.side) + sp * self.up).normalize()
    }

    /// Unit direction to the right of the view, horizontal.
    pub fn right(&self) -> Vec3 {
        self.forward().cross(self.up).normalize()
    }

    /// The camera the renderer looks through.
    pub fn camera(&self) -> Camera {
        Camera {
            eye: self.position,
            target: self.position + self.forward() * self.focus,
            up: self.up,
            fov_y_deg: self.fov_y_deg,
        }
    }

    /// Turn by a mouse movement of (dx, dy) pixels (right and down are positive).
    pub fn look(&mut self, dx: f32, dy: f32) {
        self.yaw = (self.yaw + dx * LOOK_RADIANS_PER_PIXEL).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch - dy * LOOK_RADIANS_PER_PIXEL).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Move for `seconds` at `speed` (scene units per second) in the held directions;
    /// returns whether the camera moved.
    pub fn fly(&mut self, m: &Movement, seconds: f32, speed: f32) -> bool {
        let axis = |plus: bool, minus: bool| plus as i32 as f32 - minus as i32 as f32;
        let dir = self.forward() * axis(m.forward, m.back)
            + self.right() * axis(m.right, m.left)
            + self.up * axis(m.up, m.down);
        let Some(dir) = dir.try_normalize() else {
            return false;
        };
        let step = seconds * speed * if m.fast { 5.0 } else { 1.0 };
        if !(step > 0.0 && step.is_finite()) {
            return false;
        }
        self.position += dir * step;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_camera() -> Camera {
        Camera {
            eye: Vec3::new(1.0, 2.0, 5.0),
            target: Vec3::new(0.0, 1.0, -1.0),
            up: Vec3::new(0.0, 2.0, 0.0),
            fov_y_deg: 45.0,
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5 * (1.0 + b.length())
    }

    #[test]
    fn starts_at_the_scene_camera() {
        let c = scene_camera();
        let fly = FlyCamera::new(&c);
        let back = fly.camera();
        assert_eq!(back.eye, c.eye);
        assert!(
            close(back.target, c.target),
            "{:?} vs {:?}",
            back.target,
            c.target
        );
        assert_eq!(back.up, Vec3::Y);
        assert_eq!(back.fov_y_deg, c.fov_y_deg);
    }

    #[test]
    fn z_up_scenes_keep_their_up() {
        let c = Camera {
            eye: Vec3::new(0.0, -5.0, 1.0),
            target: Vec3::new(0.0, 0.0, 1.0),
            up: Vec3::Z,
            fov_y_deg: 40.0,
        };
        let mut fly = FlyCamera::new(&c);
        assert!(close(fly.forward(), Vec3::Y));
        assert!(close(fly.right(), Vec3::X));
        fly.fly(
            &Movement {
                up: true,
                ..Default::default()
            },
            1.0,
            2.0,
        );
        assert!(close(fly.position, Vec3::new(0.0, -5.0, 3.0)));
    }

    #[test]
    fn moves_along_the_view_and_sideways() {
        let mut fly = FlyCamera::new(&scene_camera());
        let start = fly.position;
        let forward = fly.forward();
        let w = Movement {
            forward: true,
            ..Default::default()
        };
        assert!(fly.fly(&w, 0.5, 2.0));
        assert!(close(fly.position, start + forward));
        let fast = Movement { fast: true, ..w };
        fly.fly(&fast, 0.1, 2.0);
        assert!(close(fly.position, start + 2.0 * forward));
        let d = Movement {
            right: true,
            ..Default::default()
        };
        let before = fly.position;
        fly.fly(&d, 1.0, 1.0);
        let moved = fly.position - before;
        assert!((moved.length() - 1.0).abs() < 1e-5);
        assert!(moved.dot(forward).abs() < 1e-5 && moved.dot(Vec3::Y).abs() < 1e-5);
        // Nothing held, or opposite keys: no move.
        let still = Movement {
            left: true,
            right: true,
            ..Default::default()
        };
        assert!(!fly.fly(&still, 1.0, 1.0));
        assert!(!fly.fly(&Movement::default(), 1.0, 1.0));
    }

    #[test]
    fn looking_turns_and_stops_short_of_the_poles() {
        let mut fly = FlyCamera::new(&scene_camera());
        let f0 = fly.forward();
        // Mouse to the right turns to the right.
        fly.look(100.0, 0.0);
        let f1 = fly.forward();
        assert!(f1.dot(f0.cross(Vec3::Y)) > 0.0);
        // Mouse far up: pitch clamped, the basis stays defined.
        fly.look(0.0, -1e6);
        assert!(fly.pitch <= MAX_PITCH);
        let c = fly.camera();
        assert!((c.target - c.eye).normalize().cross(c.up).length() > 1e-3);
        fly.look(0.0, 1e6);
        assert!(fly.pitch >= -MAX_PITCH);
    }
}
