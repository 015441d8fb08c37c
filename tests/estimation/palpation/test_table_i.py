"""Table I: the beta sweep, and the model comparison on the real palpation logs."""

import numpy as np
import pytest

from vic_drake.estimation.palpation import PalpationData, compare_models, sweep_beta
from vic_drake.realdata import read_bag

from .synthetic import synthetic_palpation

PALPATION_LOGS = ("test_soft_1hz", "test_soft_2hz", "test_soft_25hz")


def test_sweep_finds_the_generating_beta():
    data = synthetic_palpation(kappa=2000.0, lam=15000.0, beta=1.2, noise_N=0.02)
    sweep = sweep_beta(data)
    assert sweep.betas[0] == 1.0 and sweep.betas[-1] == 2.0 and sweep.betas.size == 21
    assert sweep.best_beta == pytest.approx(1.2, abs=0.01)
    assert sweep.best_fit.rms_N <= sweep.rms_N.min() + 1e-12


@pytest.fixture(scope="module")
def real_logs(data_dir):
    return {
        name: PalpationData.from_frame(read_bag(data_dir / "palpation" / name))
        for name in PALPATION_LOGS
    }


@pytest.fixture(scope="module")
def real_comparisons(real_logs):
    return {name: compare_models(data, sweep=True) for name, data in real_logs.items()}


@pytest.mark.realdata
@pytest.mark.parametrize("name", PALPATION_LOGS)
def test_hunt_crossley_beats_kelvin_voigt_on_real_logs(real_comparisons, name):
    c = real_comparisons[name]
    assert 0.0 <= c.lag_s <= 0.2
    assert c.hunt_crossley[1.35].rms_N < c.kelvin_voigt.rms_N
    assert c.hunt_crossley[1.35].relative < c.kelvin_voigt.relative
    # The paper's beta = 1.35 is close to each log's optimum.
    assert 1.2 <= c.best_beta <= 1.5
    assert c.hunt_crossley[1.35].kappa > 0 and c.hunt_crossley[1.35].lam > 0


@pytest.mark.realdata
def test_table_i_ordering_on_soft_1hz(real_comparisons):
    c = real_comparisons["test_soft_1hz"]
    hc = c.hunt_crossley
    assert (
        hc[1.35].relative
        < hc[1.5].relative
        < hc[1.1].relative
        < c.kelvin_voigt.relative
    )


@pytest.mark.realdata
def test_real_logs_agree_on_the_soft_material(real_comparisons):
    """The three logs palpate the same soft material, so once the lag is
    removed their HC parameters should agree (an unremoved lag shows up as a
    wrong lambda: at lag 0 the 1 Hz log gives lambda ~ 1.6e3, 13x too low)."""
    fits = [c.hunt_crossley[1.35] for c in real_comparisons.values()]
    lams = np.array([f.lam for f in fits])
    assert np.all(np.abs(lams / lams.mean() - 1.0) < 0.25), lams
    # 1 and 2 Hz only: the 2.5 Hz log's logged surface sits ~1.5 mm above the
    # tissue (its force stays below 0.3 N over the first 3 mm of the fast
    # approach, half of which the ~50 ms lag explains), which lowers kappa.
    kappas = np.array([f.kappa for f in fits[:2]])
    assert abs(kappas[0] / kappas[1] - 1.0) < 0.1, kappas
    lags = np.array([c.lag_s for c in real_comparisons.values()])
    assert np.all((lags > 0.02) & (lags < 0.07)), lags
