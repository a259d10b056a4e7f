//! Loading triangle meshes from Wavefront OBJ (through `tobj`) and STL (through `stl_io`),
//! from files or bytes. Every failure is a [`CaromError::Parse`] naming the source and the
//! problem; OBJ groups and objects are merged into one mesh.

use super::trimesh::{TriMesh, TriMeshOptions};
use crate::error::{CaromError, Result};
use crate::math::{Real, Vec3};
use std::io::{BufReader, Cursor};
use std::path::Path;

fn parse_err(what: &str, reason: impl Into<String>) -> CaromError {
    CaromError::Parse {
        what: what.to_string(),
        reason: reason.into(),
    }
}

/// Builds the mesh, reporting invalid content (NaN, bad indices, no triangles) as a parse
/// error of `what`.
fn finish(
    what: &str,
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    options: TriMeshOptions,
) -> Result<TriMesh> {
    if indices.is_empty() {
        return Err(parse_err(what, "the file holds no triangles"));
    }
    TriMesh::with_options(vertices, indices, options).map_err(|e| parse_err(what, e.to_string()))
}

fn obj_from_reader(
    what: &str,
    reader: &mut impl std::io::BufRead,
    options: TriMeshOptions,
) -> Result<TriMesh> {
    let load = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) =
        tobj::load_obj_buf(reader, &load, |_| Ok((Vec::new(), Default::default())))
            .map_err(|e| parse_err(what, format!("invalid OBJ: {e}")))?;
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for model in &models {
        let m = &model.mesh;
        if m.positions.len() % 3 != 0 || m.indices.len() % 3 != 0 {
            return Err(parse_err(
                what,
                format!(
                    "object '{}' has a truncated vertex or face list",
                    model.name
                ),
            ));
        }
        let base = vertices.len();
        let count = m.positions.len() / 3;
        vertices.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0] as Real, p[1] as Real, p[2] as Real)),
        );
        for (f, t) in m.indices.chunks_exact(3).enumerate() {
            if let Some(&bad) = t.iter().find(|&&i| i as usize >= count) {
                return Err(parse_err(
                    what,
                    format!(
                        "object '{}' face {f} uses vertex {bad}, but it has {count}",
                        model.name
                    ),
                ));
            }
            let off = |i: u32| (base + i as usize) as u32;
            indices.push([off(t[0]), off(t[1]), off(t[2])]);
        }
    }
    finish(what, vertices, indices, options)
}

fn stl_from_reader<R: std::io::Read + std::io::Seek>(
    what: &str,
    reader: &mut R,
    options: TriMeshOptions,
) -> Result<TriMesh> {
    let mesh =
        stl_io::read_stl(reader).map_err(|e| parse_err(what, format!("invalid STL: {e}")))?;
    let vertices: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| Vec3::new(v[0] as Real, v[1] as Real, v[2] as Real))
        .collect();
    let mut indices = Vec::with_capacity(mesh.faces.len());
    for (f, face) in mesh.faces.iter().enumerate() {
        let [a, b, c] = face.vertices;
        if [a, b, c]
            .iter()
            .any(|&i| i >= vertices.len() || i > u32::MAX as usize)
        {
            return Err(parse_err(
                what,
                format!("face {f} has an invalid vertex index"),
            ));
        }
        indices.push([a as u32, b as u32, c as u32]);
    }
    finish(what, vertices, indices, options)
}

fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| parse_err(&path.display().to_string(), e.to_string()))
}

impl TriMesh {
    /// A mesh from the text of a Wavefront OBJ file: all objects and groups merged, polygons
    /// triangulated (fan), points and lines ignored.
    pub fn from_obj_bytes(bytes: &[u8], options: TriMeshOptions) -> Result<TriMesh> {
        obj_from_reader("OBJ data", &mut BufReader::new(bytes), options)
    }

    /// A mesh from an OBJ file (see [`TriMesh::from_obj_bytes`]).
    pub fn from_obj_file(path: impl AsRef<Path>, options: TriMeshOptions) -> Result<TriMesh> {
        let path = path.as_ref();
        let bytes = read_file(path)?;
        obj_from_reader(
            &path.display().to_string(),
            &mut BufReader::new(&bytes[..]),
            options,
        )
    }

    /// A mesh from STL bytes, ASCII or binary (identical vertices are shared).
    pub fn from_stl_bytes(bytes: &[u8], options: TriMeshOptions) -> Result<TriMesh> {
        stl_from_reader("STL data", &mut Cursor::new(bytes), options)
    }

    /// A mesh from an STL file (see [`TriMesh::from_stl_bytes`]).
    pub fn from_stl_file(path: impl AsRef<Path>, options: TriMeshOptions) -> Result<TriMesh> {
        let path = path.as_ref();
        let bytes = read_file(path)?;
        stl_from_reader(
            &path.display().to_string(),
            &mut Cursor::new(&bytes[..]),
            options,
        )
    }

    /// A mesh from a `.obj` or `.stl` file, chosen by extension (case-insensitive), with
    /// default options.
    pub fn load(path: impl AsRef<Path>) -> Result<TriMesh> {
        Self::load_with_options(path, TriMeshOptions::default())
    }

    /// A mesh from a `.obj` or `.stl` file (see [`TriMesh::load`]) with options, e.g. a
    /// `weld_tolerance` to merge the duplicate vertices of split faces.
    pub fn load_with_options(path: impl AsRef<Path>, options: TriMeshOptions) -> Result<TriMesh> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => Self::from_obj_file(path, options),
            Some("stl") => Self::from_stl_file(path, options),
            _ => Err(parse_err(
                &path.display().to_string(),
                "unknown mesh format: expected a .obj or .stl file",
            )),
        }
    }
}
