"""Rebuild tests/data/mikktspace_reference.npz: per-corner tangents from mikktspace.c.

The reference implementation (github.com/mmikk/MikkTSpace: mikktspace.c, .h)
is compiled with a small harness and run on a test mesh: a UV sphere with
jittered vertices and normals (corner angles and areas differ, so the angle
weighting matters), one vertex listed twice with equal values (MikkTSpace
welds by value) and a mirrored uv island with its own vertices (handedness
-1; on its seam, copies weld by value across the two handednesses).

usage: python tools/mikktspace_reference.py MIKKTSPACE_DIR OUT.npz   (needs gcc)
"""

from __future__ import annotations

import ctypes
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from matshop.export.obj import uv_sphere  # noqa: E402

HARNESS = r"""
#include "mikktspace.h"
typedef struct {
  int nfaces; const int* idx; const float* pos; const float* nrm; const float* uv; float* out;
} Mesh;
static Mesh* M(const SMikkTSpaceContext* c) { return (Mesh*)c->m_pUserData; }
static int nf(const SMikkTSpaceContext* c) { return M(c)->nfaces; }
static int nv(const SMikkTSpaceContext* c, int f) { return 3; }
static void gp(const SMikkTSpaceContext* c, float o[], int f, int v) {
  int i = M(c)->idx[f * 3 + v]; for (int k = 0; k < 3; k++) o[k] = M(c)->pos[i * 3 + k];
}
static void gn(const SMikkTSpaceContext* c, float o[], int f, int v) {
  int i = M(c)->idx[f * 3 + v]; for (int k = 0; k < 3; k++) o[k] = M(c)->nrm[i * 3 + k];
}
static void gt(const SMikkTSpaceContext* c, float o[], int f, int v) {
  int i = M(c)->idx[f * 3 + v]; for (int k = 0; k < 2; k++) o[k] = M(c)->uv[i * 2 + k];
}
static void st(const SMikkTSpaceContext* c, const float t[], float s, int f, int v) {
  float* o = M(c)->out + (f * 3 + v) * 4; o[0] = t[0]; o[1] = t[1]; o[2] = t[2]; o[3] = s;
}
int run(int nfaces, const int* idx, const float* pos, const float* nrm, const float* uv,
        float* out) {
  Mesh m = {nfaces, idx, pos, nrm, uv, out};
  SMikkTSpaceInterface it = {0};
  it.m_getNumFaces = nf; it.m_getNumVerticesOfFace = nv; it.m_getPosition = gp;
  it.m_getNormal = gn; it.m_getTexCoord = gt; it.m_setTSpaceBasic = st;
  SMikkTSpaceContext c = {&it, &m};
  return genTangSpaceDefault(&c);
}
"""


def test_mesh() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(positions, normals, uvs with v up, triangles) of the mesh described above."""
    rng = np.random.default_rng(7)
    mesh = uv_sphere(segments=24, rings=12)
    count = len(mesh.positions)
    pos = mesh.positions * (1 + 0.08 * rng.standard_normal((count, 1)))
    pos = pos + 0.02 * rng.standard_normal(pos.shape)
    nrm = mesh.normals + 0.05 * rng.standard_normal(pos.shape)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    uv = np.stack([mesh.uvs[:, 0], 1 - mesh.uvs[:, 1]], axis=1)
    tri = mesh.indices.reshape(-1, 3).astype(np.int64)
    # the mirrored island: whole rings (so every fan stays whole), cut off by a seam
    island = np.all((uv[tri, 1] > 0.3) & (uv[tri, 1] < 0.7), axis=1)
    band = np.unique(tri[island].reshape(-1))
    copies = np.arange(count, count + len(band))
    remap = np.arange(count + len(band))
    remap[band] = copies
    pos, nrm, uv = (np.vstack([a, a[band]]) for a in (pos, nrm, uv))
    tri[island] = remap[tri[island]]
    uv[copies, 0] = 1.0 - uv[copies, 0]
    # one vertex listed twice with equal values: half its triangles use the copy
    vertex = int(tri[300, 0])
    pos, nrm, uv = (np.vstack([a, a[vertex]]) for a in (pos, nrm, uv))
    faces, corners = np.nonzero(tri == vertex)
    tri[faces[::2], corners[::2]] = len(pos) - 1
    return (
        pos.astype(np.float32),
        nrm.astype(np.float32),
        uv.astype(np.float32),
        tri.astype(np.int32),
    )


def main(source_dir: Path, out: Path) -> None:
    with tempfile.TemporaryDirectory() as scratch:
        harness = Path(scratch) / "harness.c"
        harness.write_text(HARNESS)
        library = Path(scratch) / "libmikk.so"
        command = ["gcc", "-O2", "-shared", "-fPIC", f"-I{source_dir}", "-o", str(library)]
        source = str(source_dir / "mikktspace.c")
        subprocess.run([*command, str(harness), source, "-lm"], check=True)
        lib = ctypes.CDLL(str(library))
        pos, nrm, uv, tri = test_mesh()
        tangents = np.zeros((tri.size, 4), np.float32)
        arrays = [np.ascontiguousarray(a) for a in (tri, pos, nrm, uv, tangents)]
        pointers = [a.ctypes.data_as(ctypes.c_void_p) for a in arrays]
        if lib.run(len(tri), *pointers) != 1:
            raise SystemExit("mikktspace failed")
        tangents = arrays[-1]
    np.savez_compressed(
        out, positions=pos, normals=nrm, uvs=uv, triangles=tri, corner_tangents=tangents
    )
    print(f"{len(pos)} vertices, {len(tri)} triangles, {int((tangents[:, 3] < 0).sum())} mirrored")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
