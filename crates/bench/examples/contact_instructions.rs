//! The contact-bench cases (`benches/contacts.rs`) generated from scratch by Carom and by
//! parry3d in two `#[inline(never)]` functions, so an instruction counter can compare them
//! independently of the machine's load:
//!
//! ```sh
//! cargo build --release -p carom-bench --example contact_instructions
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*carom_fresh*' \
//!     --toggle-collect='*parry_fresh*' ./target/release/examples/contact_instructions hull8-hull8 100
//! callgrind_annotate --inclusive=yes callgrind.out.<pid> | grep _fresh
//! ```
//!
//! Arguments: the case name (default every case) and the number of rounds over its 64
//! configurations (default 100). Divide the counts by `64 × rounds` for a per-pair figure.

use carom_collision::math::Isometry;
use carom_collision::narrowphase::{ContactManifold, Dispatcher};
use parry3d::math::Pose as PPose;
use parry3d::query::{
    ContactManifold as PManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    PersistentQueryDispatcher,
};
use parry3d::shape::Shape as PShape;
use std::hint::black_box;

#[path = "../benches/common/mod.rs"]
#[allow(dead_code)]
mod common;
#[path = "../benches/common/contact_cases.rs"]
mod contact_cases;
use contact_cases::{cases, pf, Case, PREDICTION};

#[inline(never)]
fn carom_fresh(d: &Dispatcher, case: &Case, ms: &mut [ContactManifold], rounds: usize) -> usize {
    for _ in 0..rounds {
        for (p, m) in case.poses.iter().zip(ms.iter_mut()) {
            m.clear();
            d.update_manifold(&case.a, &Isometry::IDENTITY, &case.b, p, m)
                .unwrap();
        }
        black_box(&ms);
    }
    ms.iter().map(|m| m.len()).sum()
}

type Slot = (Vec<PManifold<(), ()>>, Option<ContactManifoldsWorkspace>);

#[inline(never)]
fn parry_fresh(case: &Case, poses: &[PPose], slots: &mut [Slot], rounds: usize) -> usize {
    let pd = DefaultQueryDispatcher;
    let (pa, pb): (&dyn PShape, &dyn PShape) = (&*case.pa, &*case.pb);
    for _ in 0..rounds {
        for (p, (m, ws)) in poses.iter().zip(slots.iter_mut()) {
            m.clear();
            *ws = None;
            pd.contact_manifolds(p, pa, pb, pf(PREDICTION), m, ws)
                .unwrap();
        }
        black_box(&slots);
    }
    slots
        .iter()
        .map(|(m, _)| m.iter().map(|m| m.points.len()).sum::<usize>())
        .sum()
}

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    let rounds = raw.iter().find_map(|a| a.parse().ok()).unwrap_or(100);
    let only = raw.iter().find(|a| a.parse::<usize>().is_err()).cloned();
    let d = Dispatcher::default();
    for case in cases() {
        if only.as_deref().is_some_and(|o| o != case.name) {
            continue;
        }
        let poses: Vec<PPose> = case.poses.iter().map(common::pp).collect();
        let mut ms = vec![ContactManifold::new(); case.poses.len()];
        let mut slots: Vec<Slot> = (0..poses.len()).map(|_| (Vec::new(), None)).collect();
        let ours = carom_fresh(&d, &case, &mut ms, rounds);
        let theirs = parry_fresh(&case, &poses, &mut slots, rounds);
        println!("{}: {ours} points (carom), {theirs} (parry3d)", case.name);
    }
}
