"""All claims from the results the pipeline gathered."""

from dataclasses import dataclass, field

from vic_drake.analysis.claims.claim import Claim
from vic_drake.analysis.claims.offline import (
    ModelResiduals,
    claim_c1,
    claim_c2,
    claim_c3,
)
from vic_drake.analysis.claims.scan_summary import ScanLimits
from vic_drake.analysis.claims.scans import claim_c4, claim_c5, claim_c6, claim_c7


@dataclass
class ClaimInputs:
    """Everything the claims need, gathered by the pipeline (None = absent).

    The ``reasons`` dict maps "C1.sim", "C4.real", ... to why a side is absent.
    """

    residuals_sim: ModelResiduals | None = None
    residuals_real: ModelResiduals | None = None
    decay_sim: tuple | None = None
    decay_real: tuple | None = None
    ribs_sim: dict | None = None
    ribs_real: dict | None = None
    nominal_sim: dict | None = (
        None  # {"cs": metrics, "cf": ..., "vs-cf": ..., "vs-vf": ...}
    )
    nominal_real: dict | None = None
    disturbance_sim: dict | None = None  # {"vs-vf": ..., "cs": ..., "cf": ...}
    disturbance_real: dict | None = None
    limits: ScanLimits = field(default_factory=ScanLimits)
    reasons: dict = field(default_factory=dict)


def evaluate_claims(inp: ClaimInputs) -> list[Claim]:
    """All claims C1-C7 from the gathered inputs."""
    r = inp.reasons

    def why(cid, side):
        return r.get(f"{cid}.{side}") or r.get(side) or "stage result missing"

    return [
        claim_c1(
            inp.residuals_sim,
            inp.residuals_real,
            reason_sim=why("C1", "sim"),
            reason_real=why("C1", "real"),
        ),
        claim_c2(
            inp.decay_sim,
            inp.decay_real,
            reason_sim=why("C2", "sim"),
            reason_real=why("C2", "real"),
        ),
        claim_c3(
            inp.ribs_sim,
            inp.ribs_real,
            reason_sim=why("C3", "sim"),
            reason_real=why("C3", "real"),
        ),
        claim_c4(
            inp.nominal_sim,
            inp.nominal_real,
            reason_sim=why("C4", "sim"),
            reason_real=why("C4", "real"),
        ),
        claim_c5(
            inp.nominal_sim,
            inp.nominal_real,
            reason_sim=why("C5", "sim"),
            reason_real=why("C5", "real"),
        ),
        claim_c6(
            (inp.nominal_sim or {}).get("vs-vf"),
            (inp.nominal_real or {}).get("vs-vf"),
            eps_d_m=inp.limits.eps_d_m,
            reason_sim=why("C6", "sim"),
            reason_real=why("C6", "real"),
        ),
        claim_c7(
            inp.disturbance_sim,
            inp.disturbance_real,
            limits=inp.limits,
            reason_sim=why("C7", "sim"),
            reason_real=why("C7", "real"),
        ),
    ]
