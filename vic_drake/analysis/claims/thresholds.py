"""The claims' thresholds and statements, each number with why it is what it is.

The contact rule, the scan window and the contact-loss rule the claims use
are those of :mod:`vic_drake.analysis.contact`; the rib detector is
:mod:`vic_drake.analysis.ribs`.
"""

#: C2: Spearman rank correlation of residual vs palpation time must be at most
#: this: "falls" means a clear monotone trend, not noise around a constant.
C2_MAX_SPEARMAN = -0.8
#: C2: the exponential model r(T) = c + a exp(-T/tau) must explain at least
#: this fraction of the variance ("about exponentially", Fig. 3).
C2_MIN_R2 = 0.9
#: C2: the residual at the longest palpation must be at most this fraction of
#: the shortest one's: a fall, not a flat curve with a monotone wiggle (the
#: paper's Fig. 3 falls several-fold).
C2_MAX_RATIO = 0.8
#: C3: the paper's counts: three evident ribs and at least one weaker one.
C3_MIN_STRONG_RIBS = 3
#: C3: neighbouring ribs are at least this far apart (m); closer peaks are
#: texture or an over-fitted map, not ribs (the chest's ribs are ~4 cm apart,
#: intercostal spaces >= 2 cm).
C3_MIN_RIB_SPACING_M = 0.02
#: C4: VS-CF's force RMSE may exceed CF's by at most 20 % (the issue's
#: "about as well as CF").
C4_MAX_RMSE_RATIO = 1.2
#: C5: the CS force range over the scan must be at least twice VS-CF's.
C5_MIN_RANGE_RATIO = 2.0
#: C6: median |penetration - eps_d| off the ribs at most 3 mm: the real
#: controller's penetration is measured against the map surface, whose offset
#: (2.5 mm) and GRIDFIT error are of that order.
C6_MAX_PEN_ERROR_M = 0.003
#: C6: over the ribs the 99th percentile of the pressing force may exceed
#: |F_min| by at most 10 % (FDCC tracks the QP's force bound with a lag).
C6_FORCE_CAP_TOL = 0.10
#: C7: during contact loss the stiffness must be within this of K_min (N/m);
#: 5 % of the paper's 100 N/m.
C7_K_MIN_TOL_N_PER_M = 5.0
#: C7: fraction of the contact-loss time (after the first C7_LOSS_SETTLE_S of
#: each interval) that K must spend at K_min.
C7_MIN_FRACTION_AT_K_MIN = 0.9
#: C7: seconds K may take to fall to K_min after contact is lost (the QP
#: lowers it within a tick; FDCC and sensor lags add a little).
C7_LOSS_SETTLE_S = 0.2
#: C7: the tank's power may exceed the valve's limit by this fraction: the
#: real controller takes dt from timestamps, which jitter by a few percent.
C7_POWER_TOL = 0.10
#: C7: the tank energy may dip below T_min by this much (J), numerical slack.
C7_TANK_TOL_J = 1e-6


STATEMENTS = {
    "C1": "Hunt-Crossley fits the palpation forces better than Kelvin-Voigt; "
    "beta = 1.35 is the best of the three exponents (Table I).",
    "C2": "The fit residual falls about exponentially with palpation time (Fig. 3).",
    "C3": "The ribs stand out in the kappa map; the rib under the pectoral "
    "muscle less than the others (Fig. 4).",
    "C4": "VS-CF tracks its force reference about as well as CF (force RMSE "
    "within 20 % of CF's) while keeping position control: it lifts off at the "
    "end; CF cannot (Fig. 6).",
    "C5": "The CS force follows the body's shape: its force range over the scan "
    "is at least twice VS-CF's.",
    "C6": "VS-VF holds the penetration near eps_d off the ribs and caps the force "
    "at F_min over them (Fig. 6).",
    "C7": "Under the disturbance K falls to K_min while contact is lost, its rise "
    "at re-contact is limited by the power valve, T >= T_min throughout, and the "
    "peak force of VS-VF is lower than CS's and CF's (Fig. 7).",
}
