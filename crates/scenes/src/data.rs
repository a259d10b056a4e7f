//! Embedded benchmark data: the Taru point cloud, the landscape mesh and the Halton cells
//! (converted from Bullet's headers; see `data/README.md`).

use carom_collision::math::{Real, Vec3};
use serde::Deserialize;

const TARU_OBJ: &str = include_str!("../data/taru.obj");
const LANDSCAPE_OBJ: &str = include_str!("../data/landscape.obj");
const HALTON_JSON: &str = include_str!("../data/halton_cells.json");

fn parse_vertex(line: &str) -> Option<Vec3> {
    let rest = line.strip_prefix("v ")?;
    let mut it = rest.split_whitespace().map(|x| x.parse::<f64>().ok());
    let (x, y, z) = (it.next()??, it.next()??, it.next()??);
    Some(Vec3::new(x as Real, y as Real, z as Real))
}

/// The 43 points Bullet feeds to its Taru `btConvexHullShape`.
pub fn taru_points() -> Vec<Vec3> {
    TARU_OBJ.lines().filter_map(parse_vertex).collect()
}

/// One part of the landscape: vertices and triangles (indices local to the part).
#[derive(Debug, Clone)]
pub struct MeshPart {
    /// Part name (`Landscape01` …).
    pub name: String,
    /// Vertices, raw coordinates (Bullet places every part at `(0, -25, 0)`).
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`.
    pub indices: Vec<[u32; 3]>,
}

/// The 8 landscape parts (17,160 vertices and 32,768 triangles in total).
pub fn landscape_parts() -> Vec<MeshPart> {
    let mut parts: Vec<MeshPart> = Vec::new();
    let mut base = 0u32; // global index of the current part's first vertex
    let mut total = 0u32;
    for line in LANDSCAPE_OBJ.lines() {
        if let Some(name) = line.strip_prefix("o ") {
            base = total;
            parts.push(MeshPart {
                name: name.trim().to_string(),
                vertices: Vec::new(),
                indices: Vec::new(),
            });
        } else if let Some(v) = parse_vertex(line) {
            if let Some(p) = parts.last_mut() {
                p.vertices.push(v);
                total += 1;
            }
        } else if let Some(f) = line.strip_prefix("f ") {
            let idx: Vec<u32> = f
                .split_whitespace()
                .filter_map(|t| t.split('/').next()?.parse::<u32>().ok())
                .collect();
            if let (Some(p), [a, b, c]) = (parts.last_mut(), idx.as_slice()) {
                p.indices.push([a - 1 - base, b - 1 - base, c - 1 - base]);
            }
        }
    }
    parts
}

/// One Voronoi cell of the "Convex Pack" scene.
#[derive(Debug, Clone, Deserialize)]
pub struct HaltonCell {
    /// Cell name (`h00` …).
    pub name: String,
    /// Cell volume (Bullet uses it as the mass).
    pub volume: f64,
    /// Cell centre.
    pub pos: [f64; 3],
    /// Points local to `pos`.
    pub verts: Vec<[f64; 3]>,
}

#[derive(Deserialize)]
struct HaltonFile {
    cells: Vec<HaltonCell>,
}

/// The 90 cells of the fractured 2 m cube.
pub fn halton_cells() -> Vec<HaltonCell> {
    serde_json::from_str::<HaltonFile>(HALTON_JSON)
        .map(|f| f.cells)
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_counts_match_bullet_headers() {
        assert_eq!(taru_points().len(), 43);
        let parts = landscape_parts();
        assert_eq!(parts.len(), 8);
        let (nv, nt): (usize, usize) = parts.iter().fold((0, 0), |(v, t), p| {
            (v + p.vertices.len(), t + p.indices.len())
        });
        assert_eq!((nv, nt), (17_160, 32_768));
        assert_eq!(parts[0].indices.len(), 3906);
        for p in &parts {
            assert!(p
                .indices
                .iter()
                .flatten()
                .all(|&i| (i as usize) < p.vertices.len()));
        }
        let cells = halton_cells();
        assert_eq!(cells.len(), 90);
        assert_eq!(cells.iter().map(|c| c.verts.len()).sum::<usize>(), 1790);
        let vol: f64 = cells.iter().map(|c| c.volume).sum();
        assert!((vol - 8.0).abs() < 1e-3, "{vol}");
    }
}
