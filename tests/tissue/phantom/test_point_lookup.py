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
