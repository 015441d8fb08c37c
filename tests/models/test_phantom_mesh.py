"""The phantom's tetrahedral volume mesh for hydroelastic contact."""

import numpy as np
import pytest

from vic_drake.models.phantom_mesh import boundary_triangles, phantom_volume_mesh
from vic_drake.tissue import SyntheticChestPhantom


@pytest.fixture(scope="module")
def phantom():
    return SyntheticChestPhantom()


def test_phantom_volume_mesh_is_valid_and_follows_the_surface(phantom):
    vertices, tets = phantom_volume_mesh(phantom, resolution_m=0.03, thickness_m=0.05)
    a, b, c, d = (vertices[tets[:, i]] for i in range(4))
    volumes = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6
    assert np.all(volumes > 0)
    x_min, x_max, y_min, y_max = phantom.bounds
    top = vertices[
        np.isclose(vertices[:, 2], phantom.surface_z(vertices[:, 0], vertices[:, 1]))
    ]
    assert len(top) >= ((x_max - x_min) / 0.03) * ((y_max - y_min) / 0.03)
    # The slab's volume is the integral of its height.
    footprint = (x_max - x_min) * (y_max - y_min)
    # (the grid mean of the height weights the edges like the interior: ~3 %)
    assert volumes.sum() == pytest.approx(
        footprint * (np.mean(top[:, 2]) - vertices[:, 2].min()), rel=0.05
    )
    # A closed boundary: every edge of the surface is shared by two faces.
    faces = boundary_triangles(vertices, tets)
    edges = np.sort(
        np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1
    )
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
