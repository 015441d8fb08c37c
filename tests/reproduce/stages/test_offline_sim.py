"""The ``offline_sim`` stage: C1 and C2 from palpations simulated on the phantom."""

import pytest

from vic_drake.reproduce import ReproduceOptions, reproduce


def test_offline_sim_stage_evaluates_c1_and_c2(tmp_path, monkeypatch):
    """Palpations simulated on the synthetic chest (no data needed)."""
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
    assert c2["sim"] is not None and c2["pass_sim"] in (True, False)
    assert (out / "logs" / "palpation_sim_2.5hz.parquet").is_file()
    assert (out / "logs" / "palpation_sim_2.5hz.yaml").is_file()
    assert (out / "figures" / "table1_sim.png").is_file()
