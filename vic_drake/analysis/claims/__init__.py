"""The paper's claims, each a metric computed from logs, with a pass/fail.

Every claim of the paper that vic_drake reproduces is a pure function here.
It takes the results of the pipeline's stages (fit residuals, a kappa map,
per-scan metrics reduced from logged signals) for the simulation and, where
the paper's measurements exist, for the real rig, and returns a
:class:`Claim`: the statement, the paper's value, the simulated value, the
real value and whether the claim holds.
"""

from vic_drake.analysis.claims.claim import (
    FAIL,
    NOT_EVALUATED,
    PASS,
    Claim,
    claim_status,
    claims_to_json_dict,
)
from vic_drake.analysis.claims.evaluate import ClaimInputs, evaluate_claims
from vic_drake.analysis.claims.offline import (
    ModelResiduals,
    claim_c1,
    claim_c2,
    claim_c3,
    residual_decay,
)
from vic_drake.analysis.claims.scan_summary import ScanLimits, scan_metrics
from vic_drake.analysis.claims.scans import claim_c4, claim_c5, claim_c6, claim_c7
from vic_drake.analysis.claims.thresholds import STATEMENTS

__all__ = [
    "FAIL",
    "NOT_EVALUATED",
    "PASS",
    "Claim",
    "claim_status",
    "ClaimInputs",
    "ModelResiduals",
    "STATEMENTS",
    "ScanLimits",
    "claim_c1",
    "claim_c2",
    "claim_c3",
    "claim_c4",
    "claim_c5",
    "claim_c6",
    "claim_c7",
    "claims_to_json_dict",
    "evaluate_claims",
    "residual_decay",
    "scan_metrics",
]
