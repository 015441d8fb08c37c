"""The ``offline_sim`` stage: C1 and C2 from palpations simulated on the phantom."""

import pytest

from vic_drake.reproduce import ReproduceOptions, reproduce


@pytest.mark.slow
def test_offline_sim_stage_evaluates_c1_and_c2(tmp_path, monkeypatch):
    """Palpations simulated on the synthetic chest (no data needed).

    On the relaxing tissue C2 holds; on the plain-HC control it does not
    (the estimator fits its own model as well from a short palpation).
    """
    # A clone without the data: no $VIC_DRAKE_DATA, no ../shared/data.
    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    monkeypatch.setattr("vic_drake.paths.DEFAULT_DATA_DIR", tmp_path / "no_data")
    out = tmp_path / "out"
    result = reproduce(
        ReproduceOptions(
            out_dir=out,
            quick=True,
            phantom="synthetic",
            stages=("offline_sim", "claims", "report"),
        )
    )
    c1, c2 = result.claims["C1"], result.claims["C2"]
    assert c1["pass_sim"] is True and c1["sim"]["best_beta"] == pytest.approx(1.35)
    assert c1["real"] is None and c1["pass_real"] is None
    assert c2["sim"] is not None and c2["pass_sim"] is True
    stage = result.results["offline_sim"]
    assert stage["c2_relaxing"]["pass"] is True
    assert stage["control_hc"]["c2_pass"] is False
    assert {"comparisons", "curves", "residuals", "decay"} <= set(stage)
    truth = stage["truth"]
    assert truth["kappa_relaxed"] < truth["kappa"]
    for err in stage["estimation_error"].values():
        # A plain fit of a short palpation lands between the relaxed and the
        # instantaneous kappa.
        assert -0.08 < err["kappa_rel_error_vs_instantaneous"] < 0.0
        assert err["kappa_rel_error_vs_relaxed"] > 0.0
    assert (out / "logs" / "palpation_sim_hc_2.5hz.parquet").is_file()
    assert (out / "logs" / "palpation_sim_2.5hz.parquet").is_file()
    assert (out / "logs" / "palpation_sim_2.5hz.yaml").is_file()
    assert (out / "figures" / "table1_sim.png").is_file()
