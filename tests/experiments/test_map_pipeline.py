"""The map pipeline: campaign, surface and GP maps, comparison with the truth."""

import numpy as np
import pytest

from vic_drake.experiments.campaign_params import CampaignParams
from vic_drake.experiments.map_pipeline import default_region, run_map_pipeline
from vic_drake.tissue import SyntheticChestPhantom


def test_synthetic_default_region_is_the_papers_20_by_10_cm():
    x0, x1, y0, y1 = default_region(SyntheticChestPhantom())
    assert (x1 - x0, y1 - y0) == pytest.approx((0.20, 0.10))


def test_pipeline_maps_the_campaign_region():
    phantom = SyntheticChestPhantom()
    region = (-0.08, -0.06, -0.37, -0.36)
    got = run_map_pipeline(
        phantom,
        CampaignParams(region_m=region, seed=2),
        resolution_m=1e-3,
        compare=False,
    )
    assert got.comparison is None
    assert got.region_m == region
    assert len(got.campaign.points) == 6 and got.campaign.points["ok"].all()
    tmap = got.tissue_map
    assert tmap.kappa.shape == (tmap.x_m.size, tmap.y_m.size) == (21, 11)
    np.testing.assert_allclose([tmap.x_m[0], tmap.x_m[-1]], region[:2], atol=1e-9)
