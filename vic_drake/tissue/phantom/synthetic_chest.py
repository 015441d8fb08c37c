"""An analytic chest phantom: torso dome, hump, ribs under soft tissue.

The embedded default when the measured data is absent: the measured
phantom's twin (its defaults are fitted to the measured map; see
:mod:`vic_drake.estimation.chest_fit`). Every parameter lives in
:class:`SyntheticChestParams`. Outside its footprint it clamps like the
grid phantom: values extend constantly and the gradient across the edge is
zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.paper import BEST_BETA
from vic_drake.tissue.phantom.base import Phantom, TissueSample


@dataclass(frozen=True)
class SyntheticChestParams:
    """Every parameter of the synthetic chest phantom (base frame, SI units).

    The torso is a 33 x 33 x 23 cm block whose top is a smooth dome with a
    hump, placed where the real phantom lay on the rig (the measured map's
    region sits inside it), so the same scan scenarios run on both. Ribs run
    along y and are crossed by scans along x, as on the real phantom.

    The defaults are the measured phantom's twin: the fit of
    :func:`vic_drake.estimation.chest_fit.fit_synthetic_chest` to the
    measured map (``phantom_map/``), rounded; the command and its output are
    in docs/decisions.md, "Synthetic chest: the measured phantom's twin".
    """

    center_x_m: float = -0.06  # Torso centre, x.
    center_y_m: float = -0.36  # Torso centre, y (the scan line).
    length_x_m: float = 0.33  # Torso extent along x (head-feet).
    width_y_m: float = 0.33  # Torso extent along y (left-right).
    height_m: float = 0.23  # Torso thickness; its base is at top_z_m - height_m.
    # Surface: top_z - cx (x - x_dome)^2 - cy (y - y_dome)^2 + a Gaussian
    # hump ("shoulder") of height shoulder_rise_m and radii (rx, ry).
    top_z_m: float = 0.1260  # Dome apex height, m.
    dome_dx_m: float = -0.3177  # Dome apex relative to the torso centre, x.
    dome_dy_m: float = -0.0567  # Dome apex relative to the torso centre, y.
    curvature_x_per_m: float = 0.1764  # Dome: z drops curvature * dx^2 along x.
    curvature_y_per_m: float = 3.328  # Dome: z drops curvature * dy^2 along y.
    shoulder_rise_m: float = 0.0455  # Height of the hump.
    shoulder_dx_m: float = 0.0465  # Hump centre relative to the torso centre, x.
    shoulder_dy_m: float = 0.1660  # Hump centre relative to the torso centre, y.
    shoulder_radius_m: float = 0.0737  # Gaussian radius of the hump along x.
    shoulder_radius_y_m: float = 0.1994  # Its radius along y.
    # Rib centre lines: x = center_x + offset + tilt dy + bend dy^2, with
    # dy = y - center_y; each rib's kappa rise is (kappa_rib - kappa_soft)
    # times its scale (times muscle_factor for the muscle-covered rib).
    rib_offsets_x_m: tuple[float, ...] = (-0.0454, -0.0092, 0.0355, 0.0721)
    rib_scales: tuple[float, ...] = (1.382, 0.704, 1.0, 1.0)
    rib_tilt: float = 0.0996  # dx/dy of the rib lines.
    rib_bend_per_m: float = 1.128
    rib_sigma_m: float = 0.0083  # Gaussian half-width of a rib's stiffness band.
    muscle_rib_index: int = 2  # The rib under the pectoral muscle (-1 for none).
    muscle_factor: float = 0.252  # Fraction of the rib's stiffness rise it keeps.
    # Soft tissue: kappa_soft exp(-(x - x_soft)^2 / (2 w^2)), x_soft =
    # center_x + soft_center_dx_m, w = soft_width_x_m (inf: uniform).
    kappa_soft: float = 5585.0  # Soft-tissue kappa at its plateau, N/m^beta.
    kappa_rib: float = 9253.0  # kappa_soft + the rise over a bare rib, N/m^beta.
    soft_center_dx_m: float = 0.0251
    soft_width_x_m: float = 0.1138
    kappa_texture: float = 0.0446  # Relative amplitude of smooth soft-tissue variation.
    # lambda = lam_ref * (kappa / kappa_ref)^lam_exponent (log-log least
    # squares over the measured map).
    lam_ref: float = 50754.0
    kappa_ref: float = 5531.0
    lam_exponent: float = 1.283
    beta: float = BEST_BETA  # Hunt-Crossley exponent.
    texture_seed: int = 7  # Seed of the soft-tissue texture (deterministic).
    texture_modes: int = 6  # Number of sinusoidal texture modes.

    def __post_init__(self):
        for name in (
            "length_x_m",
            "width_y_m",
            "height_m",
            "rib_sigma_m",
            "shoulder_radius_m",
            "shoulder_radius_y_m",
            "soft_width_x_m",
            "kappa_soft",
            "kappa_rib",
            "lam_ref",
            "kappa_ref",
            "beta",
        ):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise VicDrakeError(
                    f"SyntheticChestParams.{name} must be > 0, got {value!r}"
                )
        if self.kappa_rib < self.kappa_soft:
            raise VicDrakeError(
                f"SyntheticChestParams.kappa_rib ({self.kappa_rib}) must be >= "
                f"kappa_soft ({self.kappa_soft})"
            )
        if not 0 <= self.muscle_factor <= 1:
            raise VicDrakeError(
                f"SyntheticChestParams.muscle_factor must be in [0, 1], got {self.muscle_factor!r}"
            )
        if not -1 <= self.muscle_rib_index < len(self.rib_offsets_x_m):
            raise VicDrakeError(
                f"SyntheticChestParams.muscle_rib_index must be -1 or in "
                f"[0, {len(self.rib_offsets_x_m) - 1}], got {self.muscle_rib_index!r}"
            )
        if len(self.rib_scales) not in (0, len(self.rib_offsets_x_m)) or not all(
            np.isfinite(v) and v >= 0 for v in self.rib_scales
        ):
            raise VicDrakeError(
                "SyntheticChestParams.rib_scales must be empty or hold one number >= 0 "
                f"per rib ({len(self.rib_offsets_x_m)}), got {self.rib_scales!r}"
            )
        if not 0 <= self.kappa_texture < 1:
            raise VicDrakeError(
                f"SyntheticChestParams.kappa_texture must be in [0, 1), got {self.kappa_texture!r}"
            )


class SyntheticChestPhantom(Phantom):
    """An analytic chest phantom: dome, shoulder, ribs under soft tissue."""

    def __init__(self, params: SyntheticChestParams | None = None):
        self.params = params or SyntheticChestParams()
        self.beta = self.params.beta
        self.name = "synthetic"
        rng = np.random.default_rng(self.params.texture_seed)
        n = self.params.texture_modes
        # Wavelengths of 4-12 cm, random phases and directions.
        self._tex_k = rng.uniform(2 * np.pi / 0.12, 2 * np.pi / 0.04, n)
        self._tex_dir = rng.uniform(0, np.pi, n)
        self._tex_phase = rng.uniform(0, 2 * np.pi, n)

    def content_key(self):
        # Everything the phantom answers follows from its parameters (the
        # texture too, through its seed); the name is copied into a lookup.
        # A subclass may answer differently: it shares nothing by default.
        if type(self) is not SyntheticChestPhantom:
            return None
        key = ("synthetic chest", self.params, self.name)
        try:
            hash(key)
        except TypeError:  # Parameters holding a list: no sharing.
            return None
        return key

    @property
    def bounds(self):
        p = self.params
        return (
            p.center_x_m - p.length_x_m / 2,
            p.center_x_m + p.length_x_m / 2,
            p.center_y_m - p.width_y_m / 2,
            p.center_y_m + p.width_y_m / 2,
        )

    @property
    def base_z_m(self) -> float:
        return self.params.top_z_m - self.params.height_m

    def rib_centres_x(self, y) -> np.ndarray:
        """x of every rib's centre line at y: array (n_ribs, *y.shape)."""
        p = self.params
        y = np.asarray(y, float)
        dy = y - p.center_y_m
        return np.array(
            [
                p.center_x_m + o + p.rib_tilt * dy + p.rib_bend_per_m * dy**2
                for o in p.rib_offsets_x_m
            ]
        )

    def _clamp(self, x, y):
        x_min, x_max, y_min, y_max = self.bounds
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        return np.clip(x, x_min, x_max), np.clip(y, y_min, y_max)

    def _surface(self, x, y):
        p = self.params
        dx, dy = x - p.center_x_m, y - p.center_y_m
        z = (
            p.top_z_m
            - p.curvature_x_per_m * (dx - p.dome_dx_m) ** 2
            - p.curvature_y_per_m * (dy - p.dome_dy_m) ** 2
        )
        r2 = ((dx - p.shoulder_dx_m) / p.shoulder_radius_m) ** 2 + (
            (dy - p.shoulder_dy_m) / p.shoulder_radius_y_m
        ) ** 2
        return z + p.shoulder_rise_m * np.exp(-r2)

    def _kappa(self, x, y):
        p = self.params
        dx, dy = x - p.center_x_m, y - p.center_y_m
        tex = np.zeros_like(x)
        for k, a, ph in zip(self._tex_k, self._tex_dir, self._tex_phase):
            tex = tex + np.sin(k * (np.cos(a) * dx + np.sin(a) * dy) + ph)
        tex = tex / np.sqrt(len(self._tex_k) / 2.0)  # about unit RMS
        plateau = np.exp(-0.5 * ((dx - p.soft_center_dx_m) / p.soft_width_x_m) ** 2)
        soft = p.kappa_soft * plateau * (1.0 + p.kappa_texture * np.tanh(tex))
        scales = p.rib_scales or (1.0,) * len(p.rib_offsets_x_m)
        rib = np.zeros_like(x)
        for i, xc in enumerate(self.rib_centres_x(y)):
            scale = scales[i] * (p.muscle_factor if i == p.muscle_rib_index else 1.0)
            rib = np.maximum(
                rib, scale * np.exp(-0.5 * ((x - xc) / p.rib_sigma_m) ** 2)
            )
        return soft + (p.kappa_rib - p.kappa_soft) * rib

    def sample(self, x, y) -> TissueSample:
        xq, yq = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        xc, yc = self._clamp(xq, yq)
        h = 1e-5
        gx = (self._surface(xc + h, yc) - self._surface(xc - h, yc)) / (2 * h)
        gy = (self._surface(xc, yc + h) - self._surface(xc, yc - h)) / (2 * h)
        x_min, x_max, y_min, y_max = self.bounds
        gx = np.where((xq >= x_min) & (xq <= x_max), gx, 0.0)
        gy = np.where((yq >= y_min) & (yq <= y_max), gy, 0.0)
        kappa = self._kappa(xc, yc)
        p = self.params
        lam = p.lam_ref * (kappa / p.kappa_ref) ** p.lam_exponent
        return TissueSample(self._surface(xc, yc), gx, gy, kappa, lam)
