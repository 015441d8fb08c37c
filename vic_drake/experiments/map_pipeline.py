"""The map pipeline: palpation campaign -> surface fit and GP maps -> TissueMap.

:func:`run_map_pipeline` is the paper's offline phase end to end, as both
``vic-drake map`` and the reproduction's map stage run it: a simulated
palpation campaign on a grid of the phantom
(:func:`~vic_drake.experiments.palpation_campaign.run_campaign`), the
GRIDFIT-like surface and the GP maps of kappa and lambda
(:func:`~vic_drake.estimation.tissue_map.build_tissue_map`), and, when asked,
the errors and ribs of the maps against the phantom's truth
(:func:`~vic_drake.analysis.map_compare.compare_with_phantom`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from vic_drake.analysis.map_compare import MapComparison, compare_with_phantom
from vic_drake.estimation.gp_fit import GpMapParams
from vic_drake.estimation.tissue_map import TissueMap, build_tissue_map
from vic_drake.experiments.campaign_params import CampaignParams
from vic_drake.experiments.palpation_campaign import CampaignResult, run_campaign

#: The size of the region the paper palpated (x, y), m.
PAPER_REGION_SIZE_M = (0.20, 0.10)


def default_region(phantom) -> tuple[float, float, float, float]:
    """The measured map's own grid; for an analytic chest its central 20 x 10 cm.

    Returns:
        (x_min, x_max, y_min, y_max), m, base frame.
    """
    x_min, x_max, y_min, y_max = (float(v) for v in phantom.bounds)
    params = getattr(phantom, "params", None)
    if params is None or not hasattr(params, "center_x_m"):
        return (x_min, x_max, y_min, y_max)
    hx, hy = PAPER_REGION_SIZE_M[0] / 2, PAPER_REGION_SIZE_M[1] / 2
    cx, cy = params.center_x_m, params.center_y_m
    return (
        max(x_min, cx - hx),
        min(x_max, cx + hx),
        max(y_min, cy - hy),
        min(y_max, cy + hy),
    )


@dataclass
class MapPipelineResult:
    """A tissue map built from a simulated palpation campaign.

    Attributes:
        campaign: the fitted campaign (per-point fits with the truth, lag,
            timings).
        tissue_map: surface, kappa and lambda maps (and GP std) on the grid.
        comparison: errors and ribs against the phantom's truth; None when
            the pipeline ran with ``compare=False``.
        params: the campaign parameters that ran (region filled in).
    """

    campaign: CampaignResult
    tissue_map: TissueMap
    comparison: MapComparison | None
    params: CampaignParams

    @property
    def region_m(self) -> tuple[float, float, float, float]:
        """The palpated and mapped region (x_min, x_max, y_min, y_max), m."""
        return self.params.region_m


def run_map_pipeline(
    phantom,
    params: CampaignParams | None = None,
    *,
    resolution_m: float = 1e-4,
    gp: GpMapParams | None = None,
    compare: bool = True,
    progress=None,
    scheduler: str | None = None,
) -> MapPipelineResult:
    """Palpates a phantom on a grid, fits every point, maps it, compares it.

    Args:
        phantom: any :class:`vic_drake.tissue.Phantom` (its beta is used).
        params: the campaign; its ``region_m`` is palpated and mapped
            (None: :func:`default_region` of the phantom).
        resolution_m: map grid spacing, m (paper: 0.1 mm).
        gp: GP settings (default: ``GpMapParams()``).
        compare: also compare the maps with the phantom's truth (samples
            the phantom on the whole map grid).
        progress: optional callable(str) for progress lines.
        scheduler: simulate the palpations on the Dask cluster at this
            address (see
            :func:`~vic_drake.experiments.palpation_campaign.run_campaign`).

    Returns:
        A :class:`MapPipelineResult`.
    """
    say = progress or (lambda message: None)
    params = params or CampaignParams()
    if params.region_m is None:
        params = replace(params, region_m=default_region(phantom))
    campaign = run_campaign(phantom, params, progress=progress, scheduler=scheduler)
    say(f"surface fit and GP maps every {resolution_m * 1e3:g} mm")
    tissue_map = build_tissue_map(
        campaign.points,
        params.region_m,
        beta=campaign.beta,
        resolution_m=resolution_m,
        gp=gp,
        progress=progress,
    )
    comparison = compare_with_phantom(tissue_map, phantom) if compare else None
    return MapPipelineResult(
        campaign=campaign, tissue_map=tissue_map, comparison=comparison, params=params
    )


__all__ = [
    "PAPER_REGION_SIZE_M",
    "MapPipelineResult",
    "default_region",
    "run_map_pipeline",
]
