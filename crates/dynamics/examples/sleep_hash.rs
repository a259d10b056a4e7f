//! State hash of every benchmark scene after 240 steps, sleeping on and off (to check that
//! a pipeline change leaves the results bit-identical).
//!
//! `cargo run --release -p carom-dynamics --example sleep_hash`
use carom_dynamics::{PipelineParams, World};
fn main() {
    for sleeping in [true, false] {
        for number in [1usize, 2, 3, 4, 5, 6, 8] {
            let scene = carom_scenes::bullet::scene(number).unwrap();
            let mut params = PipelineParams::default();
            params.dynamics.sleep.enabled = sleeping;
            params.dynamics.parallel = false;
            let mut world = World::from_scene_with(&scene, params).unwrap();
            let (mut woken, mut slept) = (0, 0);
            for _ in 0..240 {
                let r = world.step(scene.dt).unwrap();
                woken += r.dynamics.woken.len();
                slept += r.dynamics.slept.len();
            }
            println!(
                "sleep {sleeping} scene {number} {:016x} sleeping {} woken {woken} slept {slept}",
                world.state_hash(),
                world.sleeping_count()
            );
        }
    }
}
