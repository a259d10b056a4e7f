"""Triangle meshes: tampered pickles raise CaromError naming the problem (never RuntimeError
or a crash), and ``TriMesh.load`` welds like the constructor."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

import carom


def small_mesh() -> carom.TriMesh:
    # A 2 x 2 grid of quads, slightly bumped, away from the origin.
    xs, zs = np.meshgrid(np.arange(3.0), np.arange(3.0))
    verts = np.stack([xs.ravel() + 50, np.sin(xs.ravel() + zs.ravel()) * 0.2, zs.ravel()], axis=1)
    tris = []
    for r in range(2):
        for c in range(2):
            a, b, d, e = r * 3 + c, r * 3 + c + 1, (r + 1) * 3 + c, (r + 1) * 3 + c + 1
            tris += [[a, d, b], [b, d, e]]
    return carom.TriMesh(verts, np.array(tris))


def test_every_flipped_byte_of_a_pickled_mesh_raises_caromerror_or_loads_a_valid_mesh() -> None:
    mesh = small_mesh()
    payload = mesh.to_bytes()
    pickled = pickle.dumps(mesh)
    at = pickled.index(payload)
    origins = np.array([[50.5, 5.0, 0.5], [51.2, 5.0, 1.7], [49.0, 5.0, 1.0]])
    directions = np.tile([0.0, -1.0, 0.0], (3, 1))
    want = mesh.raycast(origins, directions)
    rejected, messages = 0, set()
    for i in range(len(payload)):
        for mask in (0x01, 0x80, 0xFF):
            bad = bytearray(pickled)
            bad[at + i] ^= mask
            try:
                got = pickle.loads(bytes(bad))
            except carom.CaromError as e:  # never RuntimeError, never a crash
                rejected += 1
                messages.add(str(e).split(":")[1] if ":" in str(e) else str(e))
                continue
            # Accepted bytes are a consistent mesh: queries run, it round-trips exactly.
            hits = got.raycast(origins, directions)
            assert np.all(np.isfinite(hits.distance[hits.hit]))
            assert pickle.loads(pickle.dumps(got)) == got
            if got == mesh:
                np.testing.assert_array_equal(hits.distance, want.distance)
    assert rejected > len(payload)
    # The load checks name what is wrong (the BVH, edges, indices, ...), not just "bad bytes".
    text = " ".join(messages)
    assert "bvh" in text or "edges" in text or "indices" in text, text


def test_tampered_mesh_bytes_name_the_problem() -> None:
    mesh = small_mesh()
    other = carom.TriMesh(mesh.vertices, mesh.indices[::-1].copy())
    a, b = mesh.to_bytes(), other.to_bytes()
    assert len(a) == len(b)
    # The vertices and triangles of one mesh with the BVH and edges of the other: splice at
    # the first differing byte (the indices) and keep the rest of the other mesh.
    first = next(i for i in range(len(a)) if a[i] != b[i])
    spliced = a[:first] + b[first:first + 1] + a[first + 1:]
    with pytest.raises(carom.CaromError, match="cannot parse carom shape bytes: invalid"):
        carom.Shape.from_bytes(spliced)


OBJ_SPLIT = """v 0 0 0
v 1 0 0
v 0 0 1
v 1 0 0
v 1 0 1
v 0 0 1
f 1 3 2
f 4 6 5
"""


def test_load_welds_like_the_constructor(tmp_path: Path) -> None:
    path = tmp_path / "split.obj"
    path.write_text(OBJ_SPLIT)
    plain = carom.TriMesh.load(path)
    welded = carom.TriMesh.load(path, weld_tolerance=0.0)
    assert plain.vertices.shape == (6, 3)
    assert welded.vertices.shape == (4, 3)
    built = carom.TriMesh(plain.vertices, plain.indices, weld_tolerance=0.0)
    assert welded == built
    near = carom.TriMesh.load(str(path), weld_tolerance=1e-3)
    assert near == built
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(carom.CaromError, match="weld_tolerance"):
            carom.TriMesh.load(path, weld_tolerance=bad)
    with pytest.raises(TypeError):
        carom.TriMesh.load(path, weld_tolerance="0.1")  # type: ignore[arg-type]
