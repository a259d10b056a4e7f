//! Unit tests of `contact_cuboid_cuboid` (kept apart to keep the module under 700 lines).

use super::*;
use crate::math::{consts::FRAC_PI_4, Quat};

/// The separating-axis test as it was, with the edge axes in a loop (runtime cyclic
/// indices) and the pose's own matrix: the oracle of the unrolled test.
fn axis_reference(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> Result<(Real, Vec3, Axis), (Real, Vec3)> {
    let f = SatFrame::new(a.half_extents(), b.half_extents(), pose_ab);
    let mut best = (Real::INFINITY, Vec3::ZERO, Axis::FaceA(0));
    let mut consider = |(overlap, dist): (Real, Real),
                        axis: &dyn Fn() -> Vec3,
                        kind: Axis|
     -> Result<(), (Real, Vec3)> {
        if overlap < -prediction || overlap.is_nan() {
            return Err((-overlap, towards_b(axis(), dist)));
        }
        if overlap < best.0 {
            best = (overlap, towards_b(axis(), dist), kind);
        }
        Ok(())
    };
    for i in 0..3 {
        consider(f.face_a(i), &|| Vec3::AXES[i], Axis::FaceA(i))?;
    }
    for j in 0..3 {
        consider(f.face_b(j), &|| f.bx[j], Axis::FaceB(j))?;
    }
    for i in 0..3 {
        for j in 0..3 {
            if let Some((overlap, dist, len)) = f.edge(i, j) {
                consider(
                    (overlap, dist),
                    &|| f.edge_axis(i, j, len),
                    Axis::Edge(i, j),
                )?;
            }
        }
    }
    Ok(best)
}

/// The unrolled test gives the loop's result bit for bit (axis, overlap, normal, or the
/// separating axis and gap): overlapping, touching, apart within and beyond the
/// prediction, parallel faces (identity and 90° turns, where edge axes vanish), 45°,
/// edge–edge crossings, thin and zero-thickness boxes, 1 km from the origin, NaN.
#[test]
fn unrolled_sat_matches_the_loop_bit_for_bit() {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let bits = |v: Vec3| v.to_array().map(Real::to_bits);
    let (mut overlaps, mut aparts, mut edges) = (0, 0, 0);
    for case in 0..30000 {
        let mut h = || Vec3::new(0.05 + rnd(), 0.05 + rnd(), 0.05 + rnd());
        let (ha, mut hb) = (h(), h());
        if case % 13 == 0 {
            hb.z = 1e-6; // (nearly) zero thickness
        } else if case % 13 == 1 {
            hb.y = 1e-3; // thin plate
        }
        let rot = match case % 6 {
            0 => Quat::IDENTITY,
            1 => Quat::from_rotation_z(crate::math::consts::FRAC_PI_2),
            2 => Quat::from_rotation_y(FRAC_PI_4),
            3 => Quat::from_rotation_x(FRAC_PI_4) * Quat::from_rotation_y(FRAC_PI_4),
            4 => Quat::from_rotation_y(1e-5 * rnd()),
            _ => Quat::from_axis_angle(
                Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize(),
                rnd() * 6.0,
            ),
        };
        let mut t = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 4.0;
        if case % 7 == 0 {
            // Face to face, exactly touching along x.
            t.x = ha.x + hb.x;
        }
        let (a, b) = (Cuboid::new(ha).unwrap(), Cuboid::new(hb).unwrap());
        let mut pose = Isometry::new(t, rot);
        if case % 5 == 0 {
            // 1 km out: the relative pose of two world poses there (with its round-off).
            let wa = Isometry::new(
                Vec3::new(1000.0, -1000.0, 1000.0),
                Quat::from_rotation_y(0.3 * rnd()),
            );
            pose = wa.inv_mul(&wa.mul(&pose));
        }
        let rot_m = pose.rotation_matrix();
        for prediction in [0.0 as Real, 0.02, 5.0] {
            let want = axis_reference(&a, &b, &pose, prediction);
            let got =
                cuboid_cuboid_axis_or_separation_mat(&a, &b, &rot_m, pose.translation, prediction);
            match (got, want) {
                (Ok((go, gn, gk)), Ok((wo, wn, wk))) => {
                    assert_eq!((go.to_bits(), bits(gn), gk), (wo.to_bits(), bits(wn), wk));
                    overlaps += 1;
                    edges += matches!(gk, Axis::Edge(..)) as usize;
                }
                (Err((gd, gn)), Err((wd, wn))) => {
                    assert_eq!((gd.to_bits(), bits(gn)), (wd.to_bits(), bits(wn)));
                    aparts += 1;
                }
                (g, w) => panic!("case {case}: {g:?} vs {w:?}"),
            }
            let public = cuboid_cuboid_axis_or_separation(&a, &b, &pose, prediction);
            assert_eq!(format!("{public:?}"), format!("{want:?}"));
        }
    }
    // The paths the test means to cover do occur.
    assert!(
        overlaps > 1000 && aparts > 1000 && edges > 100,
        "{overlaps} {aparts} {edges}"
    );
    // Non-finite input is rejected the same way.
    let (a, b) = (
        Cuboid::new(Vec3::ONE).unwrap(),
        Cuboid::new(Vec3::ONE).unwrap(),
    );
    let pose = Isometry::new(Vec3::new(Real::NAN, 0.0, 0.0), Quat::IDENTITY);
    let got = cuboid_cuboid_axis_or_separation_mat(
        &a,
        &b,
        &pose.rotation_matrix(),
        pose.translation,
        0.02,
    );
    assert!(matches!(got, Err((d, _)) if d.is_nan()));
    assert!(matches!(axis_reference(&a, &b, &pose, 0.02), Err((d, _)) if d.is_nan()));
}
