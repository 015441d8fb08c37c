"""Scores of one comparison run, made up, for tests that fake the scans."""


def fake_scores(rmse, p99=9.0):
    """A run's scores (the keys the comparison's table and win count read): force
    RMSE ``rmse``, rib p99 ``p99``, every other score 0.5."""
    keys = [
        "force_rmse_dithered_truth_N",
        "dither_rms_N",
        "penetration_err_mm",
        "kappa_rel_err_median",
        "tank_min_J",
    ]
    return {"force_rmse_true_N": rmse, "rib_p99_force_N": p99} | dict.fromkeys(
        keys, 0.5
    )
