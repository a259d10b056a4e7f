//! Test helpers shared by the integration tests (each test binary uses a part of them).
#![allow(dead_code)]

pub mod brute_force_hull;
pub mod hull_checks;
