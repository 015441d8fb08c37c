"""Why a claim failed, in a line per side (read from claims.json).

A claim's ``detail`` gives its thresholds and why a side was not evaluated;
it does not say what an evaluated side missed. :func:`fail_reasons` does,
for the console of ``vic-drake reproduce``: per failing log where a side is
checked log by log (C2: which criterion, the value and the threshold), the
failed checks where the side has them (C7), else the side's scalar values
and the claim's pass criterion.
"""

from collections.abc import Mapping

from vic_drake.analysis.claims.claim import FAIL, claim_status
from vic_drake.analysis.claims.offline import c2_missed

_SIDES = (("sim", "simulation"), ("real", "real logs"))


def c2_misses(value) -> list[str]:
    """'log misses what' for each residual curve of a C2 side that fails.

    Args:
        value: a C2 side as in claims.json: {log name: curve metrics with
            its own ``pass``}, or one curve's metrics (no name).
    """
    if not isinstance(value, Mapping):
        return []
    if "ratio_last_first" in value:  # One curve.
        missed = c2_missed(value)
        return [f"misses {', '.join(missed)}"] if missed else []
    out = []
    for name, d in value.items():
        if isinstance(d, Mapping) and d.get("pass") is False:
            missed = c2_missed(d)
            out.append(f"{name} misses {', '.join(missed) or 'a criterion'}")
    return out


def _criterion(detail: str) -> str | None:
    """The "pass: ..." part of a claim's detail."""
    for part in detail.split("; "):
        if part.startswith("pass:"):
            return part
    return None


def _scalars(value: Mapping) -> str:
    items = []
    for key, v in value.items():
        if isinstance(v, bool):
            items.append(f"{key} {str(v).lower()}")
        elif isinstance(v, (int, float)):
            items.append(f"{key} {v:.3g}")
    return ", ".join(items)


def _side_reason(cid: str, value, detail: str) -> str:
    """What one failing side missed."""
    if cid == "C2":
        misses = c2_misses(value)
        if misses:
            return "; ".join(misses)
    if isinstance(value, Mapping):
        per_item = [
            str(k)
            for k, v in value.items()
            if isinstance(v, Mapping) and v.get("pass") is False
        ]
        checks = value.get("checks")
        failed = (
            [str(k) for k, ok in checks.items() if ok is False]
            if isinstance(checks, Mapping)
            else []
        )
        if per_item:
            what = f"{', '.join(per_item)} fail(s)"
        elif failed:
            what = f"check(s) {', '.join(failed)} fail"
        else:
            what = _scalars(value)
    else:
        what = ""
    criterion = _criterion(detail)
    return "; ".join(p for p in (what or "contradicts it", criterion) if p)


def fail_reasons(cid: str, claim: Mapping) -> list[str]:
    """One line per side that contradicts a FAIL claim ([] unless FAIL).

    Args:
        cid: "C1" ... "C7".
        claim: the claim as in claims.json (``Claim.to_dict``).
    """
    if claim_status(claim) != FAIL:
        return []
    detail = claim.get("detail") or ""
    return [
        f"{label}: {_side_reason(cid, claim.get(side), detail)}"
        for side, label in _SIDES
        if claim.get(f"pass_{side}") is False
    ]
