//! The orbit camera: rotates around a target, zooms along its view direction and pans in the view
//! plane. Y is up, as in the Stanford scans.

use glam::camera::rh::{proj::directx, view::look_at_mat4};
use glam::{Mat4, Vec3};

/// Vertical field of view: narrow enough that scans keep their proportions.
const FOVY: f32 = std::f32::consts::FRAC_PI_4;
/// Radians of rotation per CSS pixel of drag.
const ORBIT_PER_PIXEL: f32 = 0.01;
/// Pitch stays short of the poles, where yaw would flip the view.
const MAX_PITCH: f32 = std::f32::consts::FRAC_PI_2 - 0.01;
/// Distance factor per unit of wheel delta (a wheel notch is about 100 units).
const ZOOM_PER_UNIT: f32 = 0.001;

/// A camera looking at `target` from `distance` away, at angles `yaw` (around Y) and `pitch`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    target: Vec3,
    distance: f32,
    yaw: f32,
    pitch: f32,
    /// Radius of the scene the camera was fitted to: sets the clip planes and the zoom limits.
    scene_radius: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        let mut camera = OrbitCamera {
            target: Vec3::ZERO,
            distance: 1.0,
            yaw: 0.0,
            pitch: 0.0,
            scene_radius: 1.0,
        };
        camera.fit(Vec3::splat(-1.0), Vec3::splat(1.0));
        camera
    }
}

impl OrbitCamera {
    /// Frames the box `min..max` from the front (looking down −Z), slightly from above.
    pub fn fit(&mut self, min: Vec3, max: Vec3) {
        let radius = (0.5 * (max - min).length()).max(f32::MIN_POSITIVE.sqrt());
        self.target = 0.5 * (min + max);
        self.scene_radius = radius;
        self.distance = 1.1 * radius / (0.5 * FOVY).sin();
        self.yaw = 0.0;
        self.pitch = 0.2;
    }

    /// Rotates by a drag of `dx`, `dy` CSS pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * ORBIT_PER_PIXEL;
        self.pitch = (self.pitch + dy * ORBIT_PER_PIXEL).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves the target by a drag of `dx`, `dy` CSS pixels in a view `height` CSS pixels tall, so
    /// that the point under the cursor stays under it.
    pub fn pan(&mut self, dx: f32, dy: f32, height: f32) {
        let units_per_pixel = 2.0 * self.distance * (0.5 * FOVY).tan() / height.max(1.0);
        let (right, up) = self.right_up();
        self.target += (-dx * right + dy * up) * units_per_pixel;
    }

    /// Moves closer (negative `delta`) or farther (positive), as a wheel does.
    pub fn zoom(&mut self, delta: f32) {
        let r = self.scene_radius;
        self.distance = (self.distance * (delta * ZOOM_PER_UNIT).exp()).clamp(1e-3 * r, 1e3 * r);
    }

    /// Where the camera is.
    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(sy * cp, sp, cy * cp)
    }

    fn right_up(&self) -> (Vec3, Vec3) {
        let forward = (self.target - self.eye()).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        (right, right.cross(forward))
    }

    /// The view-projection matrix for a view `aspect` = width / height, with wgpu's 0..1 depth
    /// (the DirectX / WebGPU convention).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let near = (self.distance - 1.5 * self.scene_radius).max(1e-3 * self.distance);
        let far = self.distance + 1.5 * self.scene_radius;
        let proj = directx::perspective(FOVY, aspect.max(1e-3), near, far);
        proj * look_at_mat4(self.eye(), self.target, Vec3::Y)
    }
}

/// Where to pick and how far around: a spot in CSS pixels of a view `width` × `height` CSS
/// pixels, and the largest distance in CSS pixels a point may be from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PickSpot {
    /// CSS pixels from the left edge of the view.
    pub x: f32,
    /// CSS pixels from the top edge of the view.
    pub y: f32,
    /// View width, CSS pixels.
    pub width: f32,
    /// View height, CSS pixels.
    pub height: f32,
    /// Largest distance of a picked point from the spot, CSS pixels.
    pub radius: f32,
}

impl OrbitCamera {
    /// The index of the point of `xyz` (flat `x, y, z`) nearest the eye among those drawn
    /// within `spot.radius` CSS pixels of the spot, or `None`. Points drawn as discs overlap
    /// this way: the front one is the one seen.
    pub fn pick(&self, xyz: &[f32], spot: PickSpot) -> Option<usize> {
        if !(spot.width > 0.0 && spot.height > 0.0) {
            return None;
        }
        let m = self.view_proj(spot.width / spot.height);
        let r2 = spot.radius * spot.radius;
        let mut best: Option<(usize, f32)> = None;
        for (i, p) in xyz.chunks_exact(3).enumerate() {
            let clip = m * Vec3::from_slice(p).extend(1.0);
            if clip.w.is_nan() || clip.w <= 0.0 {
                continue;
            }
            let ndc = clip.truncate() / clip.w;
            if !(0.0..=1.0).contains(&ndc.z) {
                continue;
            }
            let sx = (ndc.x + 1.0) * 0.5 * spot.width - spot.x;
            let sy = (1.0 - ndc.y) * 0.5 * spot.height - spot.y;
            if sx * sx + sy * sy <= r2 && best.is_none_or(|(_, z)| ndc.z < z) {
                best = Some((i, ndc.z));
            }
        }
        best.map(|(i, _)| i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pick_finds_the_front_point_under_the_spot() {
        let mut c = OrbitCamera::default();
        c.fit(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0));
        let (w, h) = (400.0, 300.0);
        // The target is at the centre of the view; the eye looks at it along some direction
        // d: a point nearer the eye on the same ray projects to the same spot.
        let toward_eye = (c.eye() - Vec3::ZERO).normalize() * 0.5;
        let xyz = [
            0.9,
            0.9,
            0.9, // elsewhere
            0.0,
            0.0,
            0.0, // the target, behind
            toward_eye.x,
            toward_eye.y,
            toward_eye.z, // in front
        ];
        let spot = |x, y| PickSpot {
            x,
            y,
            width: w,
            height: h,
            radius: 4.0,
        };
        assert_eq!(c.pick(&xyz, spot(200.0, 150.0)), Some(2));
        assert_eq!(c.pick(&xyz[..6], spot(201.0, 152.0)), Some(1));
        // The corner point, at its projected position; nothing far from any point.
        let ndc = c.view_proj(w / h).project_point3(Vec3::splat(0.9));
        let (x, y) = ((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h);
        assert_eq!(c.pick(&xyz, spot(x, y)), Some(0));
        assert_eq!(c.pick(&xyz, spot(5.0, 5.0)), None);
        assert_eq!(
            c.pick(
                &xyz,
                PickSpot {
                    width: 0.0,
                    ..spot(1.0, 1.0)
                }
            ),
            None
        );
    }

    #[test]
    fn fitted_box_is_in_view() {
        let mut c = OrbitCamera::default();
        c.fit(Vec3::new(10.0, 20.0, 30.0), Vec3::new(12.0, 21.0, 31.0));
        let m = c.view_proj(1.5);
        for corner in [Vec3::new(10.0, 20.0, 30.0), Vec3::new(12.0, 21.0, 31.0)] {
            let p = m.project_point3(corner);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0 && (0.0..=1.0).contains(&p.z));
        }
    }
}
