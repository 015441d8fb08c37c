"""Safety campaigns: many closed-loop runs with sampled variations, on Dask.

:mod:`.spec` (the campaign YAML), :mod:`.plan` (each run's factors and
scenario), :mod:`.run` (one run on a worker, its metrics), :mod:`.engine`
(the runs on Dask, rows on disk, resume; the cluster itself is
:mod:`vic_drake.experiments.dask_cluster`), :mod:`.stats`,
:mod:`.report` (summary.json, summary.html, results.parquet) and
:mod:`.legend` (what each column of their tables means).
"""

from vic_drake.experiments.campaign.engine import read_rows, run_campaign
from vic_drake.experiments.campaign.plan import RunPlan, plan_campaign
from vic_drake.experiments.campaign.run import execute_run, run_metrics
from vic_drake.experiments.campaign.spec import CampaignSpec, Factor, load_campaign_spec
from vic_drake.experiments.campaign.stats import wilson_interval

__all__ = [
    "CampaignSpec",
    "Factor",
    "RunPlan",
    "execute_run",
    "load_campaign_spec",
    "plan_campaign",
    "read_rows",
    "run_campaign",
    "run_metrics",
    "wilson_interval",
]
