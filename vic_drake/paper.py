"""The paper's fixed numbers and the rig's constants, each defined once.

Everything here is a fact of the paper (its Table I, its controllers) or of
the real rig (gravity, the controller's contact rule). Tunable settings live
in the scenario dataclasses (``vic_drake.control.params``,
``vic_drake.station``), whose defaults are the real controller's settings;
this module holds only what no scenario changes. It imports nothing of
vic_drake, so every layer may use it.
"""

#: The four controllers of the paper, in the order of its figures (Sec. II-B,
#: Sec. III-C): constant stiffness, constant force, variable stiffness with a
#: constant force reference, variable stiffness with a variable one.
CONTROLLERS = ("cs", "cf", "vs-cf", "vs-vf")

#: The controllers the paper runs under the disturbance (Fig. 7).
DISTURBANCE_CONTROLLERS = ("vs-vf", "cs", "cf")

#: The Hunt-Crossley exponents of Table I, in its column order.
TABLE_I_BETAS = (1.5, 1.35, 1.1)

#: The exponent the paper found best (Table I) and used for its maps.
BEST_BETA = 1.35

#: Table I: relative fit residual of Kelvin-Voigt and of Hunt-Crossley per beta.
PAPER_TABLE_I_KELVIN_VOIGT = 0.066
PAPER_TABLE_I_HUNT_CROSSLEY = {1.5: 0.029, 1.35: 0.014, 1.1: 0.045}

#: Contact: pressing force above this, N. The real controller declared contact
#: when the sensor's z force was below -0.5 N (data README), about five times
#: the sensor's noise floor in the free-motion parts of the logs.
CONTACT_THRESHOLD_N = 0.5

#: Standard gravity, m/s^2, along -z of the world (robot base) frame.
GRAVITY_M_PER_S2 = 9.81


def paper_table_i() -> dict:
    """Table I as a flat dict: ``kelvin_voigt`` and ``hc_<beta>`` keys."""
    return {
        "kelvin_voigt": PAPER_TABLE_I_KELVIN_VOIGT,
        **{f"hc_{b:g}": v for b, v in PAPER_TABLE_I_HUNT_CROSSLEY.items()},
    }
