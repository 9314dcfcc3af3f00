//! Texture coordinates of object-frame points, with their analytic
//! gradients: the f64 twin of `glsl/lib/uv.glsl`.

use glam::{DVec2, DVec3};

/// How texture coordinates (u, v) are laid on an object, in its own frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum UvMapping {
    /// u = p · u_axis, v = p · v_axis (the axes' lengths set the scale).
    Planar {
        /// Gradient of u.
        u_axis: DVec3,
        /// Gradient of v.
        v_axis: DVec3,
    },
    /// u = azimuth around +y / 2π + 1/2 (azimuth 0 along +x, toward +z),
    /// v = angle from +y / π (0 at the top).
    Spherical,
    /// u as for `Spherical`, v = y.
    Cylindrical,
}

/// Texture coordinates of an object: (u, v) = mapping(p) · scale + offset.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct UvSettings {
    /// The mapping.
    pub mapping: UvMapping,
    /// Repeats per unit of the mapping's coordinates.
    pub scale: DVec2,
    /// Offset added after scaling.
    pub offset: DVec2,
}

impl Default for UvSettings {
    fn default() -> Self {
        Self { mapping: UvMapping::Spherical, scale: DVec2::ONE, offset: DVec2::ZERO }
    }
}

/// (u, v) at `p` (object frame) and the gradients ∇u, ∇v there.
pub fn object_uv(settings: &UvSettings, p: DVec3) -> (DVec2, DVec3, DVec3) {
    use std::f64::consts::PI;
    let (uv, gu, gv) = match settings.mapping {
        UvMapping::Planar { u_axis, v_axis } => (DVec2::new(p.dot(u_axis), p.dot(v_axis)), u_axis, v_axis),
        UvMapping::Spherical | UvMapping::Cylindrical => {
            let rho2 = (p.x * p.x + p.z * p.z).max(1e-300);
            let u = p.z.atan2(p.x) / (2.0 * PI) + 0.5;
            let gu = DVec3::new(-p.z, 0.0, p.x) / (2.0 * PI * rho2);
            if settings.mapping == UvMapping::Spherical {
                let r2 = p.length_squared().max(1e-300);
                let v = (p.y / r2.sqrt()).clamp(-1.0, 1.0).acos() / PI;
                let gv = -(DVec3::Y - p * (p.y / r2)) / (PI * rho2.sqrt());
                (DVec2::new(u, v), gu, gv)
            } else {
                (DVec2::new(u, p.y), gu, DVec3::Y)
            }
        }
    };
    (uv * settings.scale + settings.offset, gu * settings.scale.x, gv * settings.scale.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradients_match_finite_differences() {
        let mappings = [
            UvMapping::Planar { u_axis: DVec3::new(0.5, 0.1, 0.0), v_axis: DVec3::new(0.0, 0.2, 2.0) },
            UvMapping::Spherical,
            UvMapping::Cylindrical,
        ];
        for mapping in mappings {
            let s = UvSettings { mapping, scale: DVec2::new(3.0, 2.0), offset: DVec2::new(0.25, -0.5) };
            for p in [DVec3::new(0.3, 0.4, -0.8), DVec3::new(-1.2, -0.3, 0.5), DVec3::new(0.7, 0.9, 0.2)] {
                let (_, gu, gv) = object_uv(&s, p);
                let h = 1e-6;
                for axis in 0..3 {
                    let mut e = DVec3::ZERO;
                    e[axis] = h;
                    let d = (object_uv(&s, p + e).0 - object_uv(&s, p - e).0) / (2.0 * h);
                    assert!((d.x - gu[axis]).abs() < 1e-6, "{mapping:?} du/dp{axis}: {} vs {}", d.x, gu[axis]);
                    assert!((d.y - gv[axis]).abs() < 1e-6, "{mapping:?} dv/dp{axis}: {} vs {}", d.y, gv[axis]);
                }
            }
        }
    }

    #[test]
    fn spherical_mapping_covers_the_unit_square() {
        let s = UvSettings::default();
        assert!((object_uv(&s, DVec3::Y).0.y).abs() < 1e-12);
        assert!((object_uv(&s, -DVec3::Y).0.y - 1.0).abs() < 1e-12);
        assert!((object_uv(&s, DVec3::X).0 - DVec2::new(0.5, 0.5)).length() < 1e-12);
        assert!((object_uv(&s, DVec3::Z).0.x - 0.75).abs() < 1e-12);
    }
}
