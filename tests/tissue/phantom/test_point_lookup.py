"""PointLookup: the per-tick scalar lookup and its per-phantom cache."""

import pytest

from .planes import plane_phantom


def test_point_lookup_cached_per_phantom_and_mode():
    import copy

    p = plane_phantom()
    fast = p.point_lookup()
    assert p.point_lookup() is fast
    assert fast(0.0437, 0.0213) == pytest.approx(
        tuple(float(v) for v in vars(p.sample(0.0437, 0.0213)).values())
    )
    # A copy switched to nearest lookup must not reuse the bilinear lookup.
    q = copy.copy(p)
    q.lookup = "nearest"
    assert q.point_lookup() is not fast
    assert q.point_lookup()(0.0437, 0.0213)[3] == pytest.approx(1000 + 1e4 * 0.04)
    assert p.point_lookup() is fast


def test_synthetic_phantoms_of_equal_content_share_one_lookup():
    from dataclasses import replace

    from vic_drake.tissue.phantom import SyntheticChestPhantom
    from vic_drake.tissue.phantom.synthetic_chest import SyntheticChestParams

    res = 0.004  # coarse: the sharing, not the raster, is under test
    first = SyntheticChestPhantom().point_lookup(resolution_m=res)
    # A new phantom of the same parameters reuses the raster (no rebuild)...
    assert SyntheticChestPhantom().point_lookup(resolution_m=res) is first
    # ...but not at another resolution, with other parameters or another name.
    assert SyntheticChestPhantom().point_lookup(resolution_m=2 * res) is not first
    other = SyntheticChestPhantom(replace(SyntheticChestParams(), top_z_m=0.13))
    assert other.point_lookup(resolution_m=res) is not first
    renamed = SyntheticChestPhantom()
    renamed.name = "patient"
    shared = renamed.point_lookup(resolution_m=res)
    assert shared is not first and shared.name == "patient"


def test_shared_lookups_are_bounded_and_subclasses_keep_their_own():
    from dataclasses import replace

    from vic_drake.tissue.phantom import SyntheticChestPhantom, base
    from vic_drake.tissue.phantom.synthetic_chest import SyntheticChestParams

    for i in range(base.SHARED_LOOKUPS_MAX + 2):
        params = replace(SyntheticChestParams(), top_z_m=0.12 + 1e-4 * i)
        SyntheticChestPhantom(params).point_lookup(resolution_m=0.01)
    assert len(base._SHARED_LOOKUPS) == base.SHARED_LOOKUPS_MAX

    class Shifted(SyntheticChestPhantom):
        def sample(self, x, y):
            s = super().sample(x, y)
            return type(s)(s.surface_z_m + 0.01, s.dz_dx, s.dz_dy, s.kappa, s.lam)

    plain = SyntheticChestPhantom().point_lookup(resolution_m=0.01)
    shifted = Shifted().point_lookup(resolution_m=0.01)
    assert shifted is not plain
    x, y = -0.06, -0.36
    assert shifted(x, y)[0] == pytest.approx(plain(x, y)[0] + 0.01)


def test_a_pickled_phantom_leaves_its_lookups_behind_and_answers_alike():
    import pickle

    p = plane_phantom()
    before = len(pickle.dumps(p))
    fast = p.point_lookup()
    text = pickle.dumps(p)
    assert len(text) == before  # The cache is not shipped (to a Dask worker).
    q = pickle.loads(text)
    assert "_point_lookups" not in vars(q) and p.point_lookup() is fast
    assert q.point_lookup()(0.0437, 0.0213) == pytest.approx(fast(0.0437, 0.0213))
