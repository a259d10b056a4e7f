//! Regression cases of the triangle face-on bug hunt (`bug_hunt_triangle_face_on_far` in
//! `narrowphase_polytope.rs`): triangle pairs about 1 km from the origin, found in f64 and
//! replayed against the same oracle (split from `narrowphase_polytope_regressions.rs`).

mod polytope_common;

use carom_collision::math::{Quat, Vec3};
use carom_collision::shape::{Cuboid, Shape, Triangle};
use polytope_common::*;

/// Found by `bug_hunt_triangle_face_on_far` (f64): dispatcher, triangle against convex hull: ParallelEdges, a
/// point 0.2 mm off the triangle (a vertex counted over the triangle within 1e-4 of its size).
#[test]
#[allow(clippy::excessive_precision)] // f64 values, rounded in the f32 build
fn edge_witness_off_triangle_far_1() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(-0.4533764003064282, 0.9306013703464469, 1.0855555854743233),
            Vec3::new(
                -0.9733109764762367,
                -0.044175545706320575,
                -1.1404886076732303,
            ),
            Vec3::new(-1.1932722632130965, -0.8997300719487124, 0.128790929329125),
        )
        .unwrap(),
    );
    let b = hull_of(&[
        Vec3::new(
            -0.37769533739302097,
            -0.41609382382060545,
            -0.47199017499945173,
        ),
        Vec3::new(0.8165563767260045, -0.3000601293075542, 0.20091734829758404),
        Vec3::new(0.38620019981087556, 0.10416048034662573, 0.0),
        Vec3::new(0.0, 0.0, -0.77368963193257),
        Vec3::new(
            0.4287959208896004,
            -0.40300978055263553,
            -0.09325219225878921,
        ),
        Vec3::new(0.6023931113868747, 0.0, 0.0),
    ]);
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(
            -0.20652770164190148,
            0.09927211732981085,
            -0.9726101887280763,
            0.0389971275571145,
        ),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(-0.8928064441798962, -0.3700623690445439, 0.2568082869534968),
        depth: 0.003120776648513287,
        pick: (0.0, 0.29582640304529595, -2.1791217261307394),
        far: Vec3::new(0.0, 0.0, -1000.0),
    };
    let tilt = Quat::from_xyzw(
        0.00014040787494730474,
        -7.744758704907551e-5,
        -0.0003760916835111082,
        0.9999999164212693,
    );
    check_pair_tilted(&t, &b, &pr, tilt).unwrap();
    check_pair_tilted(&b, &t, &pr, tilt).unwrap();
}
/// Found by `bug_hunt_triangle_face_on_far` (f64): dispatcher, triangle against box: ParallelEdges, a
/// point 0.2 mm off the triangle (a vertex counted over the triangle within 1e-4 of its size).
#[test]
#[allow(clippy::excessive_precision)] // f64 values, rounded in the f32 build
fn edge_witness_off_triangle_far_2() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(1.2266829676264441, 0.2829716823241127, -0.8155831802690897),
            Vec3::new(-0.6520330988376047, -0.2342257978944347, 1.3304101298550555),
            Vec3::new(0.8581252037682942, -0.22880664536208645, 1.2088294560010406),
        )
        .unwrap(),
    );
    let b = Shape::Cuboid(
        Cuboid::new(Vec3::new(
            0.9075061702812331,
            0.2342817077589264,
            0.6882330128412436,
        ))
        .unwrap(),
    );
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(
            -0.1566513523799564,
            0.1726592222414034,
            -0.0,
            0.9724449325141884,
        ),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(-0.11988627649660498, 0.1933687450883072, 0.9737740031089107),
        depth: 0.0014027398265066984,
        pick: (0.9689627207972761, 0.30927153091228043, 0.9013088791079851),
        far: Vec3::new(0.0, -691.4176668475532, 722.4552650310507),
    };
    let tilt = Quat::from_xyzw(
        -5.514672066083916e-5,
        0.0001850972939509451,
        0.0001989963280131863,
        0.9999999615491455,
    );
    check_pair_tilted(&t, &b, &pr, tilt).unwrap();
    check_pair_tilted(&b, &t, &pr, tilt).unwrap();
}

/// Found by `bug_hunt_triangle_face_on_far` (f64): dispatcher, box against triangle: overlap 0.00020737086481403821 but no contact.
/// The triangle–box SAT measured an edge axis's gap with the triangle's edge alone, while
/// within its Gauss-map tolerance the opposite vertex stuck out 0.2 mm further along the
/// nearly parallel axis: a false gap, no contact. Now the true extent is used.
#[test]
#[allow(clippy::excessive_precision)] // f64 values, rounded in the f32 build
fn lost_contact_triangle_box_1() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(1.4113981812897827, 0.34300224840275784, 0.37457259836051415),
            Vec3::new(-1.1262568351993063, 0.6613301899084245, 0.7376909387287678),
            Vec3::new(0.7203220530470427, -0.8606744677527722, -0.9951761655368236),
        )
        .unwrap(),
    );
    let b = Shape::Cuboid(
        Cuboid::new(Vec3::new(0.8766197232859694, 0.05, 0.15953906759677555)).unwrap(),
    );
    let pr = Params {
        kind: Kind::FaceOn,
        rot_a: Quat::from_xyzw(
            0.2780492189262605,
            0.6752311904821731,
            0.0,
            0.6831921188469051,
        ),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(0.0, 0.0, -1.0),
        depth: 0.001,
        pick: (0.536487054771697, 0.2868307929021842, -0.43251688780116615),
        far: Vec3::new(0.0, 0.0, 1000.0),
    };
    let tilt = Quat::from_xyzw(
        8.410151425412127e-5,
        1.604951375881161e-5,
        -0.00013849083354713072,
        0.9999999867448186,
    );
    check_pair_tilted(&t, &b, &pr, tilt).unwrap();
    check_pair_tilted(&b, &t, &pr, tilt).unwrap();
}
/// Found by `bug_hunt_triangle_face_on_far` (f64): dispatcher, triangle against box: overlap 0.00022456567005946226 but no contact.
/// The triangle–box SAT measured an edge axis's gap with the triangle's edge alone, while
/// within its Gauss-map tolerance the opposite vertex stuck out 0.2 mm further along the
/// nearly parallel axis: a false gap, no contact. Now the true extent is used.
#[test]
#[allow(clippy::excessive_precision)] // f64 values, rounded in the f32 build
fn lost_contact_triangle_box_2() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(1.05910072744783, 0.9839243688356629, 0.40024803001491494),
            Vec3::new(0.27955024423136793, 1.2546983436137058, 0.7730353985964719),
            Vec3::new(0.4344200444434786, -1.0382447085069506, -0.9916285344034041),
        )
        .unwrap(),
    );
    let b = Shape::Cuboid(
        Cuboid::new(Vec3::new(0.05, 0.8549889535549564, 0.7996591423691379)).unwrap(),
    );
    let pr = Params {
        kind: Kind::FaceOn,
        rot_a: Quat::from_xyzw(
            0.2433461090766029,
            -0.7079102739908003,
            0.11579176368748198,
            0.652869039423444,
        ),
        rot_b: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        dir: Vec3::new(0.7027299807911368, -0.7114566565134438, 0.0),
        depth: 0.001,
        pick: (0.0, 0.0, 1.4322826108526385),
        far: Vec3::new(0.0, 0.0, -1000.0),
    };
    let tilt = Quat::from_xyzw(
        -8.722906481467667e-5,
        0.00017388855712175945,
        -6.855173906997991e-5,
        0.9999999787272593,
    );
    check_pair_tilted(&t, &b, &pr, tilt).unwrap();
    check_pair_tilted(&b, &t, &pr, tilt).unwrap();
}
