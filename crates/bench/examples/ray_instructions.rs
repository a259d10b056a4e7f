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

use carom_collision::math::{Aabb, Real, Vec3};
use carom_collision::shape::TriMesh;
use parry3d::query::RayCast;

type PVec = parry3d::math::Vector;

struct Lcg(u64);
impl Lcg {
    fn f(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f64 / (1u64 << 24) as f64) as Real
    }
}

fn grid(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let size = 1000.0 as Real;
    let mut v = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let x = size * i as Real / n as Real;
            let z = size * j as Real / n as Real;
            let y = (x * 0.031).sin() * (z * 0.017).cos() * 40.0 + (x * 0.4 + z * 0.3).sin();
            v.push(Vec3::new(x, y, z));
        }
    }
    let w = (n + 1) as u32;
    let mut t = Vec::new();
    for i in 0..n as u32 {
        for j in 0..n as u32 {
            let a = i * w + j;
            t.push([a, a + 1, a + w]);
            t.push([a + 1, a + w + 1, a + w]);
        }
    }
    (v, t)
}

fn rays(bounds: &Aabb, n: usize) -> Vec<(Vec3, Vec3)> {
    let mut rng = Lcg(12345);
    let c = bounds.center();
    let r = bounds.extents().length() * 0.75;
    (0..n)
        .map(|_| {
            let d = loop {
                let v = Vec3::new(rng.f() * 2.0 - 1.0, rng.f(), rng.f() * 2.0 - 1.0);
                if v.length() > 0.1 && v.length() <= 1.0 {
                    break v.normalize();
                }
            };
            let origin = c + d * r;
            let e = bounds.extents();
            let target = bounds.min + Vec3::new(rng.f() * e.x, rng.f() * e.y, rng.f() * e.z);
            (origin, (target - origin).normalize())
        })
        .collect()
}

fn pv(v: Vec3) -> PVec {
    PVec::new(v.x as _, v.y as _, v.z as _)
}

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
        ("grid", grid(cells).0, grid(cells).1),
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
