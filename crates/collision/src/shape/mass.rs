//! Mass properties: volume, centre of mass and inertia tensor.

use crate::math::{outer, Isometry, Mat3, Real, Vec3};
use serde::{Deserialize, Serialize};

/// Mass, centre of mass (shape-local) and inertia tensor about the centre of mass, in the
/// shape's axes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Total mass (`density · volume`).
    pub mass: Real,
    /// Centre of mass in shape-local coordinates.
    pub center_of_mass: Vec3,
    /// Inertia tensor about the centre of mass, in the shape's local axes.
    pub inertia: Mat3,
}

impl MassProperties {
    /// Zero mass (non-volumetric shapes: triangles, planes, open meshes).
    pub const ZERO: MassProperties = MassProperties {
        mass: 0.0,
        center_of_mass: Vec3::ZERO,
        inertia: Mat3::ZERO,
    };

    /// Mass properties with a diagonal inertia.
    pub fn new(mass: Real, center_of_mass: Vec3, principal_inertia: Vec3) -> Self {
        MassProperties {
            mass,
            center_of_mass,
            inertia: Mat3::from_diagonal(principal_inertia),
        }
    }

    /// The same body seen from a parent frame in which it sits at `pose`: the centre of mass
    /// moves and the inertia tensor rotates (`R I Rᵀ`); it stays about the centre of mass.
    pub fn transformed(&self, pose: &Isometry) -> Self {
        let r = pose.rotation_matrix();
        MassProperties {
            mass: self.mass,
            center_of_mass: pose.transform_point(self.center_of_mass),
            inertia: r * self.inertia * r.transpose(),
        }
    }

    /// Inertia of this body about `point` (parallel-axis theorem), in the same axes.
    pub fn inertia_about(&self, point: Vec3) -> Mat3 {
        let d = self.center_of_mass - point;
        self.inertia + (Mat3::IDENTITY * d.length_squared() - outer(d, d)) * self.mass
    }

    /// Sums mass properties expressed in the same frame (compound bodies).
    pub fn sum<'a, I: IntoIterator<Item = &'a MassProperties>>(parts: I) -> MassProperties {
        let parts: Vec<&MassProperties> = parts.into_iter().collect();
        let mass: Real = parts.iter().map(|p| p.mass).sum();
        if mass <= 0.0 {
            return MassProperties::ZERO;
        }
        let com = parts
            .iter()
            .fold(Vec3::ZERO, |acc, p| acc + p.center_of_mass * p.mass)
            / mass;
        let inertia = parts
            .iter()
            .fold(Mat3::ZERO, |acc, p| acc + p.inertia_about(com));
        MassProperties {
            mass,
            center_of_mass: com,
            inertia,
        }
    }

    /// The mass properties of the shape mapped by the diagonal linear map `scale`
    /// (non-uniform scaling, mirrors included). Exact: the second-moment (covariance) matrix
    /// `C = ∫ x xᵀ dm` maps as `|det S| · S C S`, and `I = tr(C)·Id − C`.
    pub fn scaled(&self, scale: Vec3) -> Self {
        let det = (scale.x * scale.y * scale.z).abs();
        let s = Mat3::from_diagonal(scale);
        let trace_i = self.inertia.x_axis.x + self.inertia.y_axis.y + self.inertia.z_axis.z;
        let cov = Mat3::IDENTITY * (0.5 * trace_i) - self.inertia;
        let cov_s = s * cov * s * det;
        let trace_c = cov_s.x_axis.x + cov_s.y_axis.y + cov_s.z_axis.z;
        MassProperties {
            mass: self.mass * det,
            center_of_mass: self.center_of_mass * scale,
            inertia: Mat3::IDENTITY * trace_c - cov_s,
        }
    }
}

/// Volume, centre of mass and inertia (about the centre of mass, unit density) of the solid
/// bounded by a closed triangle mesh with outward (counter-clockwise) winding.
///
/// Sums signed tetrahedra from the origin using the canonical-tetrahedron covariance
/// (J. Blow & A. Binstock, "How to find the inertia tensor (or other mass properties) of a
/// 3D solid body represented by a triangle mesh", 2004). Returns volume 0 for a flat or empty
/// mesh. Vertices are first shifted to their mean so far-from-origin meshes stay accurate.
pub fn polyhedron_mass_properties(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
) -> (Real, MassProperties) {
    if vertices.is_empty() || triangles.is_empty() {
        return (0.0, MassProperties::ZERO);
    }
    let shift = vertices.iter().fold(Vec3::ZERO, |a, v| a + *v) / vertices.len() as Real;
    // Covariance of the canonical tetrahedron (0,0,0),(1,0,0),(0,1,0),(0,0,1).
    let c0 = Mat3::from_cols(
        Vec3::new(2.0, 1.0, 1.0),
        Vec3::new(1.0, 2.0, 1.0),
        Vec3::new(1.0, 1.0, 2.0),
    ) * (1.0 / 120.0);
    let mut volume: Real = 0.0;
    let mut first = Vec3::ZERO;
    let mut cov = Mat3::ZERO;
    for t in triangles {
        let a = vertices[t[0] as usize] - shift;
        let b = vertices[t[1] as usize] - shift;
        let c = vertices[t[2] as usize] - shift;
        let m = Mat3::from_cols(a, b, c);
        let det = m.determinant();
        volume += det / 6.0;
        first += (a + b + c) * (det / 24.0);
        cov += m * c0 * m.transpose() * det;
    }
    // Flat (or empty) solids: the volume is rounding noise relative to the mesh's size cubed.
    let size = vertices
        .iter()
        .fold(0.0 as Real, |m, v| m.max((*v - shift).abs().max_element()));
    if !volume.is_finite() || volume.abs() <= 64.0 * Real::EPSILON * size * size * size {
        return (0.0, MassProperties::ZERO);
    }
    let com = first / volume;
    // Shift covariance to the centre of mass.
    let cov_com = cov - outer(com, com) * volume;
    let trace = cov_com.x_axis.x + cov_com.y_axis.y + cov_com.z_axis.z;
    let inertia = Mat3::IDENTITY * trace - cov_com;
    (
        volume,
        MassProperties {
            mass: volume,
            center_of_mass: com + shift,
            inertia,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let v: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    (i & 1) as Real,
                    ((i >> 1) & 1) as Real,
                    ((i >> 2) & 1) as Real,
                )
            })
            .collect();
        let t = vec![
            [0, 2, 1],
            [1, 2, 3], // z = 0
            [4, 5, 6],
            [5, 7, 6], // z = 1
            [0, 1, 4],
            [1, 5, 4], // y = 0
            [2, 6, 3],
            [3, 6, 7], // y = 1
            [0, 4, 2],
            [2, 4, 6], // x = 0
            [1, 3, 5],
            [3, 7, 5], // x = 1
        ];
        (v, t)
    }

    #[test]
    fn cube_mass_properties() {
        let (v, t) = unit_cube();
        let (vol, mp) = polyhedron_mass_properties(&v, &t);
        assert!((vol - 1.0).abs() < 1e-5, "volume {vol}");
        assert!((mp.center_of_mass - Vec3::splat(0.5)).length() < 1e-5);
        let expected = 1.0 / 6.0; // m (1 + 1) / 12
        for i in 0..3 {
            assert!((mp.inertia.col(i)[i] - expected).abs() < 1e-5);
            for j in 0..3 {
                if i != j {
                    assert!(mp.inertia.col(i)[j].abs() < 1e-5);
                }
            }
        }
    }

    #[test]
    fn scaling_a_cube_gives_a_box() {
        let (v, t) = unit_cube();
        let (_, mp) = polyhedron_mass_properties(&v, &t);
        let s = Vec3::new(2.0, 3.0, -0.5);
        let scaled = mp.scaled(s);
        let vs: Vec<Vec3> = v.iter().map(|p| *p * s.abs()).collect();
        let (_, direct) = polyhedron_mass_properties(&vs, &t);
        assert!((scaled.mass - direct.mass).abs() < 1e-4);
        for i in 0..3 {
            assert!((scaled.inertia.col(i) - direct.inertia.col(i)).length() < 1e-3);
        }
    }

    #[test]
    fn sum_uses_parallel_axis() {
        let a = MassProperties::new(1.0, Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO);
        let b = MassProperties::new(1.0, Vec3::new(-1.0, 0.0, 0.0), Vec3::ZERO);
        let s = MassProperties::sum([&a, &b]);
        assert_eq!(s.mass, 2.0);
        assert!(s.center_of_mass.length() < 1e-6);
        assert!((s.inertia.y_axis.y - 2.0).abs() < 1e-6 && s.inertia.x_axis.x.abs() < 1e-6);
    }
}

#[cfg(test)]
mod small_scale_tests {
    use super::*;

    /// Regression: a volume threshold in absolute units zeroed small solids (a 1 cm cube).
    #[test]
    fn tiny_cube_keeps_its_volume() {
        let s: Real = 0.01;
        let v: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    (i & 1) as Real,
                    ((i >> 1) & 1) as Real,
                    ((i >> 2) & 1) as Real,
                ) * s
            })
            .collect();
        let t = [
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let (vol, mp) = polyhedron_mass_properties(&v, &t);
        assert!((vol - 1e-6).abs() < 1e-9, "volume {vol}");
        assert!((mp.center_of_mass - Vec3::splat(0.005)).length() < 1e-6);
        // A flat mesh still has no volume.
        let flat: Vec<Vec3> = v.iter().map(|p| Vec3::new(p.x, p.y, 0.0)).collect();
        assert_eq!(polyhedron_mass_properties(&flat, &t).0, 0.0);
    }
}
