//! Unit tests of `contact_cuboid_cuboid` (kept apart to keep the module under 700 lines).

use super::*;
use crate::math::Quat;

/// The clip as it was before the per-corner distances and the skipped all-inside
/// passes: every pass recomputes both ends' distances and rebuilds the polygon.
fn clip_reference(
    hr: Vec3,
    rf: usize,
    hi: Vec3,
    pose_ri: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    let i = rf / 2;
    let sign: Real = if rf.is_multiple_of(2) { 1.0 } else { -1.0 };
    let mut nr = Vec3::ZERO;
    nr[i] = sign;
    let rot = pose_ri.rotation_matrix();
    let axes = [rot.x_axis, rot.y_axis, rot.z_axis];
    let (hi, hr) = (hi.to_array(), hr.to_array());
    let col = |k: usize| axes[k].to_array()[i].abs();
    let mut j = 0;
    for k in 1..3 {
        if col(k) > col(j) {
            j = k;
        }
    }
    let facing_away = axes[j].to_array()[i] * sign > 0.0;
    let inc_face = 2 * j + facing_away as usize;
    let m = if facing_away { -axes[j] } else { axes[j] };
    let centre = pose_ri.translation + m * hi[j];
    let (k1, k2) = ((j + 1) % 3, (j + 2) % 3);
    let (u, v) = (axes[k1] * hi[k1], axes[k2] * hi[k2]);
    let id = ((inc_face as u32 & 0xFF) << 16) | 0xFF;
    let mut poly: Vec<([Real; 3], u32)> = BOX_LOOPS[4 * inc_face..4 * inc_face + 4]
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let su = if c & (1 << k1) != 0 { u } else { -u };
            let sv = if c & (1 << k2) != 0 { v } else { -v };
            (
                (centre + (su + sv)).to_array(),
                id | ((k as u32 & 0xFF) << 8),
            )
        })
        .collect();
    for (tag, &(k, s)) in (0u32..).zip(&SIDE_PLANES[rf]) {
        {
            let limit = hr[k];
            let mut next_poly = Vec::new();
            let n = poly.len();
            for e in 0..n {
                let (p, ip) = poly[e];
                let (q, _) = poly[if e + 1 == n { 0 } else { e + 1 }];
                let (dp, dq) = (s * p[k] - limit, s * q[k] - limit);
                if dp <= 0.0 {
                    next_poly.push((p, ip));
                }
                if (dp < 0.0) != (dq < 0.0) && dp != dq {
                    let t = dp / (dp - dq);
                    let (pv, qv) = (Vec3::from_array(p), Vec3::from_array(q));
                    next_poly.push(((pv + (qv - pv) * t).to_array(), (ip & 0xFFFF_FF00) | tag));
                }
            }
            if next_poly.len() > CLIP_CAP {
                return;
            }
            poly = next_poly;
            if poly.is_empty() {
                return;
            }
        }
    }
    for (p, fid) in poly {
        let d = sign * p[i] - hr[i];
        if d <= prediction {
            let p = Vec3::from_array(p);
            out.push((
                Contact {
                    distance: d,
                    point_a: p - nr * d,
                    point_b: p,
                    normal: nr,
                },
                fid,
            ));
        }
    }
}

/// The clip gives the reference clip's points and ids bit for bit: faces fully inside
/// the reference face (the skipped passes), missing it, overhanging on one or more
/// sides, crossing, touching a side plane exactly, rotated 45°, thin and zero-thickness
/// boxes, 1 km out.
#[test]
fn clip_matches_the_reference_bit_for_bit() {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let (mut skipped_all, mut missed) = (0, 0);
    for case in 0..20000 {
        let far = if case % 3 == 0 { 1000.0 } else { 0.0 };
        let h = |r: &mut dyn FnMut() -> Real| {
            Vec3::new(0.05 + 2.0 * r(), 0.05 + 2.0 * r(), 0.05 + 2.0 * r())
        };
        let hr = h(&mut rnd);
        let mut hi = h(&mut rnd);
        if case % 11 == 0 {
            hi.y = 0.0; // a zero-thickness incident box
        }
        let rf = (6.0 * rnd()) as usize % 6;
        let rot = match case % 5 {
            0 => Quat::IDENTITY,
            1 => Quat::from_rotation_y(crate::math::consts::FRAC_PI_4),
            2 => Quat::from_rotation_y(rnd() * 6.0) * Quat::from_rotation_x(1e-4 * rnd()),
            _ => Quat::from_axis_angle(
                Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize(),
                rnd() * 6.0,
            ),
        };
        let mut t = Vec3::new(
            (rnd() - 0.5) * 4.0,
            (rnd() - 0.5) * 4.0,
            (rnd() - 0.5) * 4.0,
        );
        let axis = rf / 2;
        if case % 7 == 0 {
            // Exactly on a side plane: corners with distance zero.
            t[(axis + 1) % 3] = hr[(axis + 1) % 3];
        }
        t[axis] += far;
        let pose = Isometry::new(t, rot);
        let hr_far = {
            let mut v = hr;
            v[axis] += far;
            v
        };
        for prediction in [0.02 as Real, 10.0] {
            let (mut got, mut want) = (Vec::new(), Vec::new());
            let rot = pose.rotation_matrix();
            clip_box_faces(hr_far, rf, hi, &rot, &pose, prediction, 0, &mut got);
            clip_reference(hr_far, rf, hi, &pose, prediction, &mut want);
            assert_eq!(got.len(), want.len(), "case {case}");
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(g.1, w.1, "case {case}");
                let bits = |c: &Contact| {
                    [c.point_a, c.point_b, c.normal].map(|v| v.to_array().map(Real::to_bits))
                };
                assert_eq!(bits(&g.0), bits(&w.0), "case {case}");
                assert_eq!(g.0.distance.to_bits(), w.0.distance.to_bits());
            }
            if prediction > 1.0 && got.len() == 4 && got.iter().all(|c| c.1 & 0xFF == 0xFF) {
                skipped_all += 1;
            }
            missed += (prediction > 1.0 && got.is_empty()) as usize;
        }
    }
    // Incident faces fully inside the reference face occur (the skipped passes run).
    assert!(skipped_all > 100, "{skipped_all}");
    // Faces that miss (a pass with every corner outside ends the clip) occur too.
    assert!(missed > 100, "{missed}");
}
/// `Mat3::from_quat` of the inverse (conjugate) quaternion is the transpose of the
/// quaternion's matrix bit for bit (what `clip_face_b` relies on): random, axis-aligned,
/// 45°, tiny-angle and unnormalised-by-round-off rotations.
#[test]
fn transpose_is_the_inverse_matrix() {
    let mut seed = 0x1234_5678_9abc_def1_u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let mut quats = vec![
        Quat::IDENTITY,
        Quat::from_rotation_x(crate::math::consts::FRAC_PI_2),
        Quat::from_rotation_y(crate::math::consts::FRAC_PI_4),
        Quat::from_rotation_z(1e-6),
        -Quat::IDENTITY,
    ];
    for _ in 0..20000 {
        let q = Quat::from_xyzw(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
        quats.push(q.normalize());
        // A product of rotations, as `inv_mul` forms it.
        quats.push((q.normalize() * quats[quats.len() - 2]).normalize());
    }
    let bits = |m: Mat3| m.to_cols_array().map(Real::to_bits);
    for q in quats {
        let pose = Isometry::new(Vec3::ZERO, q);
        assert_eq!(
            bits(pose.inverse().rotation_matrix()),
            bits(pose.rotation_matrix().transpose()),
            "{q}"
        );
    }
}

/// `clip_face_b` gives, bit for bit, what it gave when it clipped with
/// `pose_ab.inverse()`'s own matrix and mapped each point's normal: the reference clip
/// in B's frame, mapped back to A's frame per point. Rotated, 45°, touching, thin boxes,
/// 1 km out.
#[test]
fn clip_face_b_matches_the_reference_bit_for_bit() {
    let mut seed = 0x0dd_b1a5_e5ba_d5ee_u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let mut nonempty = 0;
    for case in 0..20000 {
        let mut h = || Vec3::new(0.05 + rnd(), 0.05 + rnd(), 0.05 + rnd());
        let (ha, mut hb) = (h(), h());
        if case % 9 == 0 {
            hb.x = 1e-3;
        }
        let fb = (6.0 * rnd()) as usize % 6;
        let rot = match case % 4 {
            0 => Quat::IDENTITY,
            1 => Quat::from_rotation_y(crate::math::consts::FRAC_PI_4),
            _ => Quat::from_axis_angle(
                Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize(),
                rnd() * 6.0,
            ),
        };
        // B's centre so that A lies (roughly) over B's face `fb`.
        let mut nb = Vec3::ZERO;
        nb[fb / 2] = if fb.is_multiple_of(2) { 1.0 } else { -1.0 };
        let gap = if case % 5 == 0 {
            0.0
        } else {
            (rnd() - 0.7) * 0.2
        };
        let off = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.5;
        // A in B's frame, then B in A's frame.
        let a_in_b = Isometry::new(nb * (hb[fb / 2] + ha.max_element() + gap) + off, rot);
        let mut pose_ab = a_in_b.inverse();
        if case % 3 == 0 {
            let wa = Isometry::new(
                Vec3::new(-1000.0, 1000.0, 1000.0),
                Quat::from_rotation_x(rnd()),
            );
            pose_ab = wa.inv_mul(&wa.mul(&pose_ab));
        }
        for prediction in [0.02 as Real, 1.0] {
            let mut got = Vec::new();
            clip_face_b(
                ha,
                hb,
                fb,
                &pose_ab.rotation_matrix(),
                &pose_ab,
                prediction,
                &mut got,
            );
            let mut raw = Vec::new();
            clip_reference(hb, fb, ha, &pose_ab.inverse(), prediction, &mut raw);
            let (r, t) = (pose_ab.rotation_matrix(), pose_ab.translation);
            let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
            let want: Vec<_> = raw
                .iter()
                .map(|(c, id)| {
                    let c = Contact {
                        distance: c.distance,
                        point_a: r * c.point_b + t,
                        point_b: r * c.point_a + t,
                        normal: r * -c.normal,
                    };
                    (c, id | id_base)
                })
                .collect();
            assert_eq!(got.len(), want.len(), "case {case}");
            let bits = |c: &Contact| {
                [c.point_a, c.point_b, c.normal].map(|v| v.to_array().map(Real::to_bits))
            };
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(g.1, w.1, "case {case}");
                assert_eq!(bits(&g.0), bits(&w.0), "case {case}");
                assert_eq!(g.0.distance.to_bits(), w.0.distance.to_bits());
            }
            nonempty += !got.is_empty() as usize;
        }
    }
    assert!(nonempty > 5000, "{nonempty}");
}

/// The box clip is the general polyhedron clipper (`clip_faces` on the boxes as
/// polyhedra) specialised: the same points (to round-off), the same ids, in the same
/// order. The order matters to the solver, which sweeps a manifold's points in turn: with
/// the incident corners listed one way round for every face (the first version of this
/// clip), the release-mode 20-row pyramid of `pipeline_stacking` crept 2.2 cm in 2000
/// steps; in the polyhedron's outward loop order it creeps 0.7 cm, as before the clip.
#[test]
fn clip_matches_the_polyhedron_clipper_in_order() {
    let mut seed = 0x005e_ed0f_c11f_u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let mut compared = 0;
    for case in 0..20000 {
        let far = if case % 3 == 0 { 1000.0 } else { 0.0 };
        let mut h = || Vec3::new(0.05 + rnd(), 0.05 + rnd(), 0.05 + rnd());
        let (hr, hi) = (h(), h());
        let rf = (6.0 * rnd()) as usize % 6;
        let rot = match case % 4 {
            0 => Quat::IDENTITY,
            1 => Quat::from_rotation_y(rnd() * 6.0) * Quat::from_rotation_x(1e-4 * rnd()),
            _ => Quat::from_axis_angle(
                Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize(),
                rnd() * 6.0,
            ),
        };
        let mut nr = Vec3::ZERO;
        nr[rf / 2] = if rf.is_multiple_of(2) { 1.0 } else { -1.0 };
        let off = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 1.5;
        // 1 km out: the reference face (and the incident box over it) 1 km from the
        // reference box's centre.
        let mut hr_far = hr;
        hr_far[rf / 2] += far;
        let t = nr * (hr_far[rf / 2] + hi.min_element() * 0.5) + off;
        let pose = Isometry::new(t, rot);
        let cuboid = |h: Vec3| crate::shape::Cuboid::new(h).unwrap();
        let (pr, pi) = (
            Polyhedron::from_cuboid(&cuboid(hr_far)),
            Polyhedron::from_cuboid(&cuboid(hi)),
        );
        for prediction in [0.02 as Real, 10.0] {
            let (mut got, mut want) = (Vec::new(), Vec::new());
            clip_box_faces(
                hr_far,
                rf,
                hi,
                &pose.rotation_matrix(),
                &pose,
                prediction,
                0,
                &mut got,
            );
            super::super::polyhedron::clip_faces(&pr, rf, &pi, &pose, prediction, 0, &mut want);
            if got.is_empty() {
                // The general clipper then falls back to one vertex; the box caller
                // takes the guided path instead.
                assert!(want.iter().all(|w| w.1 & 0xFFFF == 0xFEFF), "case {case}");
                continue;
            }
            // The two clippers round differently (a coordinate against a plane through
            // an edge): points made by a clip of a nearly parallel edge differ most.
            let scale = 1.0 + far;
            assert_eq!(got.len(), want.len(), "case {case}");
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(g.1, w.1, "case {case}");
                assert!(
                    (g.0.point_b - w.0.point_b).length() <= 1e-4 * scale,
                    "case {case}: {g:?} vs {w:?}"
                );
                assert!(
                    (g.0.distance - w.0.distance).abs() <= 1e-4 * scale,
                    "case {case}"
                );
            }
            compared += 1;
        }
    }
    assert!(compared > 10000, "{compared}");
}
