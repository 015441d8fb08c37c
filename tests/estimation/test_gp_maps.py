"""gp_maps keeps every name of the map pipeline importable from one module."""

from vic_drake.estimation import gp_maps, gp_predict, tissue_map


def test_gp_maps_reexports_the_map_pipeline():
    for name in gp_maps.__all__:
        assert hasattr(gp_maps, name), name
    assert gp_maps.build_tissue_map is tissue_map.build_tissue_map
    assert gp_maps.predict_std_grid is gp_predict.predict_std_grid
