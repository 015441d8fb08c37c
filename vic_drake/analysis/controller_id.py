"""Which controller a real scan log ran, and its settings, read from its signals.

Nothing here looks at a file or folder name: each controller's law is scored
on the logged signals and the law that explains the log wins, by a margin.

31-column logs (the variable-impedance controller, layout "controller"): in
the samples where the sensor reads contact and the logged F_ref,z is on
(nonzero: the controller's own contact flag agreed), VS-CF holds F_ref,z at
one constant and F_min,z = -(kappa + lam eps_dot) eps_max^beta, VS-VF gives
F_ref,z = -(kappa + lam eps_dot) eps_d^beta and F_min,z at one constant
(-9 N on the rig), eps_dot = z_surface_dot - z_dot (data README; the same
law as :func:`vic_drake.control.references.force_references`). The fraction
of those samples each law reproduces to :data:`LAW_TOL_N` is its score. The
stiffness QP weight R is read off the logged K_z in closed form
(:func:`identify_r_weight`) and confirmed by replaying the QP
(:func:`vic_drake.control.replay.replay_controller_log`).

9-column logs (the CS and CF baselines, layout "scan"): the FDCC stage
drives the tip until the net z error vanishes, so in contact the pressing
force follows ``f = K e + f0 + c z_dot`` with e = z - z_target (tip above
its target), K the CS stiffness (f0 = 0) or f0 the CF force (K = 0), and
c z_dot the FDCC's integrating lag (c = 1 / loop gain, see
:func:`vic_drake.analysis.identification.estimate_force_loop_gain`). Each
law (CS: f0 = 0; CF: K = 0) is fitted by least squares; its score is the
fraction of the force variance it explains.

:func:`identify_controller` returns a :class:`ControllerIdentification`;
when the signals cannot tell it raises :class:`VicDrakeError` saying what it
saw and which option to pass instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from vic_drake.analysis.r_weight_id import (
    LAW_TOL_N,
    LOGGED_SETTINGS,
    identify_r_weight,
    logged_setting,
)
from vic_drake.errors import VicDrakeError
from vic_drake.paper import BEST_BETA, CONTACT_THRESHOLD_N, CONTROLLERS

#: The 9-column logs pair each pose with the force read this many ticks
#: later (data README): row i's force goes with row i + 28's pose.
SCAN_FORCE_LAG_TICKS = 28
#: 31-column logs: the winning law must reproduce at least this fraction of
#: the referenced contact samples ...
MIN_EXPLAINED_31 = 0.9
#: ... and at least this much more of them than the other law.
MIN_MARGIN_31 = 0.5
#: 9-column logs: the winning law must explain at least this fraction of the
#: contact force's variance ...
MIN_EXPLAINED_9 = 0.8
#: ... and at least this much more than the other law.
MIN_MARGIN_9 = 0.2
#: Fewest contact samples to decide on: 0.5 s at the logs' 500 Hz.
MIN_CONTACT_SAMPLES = 250
VS_CONTROLLERS = ("vs-cf", "vs-vf")
SCAN_CONTROLLERS = ("cs", "cf")


@dataclass(frozen=True)
class ControllerIdentification:
    """What a real scan log ran, as read from its signals.

    Attributes:
        controller: "cs", "cf", "vs-cf" or "vs-vf".
        settings: the settings read from the log, by the names of the
            scenario fields they fill: ``r_weight`` (VS), ``force_ref_N``
            (VS-CF, CF), ``eps_d_m`` and ``force_min_z_N`` (VS-VF),
            ``stiffness_N_per_m`` (CS); 31-column logs also the settings
            they log (:data:`LOGGED_SETTINGS`; ``power_limit_W`` as logged,
            a positive magnitude).
        evidence: the scores the decision rests on and the quality figures
            of each setting (sample counts, explained fractions, the R
            spread and the confirming replay's K_z errors).
        given: True when the controller was given, not identified.
    """

    controller: str
    settings: dict = field(default_factory=dict)
    evidence: dict = field(default_factory=dict)
    given: bool = False

    def as_dict(self) -> dict:
        """A JSON-ready record (controller, given, settings, evidence)."""
        return {
            "controller": self.controller,
            "given": self.given,
            "settings": dict(self.settings),
            "evidence": dict(self.evidence),
        }

    def summary(self) -> str:
        """One line for a person: the class, its scores, the settings (no
        figure at rounding-noise level, so the line is the same on every
        machine)."""
        ev, st = self.evidence, self.settings
        how = "given" if self.given else "identified"
        parts = [f"{self.controller} ({how}"]
        if "vs_cf_explained" in ev:
            parts[0] += (
                f"; F_ref law explains {ev['vs_cf_explained']:.1%} as VS-CF, "
                f"{ev['vs_vf_explained']:.1%} as VS-VF of {ev['referenced_samples']} "
                f"contact samples; F_min law {ev['vs_cf_fmin_explained']:.1%} / "
                f"{ev['vs_vf_fmin_explained']:.1%}"
            )
        if "cs_explained" in ev:
            parts[0] += (
                f"; force variance explained {_share(ev['cs_explained'])} by f = K e, "
                f"{_share(ev['cf_explained'])} by f = f_ref of {ev['contact_samples']} "
                "contact samples"
            )
        parts[0] += ")"
        if "stiffness_N_per_m" in st:
            parts.append(f"K = {st['stiffness_N_per_m']:.4g} N/m")
        if "force_ref_N" in st:
            parts.append(f"F_ref = {st['force_ref_N']:.4g} N")
        if "eps_d_m" in st:
            parts.append(f"eps_d = {1e3 * st['eps_d_m']:.4g} mm")
        if "force_min_z_N" in st:
            parts.append(f"F_min,z = {st['force_min_z_N']:.4g} N")
        if "r_weight" in st:
            r = f"R = {st['r_weight']:.4g}"
            if "r_ticks" in ev:
                # The replay's errors (rounding noise) stay in the evidence.
                r += f" (from {ev['r_ticks']} ticks, confirmed by the QP replay)"
            parts.append(r)
        return ", ".join(parts)


def _share(explained: float) -> str:
    """An explained fraction as a percentage; "none" when a law fits worse
    than the mean force."""
    return f"{explained:.1%}" if explained > 0.0 else "none"


def _column(df: pd.DataFrame, name: str) -> np.ndarray:
    return df[name].to_numpy(dtype=float)


def _hc_unit_force(df: pd.DataFrame) -> np.ndarray:
    """kappa + lam eps_dot per row (eps_dot = z_surface_dot - z_dot), N/m^beta."""
    eps_dot = _column(df, "surface_velocity_m_per_s") - _column(df, "vz_m_per_s")
    return (
        _column(df, "kappa_N_per_m_beta")
        + _column(df, "lambda_N_s_per_m_beta1") * eps_dot
    )


def _explained(values: np.ndarray, law: np.ndarray) -> float:
    """Fraction of samples where the logged value matches the law."""
    if values.size == 0:
        return 0.0
    return float(np.mean(np.abs(values - law) <= LAW_TOL_N))


def vs_law_scores(real: pd.DataFrame) -> dict:
    """Scores the VS-CF and VS-VF reference laws on a 31-column log.

    The samples scored are those where the sensor reads contact and the
    logged F_ref,z is nonzero (the controller's own contact flag agreed):
    zero references at the contact edges or anywhere else in contact are
    counted (``reference_off_samples``) but neither law is asked to explain
    them. VS-CF's constant is the median referenced F_ref,z; VS-VF's eps_d
    the median of (F_ref,z / -(kappa + lam eps_dot))^(1/beta).

    Returns:
        dict: sample counts, the four explained fractions
        (``vs_cf_explained``, ``vs_vf_explained`` for F_ref,z;
        ``vs_cf_fmin_explained``, ``vs_vf_fmin_explained`` for F_min,z) and
        the fitted constants ``force_ref_N``, ``eps_d_m``, ``force_min_z_N``.
    """
    contact = _column(real, "sensor_force_z_N") < -CONTACT_THRESHOLD_N
    f_ref = _column(real, "force_ref_z_N")
    f_min = _column(real, "force_min_z_N")
    use = contact & (f_ref != 0.0) & np.isfinite(f_ref) & np.isfinite(f_min)
    hc = _hc_unit_force(real)
    out = {
        "contact_samples": int(contact.sum()),
        "referenced_samples": int(use.sum()),
        "reference_off_samples": int((contact & (f_ref == 0.0)).sum()),
    }
    r, m, h = f_ref[use], f_min[use], hc[use]
    if r.size == 0:
        return {
            **out,
            **dict.fromkeys(
                (
                    "vs_cf_explained",
                    "vs_vf_explained",
                    "vs_cf_fmin_explained",
                    "vs_vf_fmin_explained",
                ),
                0.0,
            ),
            "force_ref_N": math.nan,
            "eps_d_m": math.nan,
            "force_min_z_N": math.nan,
        }
    const_ref = float(np.median(r))
    ratio = r / -h
    ok = np.isfinite(ratio) & (ratio > 0.0)
    eps_d = float(np.median(ratio[ok]) ** (1.0 / BEST_BETA)) if ok.any() else math.nan
    eps_max = _column(real, "eps_max_m")[use]
    const_min = float(np.median(m))
    out.update(
        vs_cf_explained=_explained(r, np.full_like(r, const_ref)),
        vs_vf_explained=_explained(r, -h * eps_d**BEST_BETA)
        if np.isfinite(eps_d)
        else 0.0,
        vs_cf_fmin_explained=_explained(m, -h * eps_max**BEST_BETA),
        vs_vf_fmin_explained=_explained(m, np.full_like(m, const_min)),
        force_ref_N=-const_ref,
        # The law's power makes eps_d's last digits rounding noise.
        eps_d_m=round(eps_d, 9) if np.isfinite(eps_d) else math.nan,
        force_min_z_N=const_min,
    )
    return out


def _decide(scores: dict, a: str, b: str, margin: float, least: float) -> str | None:
    """a or b when its score wins by ``margin`` and reaches ``least``; else None."""
    sa, sb = (
        scores[f"{a.replace('-', '_')}_explained"],
        scores[f"{b.replace('-', '_')}_explained"],
    )
    if sa >= least and sa - sb >= margin:
        return a
    if sb >= least and sb - sa >= margin:
        return b
    return None


def classify_vs_log(real: pd.DataFrame) -> tuple[str, dict]:
    """VS-CF or VS-VF from a 31-column log's reference laws (:func:`vs_law_scores`).

    Decided on F_ref,z (the law must explain :data:`MIN_EXPLAINED_31` of the
    referenced contact samples and beat the other by :data:`MIN_MARGIN_31`);
    F_min,z must not point the other way by as large a margin.

    Raises:
        VicDrakeError: too few referenced contact samples, scores too close,
            or F_min,z contradicting F_ref,z.
    """
    s = vs_law_scores(real)
    ask = "pass --controller vs-cf or vs-vf (and --R R, --force N for VS-CF)"
    if s["referenced_samples"] < MIN_CONTACT_SAMPLES:
        raise VicDrakeError(
            f"cannot tell the controller of this 31-column log: only "
            f"{s['referenced_samples']} samples in contact with a nonzero F_ref,z "
            f"({s['contact_samples']} in contact; {MIN_CONTACT_SAMPLES} needed); {ask}"
        )
    kind = _decide(s, "vs-cf", "vs-vf", MIN_MARGIN_31, MIN_EXPLAINED_31)
    seen = (
        f"F_ref,z law explains {s['vs_cf_explained']:.1%} of {s['referenced_samples']} "
        f"contact samples as VS-CF (constant) and {s['vs_vf_explained']:.1%} as VS-VF "
        f"(map law); F_min,z law {s['vs_cf_fmin_explained']:.1%} / "
        f"{s['vs_vf_fmin_explained']:.1%}"
    )
    if kind is None:
        raise VicDrakeError(
            f"cannot tell the controller of this 31-column log: {seen} (a law must "
            f"explain {MIN_EXPLAINED_31:.0%} and beat the other by {MIN_MARGIN_31:.0%}); "
            f"{ask}"
        )
    other = "vs-vf" if kind == "vs-cf" else "vs-cf"
    fmin = {k: s[f"{k.replace('-', '_')}_fmin_explained"] for k in VS_CONTROLLERS}
    if fmin[other] - fmin[kind] >= MIN_MARGIN_31:
        raise VicDrakeError(
            f"contradictory evidence in this 31-column log: {seen}: F_ref,z says "
            f"{kind}, F_min,z says {other}; {ask}"
        )
    return kind, s


def scan_law_scores(real: pd.DataFrame) -> dict:
    """Fits the CS and CF force laws to a 9-column log (see the module doc).

    Pairs each row's pressing force with the pose :data:`SCAN_FORCE_LAG_TICKS`
    rows later and fits, over the contact samples (pressing force above the
    contact threshold), ``f = K e + c z_dot`` (CS) and ``f = f0 + c z_dot``
    (CF), e = z - z_target.

    Returns:
        dict: ``contact_samples``, ``cs_explained``, ``cf_explained`` (the
        fraction of the force variance each law explains, 1 - SSE / SST;
        negative when a law fits worse than the mean), the fits' K
        (``stiffness_N_per_m``) and f0 (``force_ref_N``), and the spread of e
        (``e_std_mm``).
    """
    lag = SCAN_FORCE_LAG_TICKS
    f = _column(real, "force_pressing_z_N")
    e = _column(real, "z_m") - _column(real, "z_target_m")
    v = _column(real, "vz_m_per_s")
    if len(f) <= lag:
        return {"contact_samples": 0}
    f, e, v = f[:-lag], e[lag:], v[lag:]
    use = (f > CONTACT_THRESHOLD_N) & np.isfinite(e) & np.isfinite(v)
    f, e, v = f[use], e[use], v[use]
    n = int(f.size)
    out = {"contact_samples": n, "e_std_mm": float(1e3 * np.std(e)) if n else 0.0}
    if n < 3:
        return out
    sst = float(np.sum((f - f.mean()) ** 2))
    for law, a in (
        ("cs", np.column_stack([e, v])),
        ("cf", np.column_stack([np.ones(n), v])),
    ):
        coef, *_ = np.linalg.lstsq(a, f, rcond=None)
        sse = float(np.sum((f - a @ coef) ** 2))
        out[f"{law}_explained"] = 1.0 - sse / sst if sst > 0.0 else 0.0
        out["stiffness_N_per_m" if law == "cs" else "force_ref_N"] = float(coef[0])
    return out


def classify_scan_log(real: pd.DataFrame) -> tuple[str, dict]:
    """CS or CF from a 9-column log's force laws (:func:`scan_law_scores`).

    Raises:
        VicDrakeError: too little contact, or neither law explaining
            :data:`MIN_EXPLAINED_9` of the force variance with a margin of
            :data:`MIN_MARGIN_9` over the other.
    """
    s = scan_law_scores(real)
    ask = "pass --controller cs (with --stiffness N_PER_M) or cf (with --force N)"
    if s["contact_samples"] < MIN_CONTACT_SAMPLES:
        raise VicDrakeError(
            f"cannot tell the controller of this 9-column log: only "
            f"{s['contact_samples']} contact samples ({MIN_CONTACT_SAMPLES} needed); {ask}"
        )
    kind = _decide(s, "cs", "cf", MIN_MARGIN_9, MIN_EXPLAINED_9)
    if kind is None:
        raise VicDrakeError(
            f"cannot tell the controller of this 9-column log: of the contact force's "
            f"variance f = K e explains {_share(s['cs_explained'])} (K = "
            f"{s['stiffness_N_per_m']:.4g} N/m) and f = f_ref {_share(s['cf_explained'])} "
            f"(f_ref = {s['force_ref_N']:.4g} N) over {s['contact_samples']} samples, "
            f"e spreading {s['e_std_mm']:.3g} mm (a law must explain "
            f"{MIN_EXPLAINED_9:.0%} and beat the other by {MIN_MARGIN_9:.0%}); {ask}"
        )
    return kind, s


def identify_controller(
    real: pd.DataFrame,
    *,
    controller: str | None = None,
    r_weight: float | None = None,
) -> ControllerIdentification:
    """The controller of a real scan log and its settings, from its signals.

    Args:
        real: ``realdata.read_bag`` of a scan log (layout "controller", 31
            columns, or "scan", 9 columns).
        controller: the controller when the caller knows it: no
            classification, only its settings are read.
        r_weight: R when the caller knows it (31-column logs): not identified
            (and not in the settings).

    Returns:
        ControllerIdentification. 31-column VS-CF: ``force_ref_N`` and
        ``r_weight``; VS-VF: ``eps_d_m``, ``force_min_z_N`` (when the VS-VF
        laws explain the log) and ``r_weight``; every 31-column log also the
        settings it logs each tick (:data:`LOGGED_SETTINGS`, their median).
        9-column CS: ``stiffness_N_per_m``; CF: ``force_ref_N``.

    Raises:
        VicDrakeError: another layout, a controller the layout cannot hold,
            or signals that cannot tell (see :func:`classify_vs_log`,
            :func:`classify_scan_log`, :func:`identify_r_weight`).
    """
    layout = real.attrs.get("layout")
    given = controller is not None
    if given and controller not in CONTROLLERS:
        raise VicDrakeError(
            f"--controller must be one of {', '.join(CONTROLLERS)}; got {controller!r}"
        )
    if layout == "controller":
        if given:
            kind, scores = controller, vs_law_scores(real)
        else:
            kind, scores = classify_vs_log(real)
        evidence = {
            k: scores[k] for k in scores if k.endswith(("_explained", "_samples"))
        }
        settings = {}
        if kind == "vs-cf" and scores["referenced_samples"] > 0:
            settings["force_ref_N"] = scores["force_ref_N"]
        if (
            kind == "vs-vf"
            and min(scores["vs_vf_explained"], scores["vs_vf_fmin_explained"])
            >= MIN_EXPLAINED_31
        ):
            settings["eps_d_m"] = scores["eps_d_m"]
            settings["force_min_z_N"] = scores["force_min_z_N"]
        if kind in VS_CONTROLLERS and r_weight is None:
            found = identify_r_weight(real)
            settings["r_weight"] = found.pop("r_weight")
            evidence.update(found)
        settings.update(
            {k: logged_setting(real, c) for k, c in LOGGED_SETTINGS.items()}
        )
    elif layout == "scan":
        if given:
            if controller not in SCAN_CONTROLLERS:
                raise VicDrakeError(
                    f"a 9-column log is a CS or CF scan; --controller must be cs or cf, "
                    f"got {controller!r}"
                )
            kind, scores = controller, scan_law_scores(real)
            if scores["contact_samples"] < 3:
                raise VicDrakeError(
                    f"the 9-column log has {scores['contact_samples']} contact samples; "
                    "cannot read its setting: pass --stiffness N_PER_M (cs) or --force N (cf)"
                )
        else:
            kind, scores = classify_scan_log(real)
        evidence = {
            k: scores[k]
            for k in ("contact_samples", "cs_explained", "cf_explained", "e_std_mm")
        }
        key = "stiffness_N_per_m" if kind == "cs" else "force_ref_N"
        settings = {key: scores[key]}
    else:
        raise VicDrakeError(
            f"controller identification needs a scan log (31-column 'controller' or "
            f"9-column 'scan' layout); got layout {layout!r}"
        )
    return ControllerIdentification(
        controller=kind, settings=settings, evidence=evidence, given=given
    )


__all__ = [
    "SCAN_FORCE_LAG_TICKS",
    "ControllerIdentification",
    "classify_scan_log",
    "classify_vs_log",
    "identify_controller",
    "scan_law_scores",
    "vs_law_scores",
]
