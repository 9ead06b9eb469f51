//! The camera that looks at the ocean patch, defined once: where it stands, where it looks and
//! what it sees. The `render` workload transforms every vertex with its view-projection matrix;
//! the projected grid and the fog reuse it. A camera may also move along a path in frame time
//! ([`Camera::view_at`]); [`Camera::eye`] is where it stands at t = 0.

use crate::grid::Grid;
use crate::input::InputError;
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

/// A perspective camera looking down at the centre of the patch (config key `camera`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Camera {
    /// Height above the still sea; `null` places the camera as low as it can while the whole
    /// patch, with its waves, stays in view.
    pub height: Option<f32>,
    /// How far below the horizon the camera looks at the patch's centre.
    pub pitch_degrees: f32,
    /// The vertical field of view.
    pub fov_degrees: f32,
    /// Width over height of the image.
    pub aspect: f32,
    /// How far the projected grid reaches along the sea: a ray that meets the sea beyond it, or
    /// not at all, ends at this horizontal distance from the eye; `null` is 10 × the patch's
    /// width.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub far: Option<f32>,
    /// The path the eye travels in frame time; `null` keeps it still.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub path: Option<CameraPath>,
}

/// A horizontal circle the eye travels at constant speed, keeping its heading and pitch: at
/// time t it is at `eye + radius·(cos a − 1, sin a, 0)`, a = 2π·t / `period_seconds`, so t = 0
/// is the still camera's position.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraPath {
    /// The circle's radius, in world units.
    pub radius: f32,
    /// Seconds of frame time per turn.
    pub period_seconds: f32,
}

/// Where the camera stands at one instant and the unit vectors of its frame: what the
/// projected grid casts its rays from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// The eye.
    pub eye: Vec3,
    /// The direction it looks in.
    pub forward: Vec3,
    /// The image's right, horizontal.
    pub right: Vec3,
    /// The image's up.
    pub up: Vec3,
    /// tan of half the vertical field of view.
    pub tan_half_fov: f32,
    /// Width over height of the image.
    pub aspect: f32,
    /// The horizontal distance rays are clamped to.
    pub far: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            height: None,
            pitch_degrees: 30.0,
            fov_degrees: 60.0,
            aspect: 16.0 / 9.0,
            far: None,
            path: None,
        }
    }
}

/// Most pitch: straight down (a camera at or above the horizon never sees the sea).
pub const MAX_PITCH: f32 = 90.0;
/// Fields of view stay below this (a half angle of 90° has no tangent).
pub const MAX_FOV: f32 = 180.0;
/// Most aspect ratio.
pub const MAX_ASPECT: f32 = 10.0;
/// Heights, far distances and path radii above this, in world units, are typos rather than
/// cameras (and would leave an f32 vertex no fractional digits).
pub const MAX_HEIGHT: f32 = 1e6;
/// The default far distance, in patch widths.
pub const FAR_PATCHES: f32 = 10.0;
/// How far the waves may rise above the still sea when the default height frames the patch,
/// as a fraction of the patch's width.
const WAVE_ROOM: f32 = 0.1;

impl Camera {
    /// Checks every field; the message names it and its allowed range.
    pub fn validate(&self) -> Result<(), InputError> {
        let above_zero = |field: &str, v: f32, max: f32, inclusive: bool| {
            let below = if inclusive { v <= max } else { v < max };
            if v.is_finite() && v > 0.0 && below {
                Ok(())
            } else {
                let at_most = if inclusive { "at most" } else { "below" };
                Err(InputError(format!(
                    "camera.{field}: must be above 0 and {at_most} {max}, got {v}"
                )))
            }
        };
        above_zero("pitch_degrees", self.pitch_degrees, MAX_PITCH, true)?;
        above_zero("fov_degrees", self.fov_degrees, MAX_FOV, false)?;
        above_zero("aspect", self.aspect, MAX_ASPECT, true)?;
        if let Some(h) = self.height {
            if !(h.is_finite() && h > 0.0 && h <= MAX_HEIGHT) {
                return Err(InputError(format!(
                    "camera.height: must be above 0 and at most {MAX_HEIGHT}, or null to frame the patch, got {h}"
                )));
            }
        }
        if let Some(far) = self.far {
            if !(far.is_finite() && far > 0.0 && far <= MAX_HEIGHT) {
                return Err(InputError(format!(
                    "camera.far: must be above 0 and at most {MAX_HEIGHT}, or null for {FAR_PATCHES} patch widths, got {far}"
                )));
            }
        }
        if let Some(path) = self.path {
            let r = path.radius;
            if !(r.is_finite() && (0.0..=MAX_HEIGHT).contains(&r)) {
                return Err(InputError(format!(
                    "camera.path.radius: must be 0 to {MAX_HEIGHT}, got {r}"
                )));
            }
            above_zero("path.period_seconds", path.period_seconds, MAX_HEIGHT, true)?;
        }
        Ok(())
    }

    /// Where the camera stands at frame time `t` and how it is turned, for `grid`: the still
    /// camera's eye moved along the path, looking the same way.
    pub fn view_at(&self, grid: Grid, t: f32) -> View {
        let pitch = self.pitch_degrees.to_radians();
        let (sin_p, cos_p) = pitch.sin_cos();
        let mut eye = self.eye(grid);
        if let Some(path) = self.path {
            // The angle in f64 from the fraction of a turn, so a late frame is as exact as
            // the first.
            let turns = t as f64 / path.period_seconds as f64;
            let (s, c) = (std::f64::consts::TAU * (turns - turns.floor())).sin_cos();
            let r = path.radius as f64;
            eye += Vec3::new((r * (c - 1.0)) as f32, (r * s) as f32, 0.0);
        }
        View {
            eye,
            forward: Vec3::new(0.0, cos_p, -sin_p),
            right: Vec3::X,
            up: Vec3::new(0.0, sin_p, cos_p),
            tan_half_fov: (self.fov_degrees.to_radians() / 2.0).tan(),
            aspect: self.aspect,
            far: self.far.unwrap_or(FAR_PATCHES * patch(grid).1),
        }
    }

    /// The camera's position for `grid`: on the line through the patch's centre at the pitch,
    /// at the given height or far enough back that a sphere around the patch and its waves
    /// fits the narrower field of view.
    pub fn eye(&self, grid: Grid) -> Vec3 {
        let (centre, width) = patch(grid);
        let pitch = self.pitch_degrees.to_radians();
        let distance = match self.height {
            Some(h) => h / pitch.sin(),
            None => {
                let radius = width * (0.5f32.powi(2) * 2.0 + WAVE_ROOM.powi(2)).sqrt();
                radius / (self.narrower_fov() / 2.0).sin()
            }
        };
        centre + Vec3::new(0.0, -pitch.cos(), pitch.sin()) * distance
    }

    /// The view matrix for `grid`: world (z up) to the camera's right-handed view space.
    pub fn view(&self, grid: Grid) -> Mat4 {
        Mat4::look_at_rh(self.eye(grid), patch(grid).0, Vec3::Z)
    }

    /// The view-projection matrix for `grid` (right-handed, z up, OpenGL clip depth), with the
    /// near and far planes a patch's width either side of the centre.
    pub fn view_projection(&self, grid: Grid) -> Mat4 {
        let (centre, width) = patch(grid);
        let distance = self.eye(grid).distance(centre);
        let near = (distance - width).max(distance * 1e-3);
        let far = distance + width;
        let projection =
            Mat4::perspective_rh_gl(self.fov_degrees.to_radians(), self.aspect, near, far);
        projection * self.view(grid)
    }

    /// The smaller of the vertical and horizontal fields of view, in radians.
    fn narrower_fov(&self) -> f32 {
        let vertical = self.fov_degrees.to_radians();
        let horizontal = 2.0 * ((vertical / 2.0).tan() * self.aspect).atan();
        vertical.min(horizontal)
    }
}

/// The still patch's centre and width.
fn patch(grid: Grid) -> (Vec3, f32) {
    let width = (grid.n - 1) as f32 * grid.spacing;
    (Vec3::new(width / 2.0, width / 2.0, 0.0), width)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    fn clip(c: &Camera, grid: Grid, p: Vec3) -> Vec3 {
        let v = c.view_projection(grid) * Vec4::new(p.x, p.y, p.z, 1.0);
        v.truncate() / v.w
    }

    #[test]
    fn the_default_camera_sees_the_whole_patch_and_its_waves() {
        for (n, spacing) in [(2, 1.0), (40, 1.0), (256, 1.0), (256, 3.5), (1024, 0.25)] {
            let grid = Grid::new(n, spacing).unwrap();
            let w = (n - 1) as f32 * spacing;
            for aspect in [0.5, 16.0 / 9.0, 4.0] {
                let c = Camera {
                    aspect,
                    ..Camera::default()
                };
                for x in [0.0, w] {
                    for y in [0.0, w] {
                        for z in [-WAVE_ROOM * w, WAVE_ROOM * w] {
                            let p = clip(&c, grid, Vec3::new(x, y, z));
                            assert!(
                                p.abs().max_element() <= 1.0,
                                "n {n} spacing {spacing} aspect {aspect}: corner ({x}, {y}, {z}) at {p}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_centre_is_in_the_middle_and_the_height_is_kept() {
        let grid = Grid::new(64, 2.0).unwrap();
        let c = Camera {
            height: Some(40.0),
            ..Camera::default()
        };
        let p = clip(&c, grid, Vec3::new(63.0, 63.0, 0.0));
        assert!(p.x.abs() < 1e-5 && p.y.abs() < 1e-5, "{p}");
        assert!((c.eye(grid).z - 40.0).abs() < 1e-3);
        // The near edge of the patch is lower in the image than the far edge.
        let near = clip(&c, grid, Vec3::new(63.0, 0.0, 0.0));
        let far = clip(&c, grid, Vec3::new(63.0, 126.0, 0.0));
        assert!(near.y < far.y);
    }

    #[test]
    fn a_still_camera_s_view_stands_at_its_eye_and_a_path_returns_after_a_period() {
        let grid = Grid::new(33, 1.0).unwrap();
        let still = Camera::default();
        assert_eq!(still.view_at(grid, 7.5).eye, still.eye(grid));
        assert_eq!(still.view_at(grid, 0.0).far, 320.0, "10 patch widths");
        let moving = Camera {
            path: Some(CameraPath {
                radius: 5.0,
                period_seconds: 4.0,
            }),
            ..still
        };
        let at = |t: f32| moving.view_at(grid, t).eye;
        assert_eq!(at(0.0), still.eye(grid));
        assert!(
            (at(2.0) - still.eye(grid)).length() > 9.99,
            "half a turn: the diameter"
        );
        assert!((at(4.0) - at(0.0)).length() < 1e-4);
        assert_eq!(
            moving.view_at(grid, 1.0).forward,
            still.view_at(grid, 1.0).forward
        );
    }

    #[test]
    fn every_field_out_of_range_is_named() {
        fn path(radius: f32, period_seconds: f32) -> Option<CameraPath> {
            Some(CameraPath {
                radius,
                period_seconds,
            })
        }
        /// The field named, and how the case sets it out of range in the default camera.
        type Case = (&'static str, fn(&mut Camera));
        let bad: [Case; 10] = [
            ("pitch_degrees", |c| c.pitch_degrees = 0.0),
            ("pitch_degrees", |c| c.pitch_degrees = 91.0),
            ("fov_degrees", |c| c.fov_degrees = f32::NAN),
            ("fov_degrees", |c| c.fov_degrees = 180.0),
            ("aspect", |c| c.aspect = 0.0),
            ("height", |c| c.height = Some(-1.0)),
            ("height", |c| c.height = Some(f32::INFINITY)),
            ("far", |c| c.far = Some(0.0)),
            ("path.radius", |c| c.path = path(-1.0, 1.0)),
            ("path.period_seconds", |c| c.path = path(1.0, f32::NAN)),
        ];
        let bad = bad.map(|(field, set)| {
            let mut c = Camera::default();
            set(&mut c);
            (field, c)
        });
        for (field, c) in bad {
            let e = c.validate().unwrap_err().0;
            assert!(e.starts_with(&format!("camera.{field}: must be")), "{e}");
        }
        Camera::default().validate().unwrap();
    }
}
