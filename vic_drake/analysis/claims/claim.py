"""A claim's verdict, and the JSON form of claims.json.

``pass`` is True when the simulated side was evaluated and passes and the
real side, where evaluated, passes too (the reproduction must show the
claim; the real logs must not contradict it). ``pass_sim`` and
``pass_real`` give each side's verdict (None when not evaluated). A side
that could not be evaluated is ``None`` with the reason in ``detail``; it
never counts as a pass.

``status`` says which of three a claim is: "pass", "fail" (a side was
evaluated and contradicts the claim) or "not evaluated" (the simulated side
could not be evaluated and no evaluated side contradicts the claim; the
reason is in ``detail``). A claim that was not evaluated is never a "fail".
"""

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from vic_drake.analysis.claims.thresholds import STATEMENTS

#: The three verdicts of a claim (``Claim.status``, "status" in claims.json).
PASS, FAIL, NOT_EVALUATED = "pass", "fail", "not evaluated"


def claim_status(claim: Mapping) -> str:
    """The status of a claim read from claims.json (older files lack "status")."""
    if claim.get("status") in (PASS, FAIL, NOT_EVALUATED):
        return claim["status"]
    if claim.get("pass_sim") is False or claim.get("pass_real") is False:
        return FAIL
    return PASS if claim.get("pass") else NOT_EVALUATED


@dataclass(frozen=True)
class Claim:
    """One claim's verdict.

    Attributes:
        id: "C1" ... "C7".
        statement: what the paper claims, as checked here.
        paper: the paper's value (number, dict or text).
        sim: the simulated value (dict of metrics) or None if not evaluated.
        real: the value in the real logs or None where no log exists.
        pass_sim: the simulated side's verdict, None if not evaluated.
        pass_real: the real side's verdict, None if not evaluated.
        detail: thresholds used and reasons for any side not evaluated.
    """

    id: str
    statement: str
    paper: Any
    sim: Any
    real: Any
    pass_sim: bool | None
    pass_real: bool | None
    detail: str = ""

    @property
    def passed(self) -> bool:
        return bool(self.pass_sim) and self.pass_real is not False

    @property
    def status(self) -> str:
        """ "pass", "fail" or "not evaluated" (see the module's docstring)."""
        if self.pass_sim is False or self.pass_real is False:
            return FAIL
        return PASS if self.pass_sim else NOT_EVALUATED

    def to_dict(self) -> dict:
        return {
            "statement": self.statement,
            "paper": self.paper,
            "sim": self.sim,
            "real": self.real,
            "pass": self.passed,
            "status": self.status,
            "pass_sim": self.pass_sim,
            "pass_real": self.pass_real,
            "detail": self.detail,
        }


def claims_to_json_dict(claims: Sequence[Claim]) -> dict:
    """{"C1": {...}, ...} as written to claims.json."""
    return {c.id: c.to_dict() for c in claims}


def clean(value):
    """Plain Python numbers (floats rounded to 6 significant digits)."""
    if isinstance(value, Mapping):
        return {str(k): clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [clean(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return float(f"{v:.6g}") if np.isfinite(v) else None
    return value


def two_sided(
    claim_id: str,
    paper: Any,
    sim: tuple[Any, bool | None],
    real: tuple[Any, bool | None],
    detail: str,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """The Claim ``claim_id`` (its statement from ``thresholds.STATEMENTS``)
    from its two sides, each (value, verdict), (None, None) for a side that
    was not evaluated; ``detail`` says the thresholds, and a side whose
    verdict is None adds its reason (``reason_sim``, ``reason_real``)."""
    (sv, sp), (rv, rp) = sim, real
    extra = _not_evaluated(
        reason_sim if sp is None else None, reason_real if rp is None else None
    )
    return Claim(
        claim_id,
        STATEMENTS[claim_id],
        paper,
        clean(sv),
        clean(rv),
        sp,
        rp,
        "; ".join(p for p in (detail, extra) if p),
    )


def _not_evaluated(reason_sim: str | None, reason_real: str | None) -> str:
    parts = []
    if reason_sim:
        parts.append(f"sim not evaluated: {reason_sim}")
    if reason_real:
        parts.append(f"real not evaluated: {reason_real}")
    return "; ".join(parts)
