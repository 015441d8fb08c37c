"""Tetrahedral volume mesh of a phantom's height field, for hydroelastic contact.

Drake's compliant hydroelastic geometry needs a tetrahedral volume mesh whose
pressure field it derives from each vertex's distance to the boundary. The
phantom is a slab: its top is the tissue surface z(x, y) sampled on a
regular grid, its bottom is flat ``thickness_m`` below the lowest surface
point. Between them sits one interior vertex layer (halfway), so interior
vertices have a positive distance to the boundary. Every grid cell and layer
is a hexahedron cut into six tetrahedra around its main diagonal (the Kuhn
split), which conforms across neighbouring cells.

The mesh is written as a legacy ASCII ``.vtk`` unstructured grid into a
cache folder keyed by the phantom's name and the meshing settings; the
repository holds no generated meshes.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom import Phantom

#: Corner offsets (i, j, k) of a hexahedron, indexed 0..7 as 4i + 2j + k.
_KUHN_PATHS = (
    (0, 1, 2),
    (0, 2, 1),
    (1, 0, 2),
    (1, 2, 0),
    (2, 0, 1),
    (2, 1, 0),
)


def phantom_volume_mesh(
    phantom: Phantom, *, resolution_m: float, thickness_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Tetrahedral mesh of the phantom slab in the phantom's (map) frame.

    Args:
        phantom: the tissue map; its ``bounds`` give the footprint.
        resolution_m: grid spacing of the top surface, m (> 0).
        thickness_m: slab thickness below the lowest surface point, m (> 0).

    Returns:
        (vertices (n, 3) in m, tetrahedra (m, 4) vertex indices), every
        tetrahedron with positive signed volume.
    """
    if not (np.isfinite(resolution_m) and resolution_m > 0):
        raise VicDrakeError(f"resolution_m must be > 0, got {resolution_m!r}")
    if not (np.isfinite(thickness_m) and thickness_m > 0):
        raise VicDrakeError(f"thickness_m must be > 0, got {thickness_m!r}")
    x_min, x_max, y_min, y_max = phantom.bounds
    nx = max(2, int(np.ceil((x_max - x_min) / resolution_m)) + 1)
    ny = max(2, int(np.ceil((y_max - y_min) / resolution_m)) + 1)
    xs = np.linspace(x_min, x_max, nx)
    ys = np.linspace(y_min, y_max, ny)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    top = phantom.surface_z(X, Y)
    bottom = float(np.min(top)) - thickness_m
    layers = (np.full_like(top, bottom), 0.5 * (top + bottom), top)
    nk = len(layers)
    vertices = np.stack(
        [
            np.stack([X, Y, z], axis=-1)  # (nx, ny, 3)
            for z in layers
        ],
        axis=2,
    )  # (nx, ny, nk, 3), index (i, j, k)
    vertices = vertices.reshape(-1, 3)

    def vid(i, j, k):
        return (i * ny + j) * nk + k

    ii, jj, kk = np.meshgrid(
        np.arange(nx - 1), np.arange(ny - 1), np.arange(nk - 1), indexing="ij"
    )
    ii, jj, kk = ii.ravel(), jj.ravel(), kk.ravel()
    tets = []
    for path in _KUHN_PATHS:
        corner = np.zeros((3, ii.size), dtype=int)
        chain = [vid(ii, jj, kk)]
        for axis in path:
            corner[axis] += 1
            chain.append(vid(ii + corner[0], jj + corner[1], kk + corner[2]))
        tets.append(np.stack(chain, axis=1))
    tets = np.concatenate(tets, axis=0)
    a, b, c, d = (vertices[tets[:, n]] for n in range(4))
    signed = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)
    flip = signed < 0
    tets[flip, 1], tets[flip, 2] = tets[flip, 2].copy(), tets[flip, 1].copy()
    return vertices, tets


def write_vtk(path: str | os.PathLike, vertices: np.ndarray, tets: np.ndarray) -> Path:
    """Writes a legacy ASCII VTK unstructured grid of tetrahedra (cell type 10)."""
    path = Path(path)
    lines = [
        "# vtk DataFile Version 3.0",
        "vic_drake phantom volume mesh",
        "ASCII",
        "DATASET UNSTRUCTURED_GRID",
        f"POINTS {len(vertices)} double",
    ]
    lines += [f"{x:.9g} {y:.9g} {z:.9g}" for x, y, z in vertices]
    lines.append(f"CELLS {len(tets)} {5 * len(tets)}")
    lines += [f"4 {a} {b} {c} {d}" for a, b, c, d in tets]
    lines.append(f"CELL_TYPES {len(tets)}")
    lines += ["10"] * len(tets)
    tmp = path.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(path)  # atomic: parallel test workers never read half a file
    return path


def boundary_triangles(vertices: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """The tetrahedral mesh's boundary faces (m, 3), normals pointing outwards."""
    faces, opposite = [], []
    for skip in range(4):
        keep = [i for i in range(4) if i != skip]
        faces.append(tets[:, keep])
        opposite.append(tets[:, skip])
    faces = np.concatenate(faces)
    opposite = np.concatenate(opposite)
    key = np.sort(faces, axis=1)
    _, index, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    faces, opposite = faces[index[counts == 1]], opposite[index[counts == 1]]
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    normal = np.cross(b - a, c - a)
    inward = np.einsum("ij,ij->i", normal, vertices[opposite] - a) > 0
    faces[inward, 1], faces[inward, 2] = (
        faces[inward, 2].copy(),
        faces[inward, 1].copy(),
    )
    return faces


def write_obj(
    path: str | os.PathLike, vertices: np.ndarray, triangles: np.ndarray
) -> Path:
    """Writes a triangle surface as Wavefront OBJ (for visualization)."""
    path = Path(path)
    used = np.unique(triangles)
    remap = np.full(len(vertices), -1)
    remap[used] = np.arange(len(used))
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in vertices[used]]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in remap[triangles]]
    tmp = path.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(path)
    return path


def cache_dir() -> Path:
    """Folder for generated model files ($VIC_DRAKE_CACHE or the temp dir)."""
    root = os.environ.get("VIC_DRAKE_CACHE")
    base = Path(root) if root else Path(tempfile.gettempdir()) / "vic_drake_cache"
    base.mkdir(parents=True, exist_ok=True)
    return base


def phantom_mesh_paths(
    phantom: Phantom, *, resolution_m: float, thickness_m: float
) -> tuple[Path, Path]:
    """Writes (or reuses) the phantom's meshes: (volume .vtk, boundary .obj).

    The .vtk is the compliant hydroelastic geometry, the .obj its boundary
    for visualization (Meshcat draws no .vtk). File names hash the mesh, so
    a changed phantom or setting never reuses a stale file.
    """
    vertices, tets = phantom_volume_mesh(
        phantom, resolution_m=resolution_m, thickness_m=thickness_m
    )
    digest = hashlib.sha1(vertices.tobytes() + tets.tobytes()).hexdigest()[:16]
    vtk = cache_dir() / f"phantom_{phantom.name}_{digest}.vtk"
    obj = vtk.with_suffix(".obj")
    if not vtk.is_file():
        write_vtk(vtk, vertices, tets)
    if not obj.is_file():
        write_obj(obj, vertices, boundary_triangles(vertices, tets))
    return vtk, obj
