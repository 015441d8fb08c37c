"""Regularised grid fit of a surface to scattered heights (as MATLAB's GRIDFIT).

The paper reconstructs the tissue surface from the palpation contact points
with D'Errico's GRIDFIT. This is the same method: the unknowns are the
heights at the nodes of a regular grid; each data point contributes one
equation, the bilinear interpolation of its four surrounding nodes equal to
the measured height; each interior node contributes two smoothness
equations, the second differences of the heights along x and along y equal
to zero (GRIDFIT's "gradient" regulariser: the gradient varies as smoothly
as possible). As in GRIDFIT the smoothness rows are scaled by
``smoothness * ||A||_1 / ||R||_1`` so the smoothness is dimensionless and
independent of the node spacing. The sparse normal equations
``(A^T A + mu^2 R^T R) z = A^T h`` are solved by dense Cholesky up to
:data:`DENSE_MAX_NODES` nodes, else by sparse LU.

The smoothness is chosen by generalised cross-validation (Craven and Wahba
1979): the value on a log grid that minimises
``GCV = n ||h - H h||^2 / (n - tr H)^2`` with the hat matrix
``H = A (A^T A + mu^2 R^T R)^-1 A^T``, whose trace is computed exactly from
one factorisation per candidate (``tr H = sum(A * (M^-1 A^T)^T)``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.interpolate import RectBivariateSpline
from scipy.linalg import cho_factor, cho_solve
from scipy.sparse.linalg import splu
from threadpoolctl import threadpool_limits

from vic_drake.errors import VicDrakeError

DEFAULT_SMOOTHNESS_GRID = tuple(np.logspace(-4, 3, 22))
"""Candidate smoothness values for GCV (dimensionless, GRIDFIT's default is 1)."""


def grid_axis(lo: float, hi: float, spacing: float) -> np.ndarray:
    """Nodes from lo to hi (both included) at most ``spacing`` apart, evenly spaced."""
    if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
        raise VicDrakeError(f"grid axis needs lo < hi, got {lo!r}, {hi!r}")
    if not (np.isfinite(spacing) and spacing > 0):
        raise VicDrakeError(f"grid spacing must be > 0, got {spacing!r}")
    n = max(2, int(np.ceil((hi - lo) / spacing - 1e-9)) + 1)
    return np.linspace(lo, hi, n)


def bilinear_matrix(x, y, x_nodes, y_nodes) -> sp.csr_matrix:
    """Sparse (n, nx*ny) bilinear interpolation from grid nodes to points.

    Node (ix, iy) is column ``ix * ny + iy``. Points must lie in the grid.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    nx, ny = x_nodes.size, y_nodes.size
    if np.any(
        (x < x_nodes[0] - 1e-12)
        | (x > x_nodes[-1] + 1e-12)
        | (y < y_nodes[0] - 1e-12)
        | (y > y_nodes[-1] + 1e-12)
    ):
        raise VicDrakeError("gridfit: data points must lie inside the node grid")
    ix = np.clip(np.searchsorted(x_nodes, x, side="right") - 1, 0, nx - 2)
    iy = np.clip(np.searchsorted(y_nodes, y, side="right") - 1, 0, ny - 2)
    tx = (x - x_nodes[ix]) / (x_nodes[ix + 1] - x_nodes[ix])
    ty = (y - y_nodes[iy]) / (y_nodes[iy + 1] - y_nodes[iy])
    rows = np.repeat(np.arange(x.size), 4)
    cols = np.stack(
        [ix * ny + iy, (ix + 1) * ny + iy, ix * ny + iy + 1, (ix + 1) * ny + iy + 1],
        axis=1,
    ).ravel()
    vals = np.stack(
        [(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty], axis=1
    ).ravel()
    return sp.csr_matrix((vals, (rows, cols)), shape=(x.size, nx * ny))


def _second_difference(nodes: np.ndarray) -> sp.csr_matrix:
    """(n-2, n) second-difference operator on uneven nodes (d2/dx2)."""
    h = np.diff(nodes)
    n = nodes.size
    h0, h1 = h[:-1], h[1:]
    rows = np.repeat(np.arange(n - 2), 3)
    cols = (np.arange(n - 2)[:, None] + np.arange(3)[None, :]).ravel()
    vals = np.stack(
        [2 / (h0 * (h0 + h1)), -2 / (h0 * h1), 2 / (h1 * (h0 + h1))], axis=1
    ).ravel()
    return sp.csr_matrix((vals, (rows, cols)), shape=(n - 2, n))


def gradient_regularizer(x_nodes, y_nodes) -> sp.csr_matrix:
    """Second differences along x and along y of the node heights, stacked."""
    nx, ny = x_nodes.size, y_nodes.size
    blocks = []
    if nx >= 3:
        blocks.append(sp.kron(_second_difference(x_nodes), sp.identity(ny)))
    if ny >= 3:
        blocks.append(sp.kron(sp.identity(nx), _second_difference(y_nodes)))
    if not blocks:
        raise VicDrakeError("gridfit needs at least 3 nodes along x or y")
    return sp.vstack(blocks).tocsr()


@dataclass(frozen=True)
class GridFit:
    """A fitted surface on a node grid.

    Attributes:
        x_nodes, y_nodes: node axes (nx,), (ny,), m.
        z: node heights (nx, ny), m.
        smoothness: the smoothness used (dimensionless).
        gcv: GCV score per candidate smoothness (empty if not chosen by GCV).
        smoothness_grid: the candidates.
        residual_rms: RMS of data minus fit at the data points, m.
        effective_dof: trace of the hat matrix at the chosen smoothness.
    """

    x_nodes: np.ndarray
    y_nodes: np.ndarray
    z: np.ndarray
    smoothness: float
    residual_rms: float
    effective_dof: float
    gcv: np.ndarray = field(default_factory=lambda: np.zeros(0))
    smoothness_grid: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __call__(self, x, y) -> np.ndarray:
        """Bilinear interpolation of the node heights at points (x, y)."""
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        A = bilinear_matrix(
            np.clip(x.ravel(), self.x_nodes[0], self.x_nodes[-1]),
            np.clip(y.ravel(), self.y_nodes[0], self.y_nodes[-1]),
            self.x_nodes,
            self.y_nodes,
        )
        return (A @ self.z.ravel()).reshape(x.shape)

    def on_grid(self, xs, ys) -> np.ndarray:
        """The surface on the grid xs x ys, shape (len(xs), len(ys)).

        Bicubic spline through the node heights (C2 between nodes; the
        nodes are already smooth), clamped to the node grid.
        """
        kx = min(3, self.x_nodes.size - 1)
        ky = min(3, self.y_nodes.size - 1)
        spline = RectBivariateSpline(
            self.x_nodes, self.y_nodes, self.z, kx=kx, ky=ky, s=0
        )
        xs = np.clip(np.asarray(xs, float), self.x_nodes[0], self.x_nodes[-1])
        ys = np.clip(np.asarray(ys, float), self.y_nodes[0], self.y_nodes[-1])
        return spline(xs, ys, grid=True)


DENSE_MAX_NODES = 4000
"""Up to this many nodes the normal equations are solved densely (Cholesky)."""


def _solve(A, R, h, mu, *, want_trace: bool):
    """Node heights and tr(H) for one smoothness (dense Cholesky or sparse LU)."""
    M = A.T @ A + (mu * mu) * (R.T @ R)
    rhs = A.T @ h
    trace = np.nan
    if M.shape[0] <= DENSE_MAX_NODES:
        factor = cho_factor(M.toarray(), lower=True, check_finite=False)
        z = cho_solve(factor, rhs, check_finite=False)
        if want_trace:
            X = cho_solve(factor, A.T.toarray(), check_finite=False)
            trace = float(np.sum(A.toarray() * X.T))
        return z, trace
    lu = splu(M.tocsc())
    z = lu.solve(rhs)
    if want_trace:
        X = lu.solve(A.T.toarray())  # (nodes, n) = M^-1 A^T
        trace = float(np.sum(A.toarray() * X.T))
    return z, trace


def gridfit(
    x,
    y,
    z,
    *,
    x_nodes,
    y_nodes,
    smoothness: float | None = None,
    smoothness_grid=DEFAULT_SMOOTHNESS_GRID,
) -> GridFit:
    """Fits a smooth surface on a node grid to scattered heights.

    Args:
        x, y, z: data points (n,), m. Non-finite points are rejected.
        x_nodes, y_nodes: increasing node axes covering the data, m.
        smoothness: fixed smoothness (> 0); None chooses it by GCV over
            ``smoothness_grid``.
        smoothness_grid: GCV candidates (positive).

    Returns:
        A :class:`GridFit`.

    Raises:
        VicDrakeError: bad shapes, non-finite data, fewer than 4 points,
            points outside the node grid, non-positive smoothness.
    """
    x, y, z = (np.asarray(a, float).ravel() for a in (x, y, z))
    if not (x.size == y.size == z.size):
        raise VicDrakeError(
            f"gridfit: x, y, z sizes differ ({x.size}, {y.size}, {z.size})"
        )
    if not np.all(np.isfinite(x) & np.isfinite(y) & np.isfinite(z)):
        raise VicDrakeError("gridfit: data points must be finite")
    if x.size < 4:
        raise VicDrakeError(f"gridfit needs at least 4 data points, got {x.size}")
    x_nodes, y_nodes = np.asarray(x_nodes, float), np.asarray(y_nodes, float)
    for name, nodes in (("x_nodes", x_nodes), ("y_nodes", y_nodes)):
        if nodes.ndim != 1 or nodes.size < 2 or np.any(np.diff(nodes) <= 0):
            raise VicDrakeError(f"gridfit: {name} must be increasing with >= 2 nodes")
    with threadpool_limits(limits=1, user_api="blas"):
        # Small dense factorisations: one BLAS thread avoids oversubscription.
        return _gridfit(x, y, z, x_nodes, y_nodes, smoothness, smoothness_grid)


def _gridfit(x, y, z, x_nodes, y_nodes, smoothness, smoothness_grid) -> GridFit:
    A = bilinear_matrix(x, y, x_nodes, y_nodes)
    R = gradient_regularizer(x_nodes, y_nodes)
    scale = sp.linalg.norm(A, 1) / sp.linalg.norm(R, 1)
    offset = float(np.mean(z))  # The regulariser ignores planes; this only conditions.
    h = z - offset
    n = x.size

    grid = np.zeros(0)
    scores = np.zeros(0)
    if smoothness is None:
        grid = np.asarray(smoothness_grid, float)
        if grid.size == 0 or np.any(~(grid > 0)):
            raise VicDrakeError("gridfit: smoothness_grid must hold positive numbers")
        scores = np.empty(grid.size)
        for k, s in enumerate(grid):
            sol, trace = _solve(A, R, h, s * scale, want_trace=True)
            rss = float(np.sum((h - A @ sol) ** 2))
            denom = max(n - trace, 1e-9)
            scores[k] = n * rss / denom**2
        smoothness = float(grid[int(np.argmin(scores))])
    elif not (np.isfinite(smoothness) and smoothness > 0):
        raise VicDrakeError(f"gridfit: smoothness must be > 0, got {smoothness!r}")
    sol, trace = _solve(A, R, h, float(smoothness) * scale, want_trace=True)
    resid = h - A @ sol
    return GridFit(
        x_nodes=x_nodes,
        y_nodes=y_nodes,
        z=sol.reshape(x_nodes.size, y_nodes.size) + offset,
        smoothness=float(smoothness),
        residual_rms=float(np.sqrt(np.mean(resid**2))),
        effective_dof=float(trace),
        gcv=scores,
        smoothness_grid=grid,
    )
