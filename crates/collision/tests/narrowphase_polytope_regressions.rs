//! Regression cases of the polytope oracle's bug hunts (`narrowphase_polytope.rs`): each
//! configuration proptest found, replayed against the same oracle.

mod polytope_common;

use carom_collision::math::{Quat, Vec3};
use carom_collision::shape::{Cuboid, Shape, Triangle};
use polytope_common::*;

/// Found by `bug_hunt_random_triangle_pairs`: a thin box touching a triangle (as B) 1 km
/// from the origin. The full SAT clipped on one face and added the deepest vertex along the
/// other shape's face ("one normal per manifold"); the deepest vertex now comes from the
/// reference face the points were clipped on.
#[test]
fn regression_box_touching_triangle_far() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(0.90056473, -1.1995764, 0.0),
            Vec3::new(0.90151817, 1.1413507, 0.36685637),
            Vec3::new(0.46734893, -1.301248, 0.581669),
        )
        .unwrap(),
    );
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.31747034, 0.8892618, 0.075741194)).unwrap());
    let pr = Params {
        kind: Kind::Touching,
        rot_a: Quat::from_xyzw(0.044358917, 0.013030494, -0.012803791, 0.9988486).normalize(),
        rot_b: Quat::from_xyzw(-0.2071759, 0.17371134, 0.030773124, 0.96226585).normalize(),
        dir: Vec3::new(0.4270909, 0.0, 0.90420866),
        depth: 0.001,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(772.96246, 634.45184, 0.0),
    };
    check_pair(&b, &t, &pr).unwrap();
    check_pair(&t, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against box: one normal per manifold
#[test]
fn guided_one_normal_hull_box_1() {
    let a = hull_of(&[
        Vec3::new(0.24765214, -0.55863523, 0.6661776),
        Vec3::new(0.0, 0.0, -0.4),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::new(-0.2678933, 0.07167182, 0.64118165),
        Vec3::new(-0.4, 0.0, 0.0),
        Vec3::new(-0.57762504, 0.5831844, 0.4051246),
    ]);
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.33123708, 0.17407466, 0.05)).unwrap());
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(0.29654852, 0.34184483, 0.89174044),
        depth: 0.033365354,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: full SAT, box against triangle: one normal per manifold
#[test]
fn full_sat_one_normal_box_triangle_1() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(-0.98866665, 1.1280683, 0.0),
            Vec3::new(-0.40096244, -1.4324086, 0.19348037),
            Vec3::new(-0.63061494, -0.99710417, -0.9263411),
        )
        .unwrap(),
    );
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.7941154, 0.7362162, 0.05)).unwrap());
    let pr = Params {
        kind: Kind::Touching,
        rot_a: Quat::from_xyzw(-0.41608217, -0.21637352, 0.0, 0.883209),
        rot_b: Quat::from_xyzw(0.04450508, -0.04017817, 0.11958779, 0.9910115),
        dir: Vec3::new(-0.7335646, 0.0, 0.6796197),
        depth: 0.001,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(346.80176, 937.9385, 0.0),
    };
    check_pair(&t, &b, &pr).unwrap();
    check_pair(&b, &t, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, box against convex hull: one normal per manifold
#[test]
fn guided_one_normal_box_hull_1() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.9657091, 0.05, 0.1858526)).unwrap());
    let b = hull_of(&[
        Vec3::new(0.54734004, 0.21837048, 0.533274),
        Vec3::new(0.0, 0.0, -0.4),
        Vec3::new(0.0, 0.6773449, 0.0),
        Vec3::new(-0.31589147, 0.24538253, 0.0),
        Vec3::new(0.18976665, 0.37855726, 0.43276086),
    ]);
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, -0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(-0.22939055, 0.78433526, 0.5372787, 0.20863804),
        dir: Vec3::new(0.0, -0.9865007, 0.16375695),
        depth: 0.047515653,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against triangle: Random: manifold depth 0.0370277762413
#[test]
fn deepest_vertex_wrong_face_depth_hull_triangle_1() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(1.197696, -0.57173073, 0.6990341),
            Vec3::new(-0.07567707, -0.58330107, 1.379867),
            Vec3::new(-0.7074971, -0.090187654, 1.3195887),
        )
        .unwrap(),
    );
    let b = hull_of(&[
        Vec3::new(-0.52121776, -0.179258, 0.42746723),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::new(0.76555973, -0.567598, 0.0),
        Vec3::new(0.7699532, 0.0, 0.61479974),
        Vec3::new(-0.10483856, -0.03652037, 0.5850515),
    ]);
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(-0.74770343, 0.27061635, 0.09030265, 0.5996264),
        dir: Vec3::new(-0.41213912, -0.72975135, 0.54553115),
        depth: 0.038325697,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, -0.0, 0.0),
    };
    check_pair(&t, &b, &pr).unwrap();
    check_pair(&b, &t, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, box against box: FaceOn: point_a [0.3221399188041687, 0.391667544841
#[test]
fn box_box_touching_edge_axis_witness_2() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.62482464, 0.6427038, 0.05)).unwrap());
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.36318362, 0.93619996, 0.05)).unwrap());
    let pr = Params {
        kind: Kind::FaceOn,
        rot_a: Quat::from_xyzw(0.6692226, 0.47576916, 0.53600353, 0.19617641),
        rot_b: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        dir: Vec3::new(-0.5642373, 0.0, -0.8256127),
        depth: 0.001,
        pick: (0.3734916, 0.9414248, -1.7277744),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: full SAT, box against triangle: one normal per manifold
#[test]
fn full_sat_one_normal_box_triangle_2() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(-0.7804851, -0.7778118, -1.0177683),
            Vec3::new(-0.61017185, 0.0, -1.3702884),
            Vec3::new(-0.5531547, -0.9405564, -1.029259),
        )
        .unwrap(),
    );
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.05, 0.66514397, 0.062121633)).unwrap());
    let pr = Params {
        kind: Kind::Touching,
        rot_a: Quat::from_xyzw(-0.19006754, 0.3401035, 0.39922708, 0.8299528),
        rot_b: Quat::from_xyzw(-0.4344042, 0.6612572, -0.34991184, 0.5015911),
        dir: Vec3::new(0.0, 1.0, 0.0),
        depth: 0.001,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -1000.0),
    };
    check_pair(&t, &b, &pr).unwrap();
    check_pair(&b, &t, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against convex hull: one normal per manifold
#[test]
fn guided_one_normal_hull_hull_1() {
    let a = hull_of(&[
        Vec3::new(0.27614498, 0.13821599, 0.68606687),
        Vec3::new(0.54153806, -0.5069066, -0.45970544),
        Vec3::new(0.0, 0.0, -0.4),
        Vec3::new(-0.4, 0.0, 0.0),
        Vec3::new(0.26963627, -0.3930321, 0.15669186),
        Vec3::new(0.18379098, -0.28025702, 0.43302882),
    ]);
    let b = hull_of(&[
        Vec3::new(-0.7136289, -0.029328309, -0.62735933),
        Vec3::new(0.0, -0.06587754, -0.79983485),
        Vec3::new(0.0, -0.50170505, 0.68643194),
        Vec3::new(0.0, 0.0, 0.4),
        Vec3::new(0.0, 0.0, -0.39999998),
    ]);
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(0.47861472, -0.022176083, -0.5548172, 0.68015736),
        dir: Vec3::new(0.656863, -0.5732837, 0.48977226),
        depth: 0.03631398,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: full SAT, convex hull against convex hull: ParallelEdges: point_a [-0.5056602954
#[test]
fn full_sat_parallel_edges_deepest_vertex_hull_hull_1() {
    let a = hull_of(&[
        Vec3::new(0.28878215, 0.0, 0.2767759),
        Vec3::new(-0.5075998, -0.20797932, 0.70928097),
        Vec3::new(0.13351133, -0.23484953, -0.29499227),
        Vec3::new(0.38642645, 0.4504412, 0.0),
        Vec3::new(-0.31967658, 0.3773566, -0.41865525),
        Vec3::new(0.0, 0.0, -0.51751477),
        Vec3::new(0.043573312, -0.3105365, -0.71103853),
        Vec3::new(-0.1539801, -0.09079404, -0.5476603),
        Vec3::new(-0.21364947, 0.19937211, 0.31694654),
        Vec3::new(-0.36781797, 0.06720847, -0.14210199),
        Vec3::new(0.0, 0.4, 0.0),
    ]);
    let b = hull_of(&[
        Vec3::new(0.50665253, 0.6955039, 0.0),
        Vec3::new(-0.45839736, -0.48566893, 0.48374847),
        Vec3::new(0.0, -0.46291742, -0.22608605),
        Vec3::new(-0.1593665, 0.65649897, 0.0),
        Vec3::new(0.08213482, 0.0, -0.9634006),
        Vec3::new(-0.28461424, -0.3053991, -0.027383469),
        Vec3::new(0.34750772, 0.6994296, -0.38519478),
        Vec3::new(0.33956972, 0.0, -0.40460694),
    ]);
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(0.0, -0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        dir: Vec3::new(-0.06872098, 0.24131179, -0.9680114),
        depth: 0.049164195,
        pick: (0.34145945, 0.4528423, -1.8224347),
        far: Vec3::new(0.0, -1000.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: full SAT, convex hull against box: ParallelEdges: manifold depth 0.0213708169758
#[test]
fn deepest_vertex_wrong_face_depth_hull_box_1() {
    let a = hull_of(&[
        Vec3::new(-0.6167033, 0.0, -0.11332993),
        Vec3::new(0.0, 0.54465306, 0.2760534),
        Vec3::new(0.11147297, 0.0, -0.55757225),
        Vec3::new(-0.1692049, -0.3085713, -0.19014055),
        Vec3::new(0.09319355, -0.4023561, -0.87834764),
        Vec3::new(0.25599012, 0.30735824, 0.0),
        Vec3::new(-0.044841032, 0.2903047, 0.3099444),
    ]);
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.42312983, 0.05, 0.8774479)).unwrap());
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(0.0, 0.6745851, -0.73819715),
        depth: 0.039330762,
        pick: (0.32170278, 0.0, 2.092035),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, box against convex hull: one normal per manifold
#[test]
fn guided_one_normal_box_hull_2() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.05, 0.9005586, 0.7139295)).unwrap());
    let b = hull_of(&[
        Vec3::new(-0.13208297, -0.08381706, 0.837136),
        Vec3::new(-0.36881727, -0.15483485, 0.0),
        Vec3::new(0.49272844, 0.0, 0.0),
        Vec3::new(-0.45824894, 0.6931195, -0.41240928),
        Vec3::new(0.0, 0.33744827, -0.89297384),
        Vec3::new(0.29004586, 0.2754513, 0.0),
        Vec3::new(-0.54239774, 0.0, 0.3361367),
        Vec3::new(-0.35280472, 0.31769046, 0.1936215),
        Vec3::new(0.0, 0.2826826, 0.30176595),
        Vec3::new(0.3080872, 0.0, -0.25511226),
        Vec3::new(0.0, 0.0, -0.46038204),
        Vec3::new(0.0, 0.39972433, -0.014848188),
    ]);
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(0.0, -0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        dir: Vec3::new(-0.72559714, 0.0, -0.68811977),
        depth: 0.027457105,
        pick: (0.764281, 0.17993331, 1.8952795),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, box against convex hull: one normal per manifold
#[test]
fn guided_one_normal_box_hull_3() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.05, 0.67245704, 0.44343662)).unwrap());
    let b = hull_of(&[
        Vec3::new(-0.5871228, -0.4093587, -0.5397548),
        Vec3::new(-0.47873804, 0.0, 0.38347262),
        Vec3::new(0.73743886, 0.37030944, -0.11205128),
        Vec3::new(0.41111976, -0.8137041, 0.35001978),
        Vec3::new(0.466623, 0.0, -0.27717435),
        Vec3::new(0.5230338, -0.26775295, 0.57504976),
        Vec3::new(0.9280925, 0.2947003, 0.0),
        Vec3::new(0.48042345, 0.30451456, 0.39450482),
    ]);
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        dir: Vec3::new(0.15294345, 0.988235, 0.0),
        depth: 0.027846111,
        pick: (0.4125188, 0.9160327, 1.8261218),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against convex hull: one normal per manifold
#[test]
fn guided_one_normal_hull_hull_2() {
    let a = hull_of(&[
        Vec3::new(-0.52477014, -0.031326827, -0.57422036),
        Vec3::new(0.79697883, -0.069251426, -0.44250777),
        Vec3::new(-0.29078025, -0.6036774, -0.062440738),
        Vec3::new(0.0, 0.0, 0.39999998),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::new(-0.4, 0.0, 0.0),
    ]);
    let b = hull_of(&[
        Vec3::new(0.0, 0.0, -0.9880938),
        Vec3::new(-0.6463167, 0.64418375, 0.32402012),
        Vec3::new(0.0, 0.0, 0.8566885),
        Vec3::new(0.0, -0.20759793, -0.8106614),
        Vec3::new(-0.5359196, 0.40135875, -0.53047174),
    ]);
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(0.6578036, -0.60327053, -0.41665697, 0.17249994),
        dir: Vec3::new(0.0, -0.41190568, -0.91122645),
        depth: 0.019103086,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, triangle against convex hull: Random: manifold depth 0.0100328922271
#[test]
fn deepest_vertex_wrong_face_depth_triangle_hull_1() {
    let t = Shape::Triangle(
        Triangle::new(
            Vec3::new(-1.1521513, 0.90898716, 0.3103057),
            Vec3::new(-1.0987101, -0.8720391, -0.5313984),
            Vec3::new(0.6593411, -1.0949436, 0.785091),
        )
        .unwrap(),
    );
    let b = hull_of(&[
        Vec3::new(-0.6491847, 0.16646156, -0.48191503),
        Vec3::new(0.8970559, -0.018412935, -0.29252946),
        Vec3::new(0.0, 0.0, 0.4),
        Vec3::new(-0.36904767, 0.9104688, 0.0),
        Vec3::new(0.419678, 0.36526084, -0.16367227),
    ]);
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(-0.28621253, -0.26554328, 0.18309799, 0.90224403),
        dir: Vec3::new(-0.6927196, -0.721207, 0.0),
        depth: 0.038171746,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&t, &b, &pr).unwrap();
    check_pair(&b, &t, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, box against convex hull: one normal per manifold
#[test]
fn guided_one_normal_box_hull_4() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.05, 0.6288772, 0.6929274)).unwrap());
    let b = hull_of(&[
        Vec3::new(0.39552742, 0.0, 0.77825034),
        Vec3::new(-0.10048938, 0.36249077, -0.13602324),
        Vec3::new(0.121196665, -0.36835468, 0.098113246),
        Vec3::new(-0.1647456, -0.60122126, -0.6070519),
        Vec3::new(0.34195584, 0.33148205, 0.21779092),
        Vec3::new(0.13781382, 0.54402715, 0.2429392),
    ]);
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(1.0, 0.0, 0.0),
        depth: 0.029657334,
        pick: (0.24750648, 0.62299806, -2.228936),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against box: one normal per manifold
#[test]
fn guided_one_normal_hull_box_2() {
    let a = hull_of(&[
        Vec3::new(0.121778905, 0.58126795, -0.022288363),
        Vec3::new(-0.59584767, 0.49154624, 0.0),
        Vec3::new(-0.25487554, -0.41096258, 0.57280415),
        Vec3::new(0.48524946, 0.0, -0.5485025),
        Vec3::new(0.4110417, -0.15364985, 0.3315727),
        Vec3::new(-0.16964318, -0.67674017, 0.6530887),
        Vec3::new(-0.4779623, 0.0, -0.07218233),
        Vec3::new(0.0, -0.4, 0.0),
        Vec3::new(0.0, 0.0, -0.39999998),
    ]);
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.63882613, 0.18720892, 0.05)).unwrap());
    let pr = Params {
        kind: Kind::ParallelEdges,
        rot_a: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(-0.98909616, 0.14727142, 0.0),
        depth: 0.041604083,
        pick: (0.15323675, 0.0, 1.0366669),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against box: one normal per manifold
#[test]
fn guided_one_normal_hull_box_3() {
    let a = hull_of(&[
        Vec3::new(-0.4960641, 0.06532061, -0.83668905),
        Vec3::new(0.0, 0.0, 0.39999998),
        Vec3::new(0.4998084, 0.0, 0.0),
        Vec3::new(0.22798076, -0.4020564, -0.74525017),
        Vec3::new(0.0, -0.4, 0.0),
        Vec3::new(0.6831547, -0.5811695, -0.40683725),
    ]);
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.5678611, 0.8900177, 0.05)).unwrap());
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(0.17317575, -0.013831059, -0.7656967, 0.61929584),
        dir: Vec3::new(-0.5318434, 0.0, -0.8468427),
        depth: 0.031045042,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, box against box: FaceOn: manifold area 0 of 0.006332850012218767
#[test]
fn box_box_face_on_lateral_area() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.102165, 0.10172725, 0.05)).unwrap());
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.05, 0.66615266, 0.06161526)).unwrap());
    let pr = Params {
        kind: Kind::FaceOn,
        rot_a: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        rot_b: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        dir: Vec3::new(0.7370327, -0.675857, 0.0),
        depth: 0.044002015,
        pick: (0.74316394, 0.0, 1.723733),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against convex hull: one normal per manifold
#[test]
fn guided_one_normal_hull_hull_3() {
    let a = hull_of(&[
        Vec3::new(0.7444423, -0.3906804, 0.29685813),
        Vec3::new(0.0, 0.8608217, 0.0),
        Vec3::new(0.22960892, -0.30664912, 0.6652165),
        Vec3::new(-0.34838614, 0.18989043, -0.050682724),
        Vec3::new(-0.21665381, 0.0, 0.33624563),
        Vec3::new(0.0, 0.4, 0.0),
    ]);
    let b = hull_of(&[
        Vec3::new(-0.4090524, 0.411803, 0.6084941),
        Vec3::new(0.5020581, 0.35028318, -0.39960548),
        Vec3::new(-0.28308994, -0.7281621, -0.3631107),
        Vec3::new(0.0, 0.0, 0.4),
        Vec3::new(0.2845214, -0.28115395, 0.0),
        Vec3::new(0.0, -0.39999998, 0.0),
    ]);
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(0.1945696, -0.20398875, -0.12215059, 0.9516357),
        dir: Vec3::new(0.6083712, -0.41943204, 0.67376643),
        depth: 0.019463275,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against box: one normal per manifold
#[test]
fn guided_one_normal_hull_box_4() {
    let a = hull_of(&[
        Vec3::new(0.04293182, -0.28031945, -0.66150355),
        Vec3::new(0.66281474, 0.0, 0.6713605),
        Vec3::new(0.0, 0.0, 0.4),
        Vec3::new(0.5456442, 0.15545392, -0.34771344),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::new(0.8274998, 0.31262645, 0.22020648),
    ]);
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.8784096, 0.05, 0.99694526)).unwrap());
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(-0.21682885, 0.30246592, -0.7758293, 0.5094984),
        dir: Vec3::new(0.38065004, 0.4115491, -0.82808983),
        depth: 0.04284558,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, convex hull against convex hull: one normal per manifold
#[test]
fn guided_one_normal_hull_hull_4() {
    let a = hull_of(&[
        Vec3::new(-0.3901286, 0.55613965, -0.5535551),
        Vec3::new(0.0, -0.4, 0.0),
        Vec3::new(0.0, 0.0, 0.5993267),
        Vec3::new(0.012356381, 0.49475843, 0.0),
        Vec3::new(-0.021034727, 0.5972101, -0.35735148),
        Vec3::new(0.0, 0.45587084, 0.13308704),
    ]);
    let b = hull_of(&[
        Vec3::new(0.0, -0.7831849, 0.37329528),
        Vec3::new(0.35376066, 0.0, -0.6488061),
        Vec3::new(0.15383723, 0.6969776, -0.16708048),
        Vec3::new(0.0, 0.0, -0.58621985),
        Vec3::new(0.0, 0.0, -0.39999998),
        Vec3::new(0.0, -0.39999998, 0.0),
    ]);
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(0.65801877, -0.67249006, 0.3306958, 0.07354368),
        dir: Vec3::new(-0.42965436, 0.80375, -0.41156188),
        depth: 0.03120082,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: box against box FaceOn touching, point_a off A's surface by 0.116
#[test]
fn box_box_touching_edge_axis_witness_1() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.10777891, 0.05, 0.20775482)).unwrap());
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.41556516, 0.99334747, 0.9890373)).unwrap());
    let pr = Params {
        kind: Kind::FaceOn,
        rot_a: Quat::from_xyzw(0.42286992, 0.02702876, 0.69780624, 0.5775093),
        rot_b: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        dir: Vec3::new(-0.9712468, 0.0, -0.2380755),
        depth: 0.001,
        pick: (0.99975634, 0.37336212, 3.0990222),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}

/// Found by a bug hunt: dispatcher, box against box: Random: point_a [-0.5137841701507568, -0.3335343599
#[test]
fn box_box_edge_witness_outside_segments_1() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.5143063, 0.33306146, 0.05)).unwrap());
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.05, 0.16316329, 0.7212548)).unwrap());
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(-0.33443, -0.1719408, 0.3836433, 0.8434517),
        dir: Vec3::new(-0.62752885, -0.25655642, 0.73510975),
        depth: 0.014923517,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, 0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}
/// Found by a bug hunt: dispatcher, box against box: Random: point_a [0.04951801523566246, -0.0417594909
#[test]
fn box_box_edge_witness_outside_segments_2() {
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.05, 0.05, 0.6535678)).unwrap());
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(0.5775652, 0.35814404, 0.36664438)).unwrap());
    let pr = Params {
        kind: Kind::Random,
        rot_a: Quat::from_xyzw(0.0, 0.0, -0.0, 1.0),
        rot_b: Quat::from_xyzw(-0.099635735, -0.3087706, 0.40058836, 0.8568911),
        dir: Vec3::new(0.22782412, -0.76022154, -0.6084073),
        depth: 0.008732413,
        pick: (0.0, 0.0, 0.0),
        far: Vec3::new(0.0, 0.0, -0.0),
    };
    check_pair(&a, &b, &pr).unwrap();
}
