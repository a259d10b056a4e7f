//! Closest-hit rays of Carom and parry3d in two `#[inline(never)]` functions, so an
//! instruction counter can compare them independently of the machine's load:
//!
//! ```sh
//! cargo build --release -p carom-bench --example ray_instructions
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*carom_rays*' \
//!     --toggle-collect='*parry_rays*' ./target/release/examples/ray_instructions 20000 708
//! callgrind_annotate --inclusive=yes callgrind.out.<pid> | grep _rays
//! ```
//!
//! Arguments: rays per mesh (default 20000), cells per side of the generated grid (default
//! 708, about 1M triangles), and `landscape` or `grid` to run one mesh only (one mesh per
//! process keeps the counts apart). Meshes and rays are those of `carom-bench midphase`.

use carom_collision::math::Vec3;
use carom_collision::shape::TriMesh;
use parry3d::query::RayCast;

#[path = "../src/mesh_inputs.rs"]
mod mesh_inputs;

use mesh_inputs::{generated_mesh, pv, rays};

#[inline(never)]
fn carom_rays(mesh: &TriMesh, rays: &[(Vec3, Vec3)]) -> usize {
    rays.iter()
        .filter(|(o, d)| mesh.raycast(*o, *d, 1.0e30).is_some())
        .count()
}

#[inline(never)]
fn parry_rays(mesh: &parry3d::shape::TriMesh, rays: &[parry3d::query::Ray]) -> usize {
    rays.iter()
        .filter(|r| {
            mesh.cast_local_ray_and_get_normal(r, 1.0e30, false)
                .is_some()
        })
        .count()
}

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<usize> = raw.iter().filter_map(|a| a.parse().ok()).collect();
    let only = raw.iter().find(|a| a.parse::<usize>().is_err()).cloned();
    let n_rays = args.first().copied().unwrap_or(20_000);
    let cells = args.get(1).copied().unwrap_or(708);
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/data/landscape.obj");
    let landscape = TriMesh::load(path).expect("landscape.obj");
    let meshes = [
        (
            "landscape",
            landscape.vertices().to_vec(),
            landscape.indices().to_vec(),
        ),
        ("grid", generated_mesh(cells).0, generated_mesh(cells).1),
        // (the grid is generated twice; cheap next to the rays under an instruction counter)
    ];
    for (name, v, t) in meshes {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let mesh = TriMesh::new(v.clone(), t.clone()).expect("valid mesh");
        let pmesh = parry3d::shape::TriMesh::new(v.iter().map(|p| pv(*p)).collect(), t)
            .expect("valid mesh");
        let rs = rays(&mesh.local_aabb(), n_rays);
        let prs: Vec<_> = rs
            .iter()
            .map(|(o, d)| parry3d::query::Ray::new(pv(*o), pv(*d)))
            .collect();
        let hits = (carom_rays(&mesh, &rs), parry_rays(&pmesh, &prs));
        println!(
            "{name}: {} triangles, {n_rays} rays, hits {hits:?}",
            mesh.num_triangles()
        );
    }
}
