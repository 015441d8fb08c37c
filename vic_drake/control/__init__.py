"""Online control math: energy tank, stiffness QP, force references, replay.

Pure functions and dataclasses; the Drake LeafSystems that wrap them live in
``vic_drake.systems`` (``references``, ``stiffness_qp``, ``tank``,
``controller``).

- :mod:`vic_drake.control.params`: ``ControllerParams`` (``period_s``,
  ``tank: TankParams``, ``qp: StiffnessQpParams``,
  ``reference: ReferenceParams``), defaults of the real controller.
- :mod:`vic_drake.control.tank`: ``tank_step`` (T, dT/dt, sigma, enabled),
  ``tank_qp_rows``.
- :mod:`vic_drake.control.stiffness_qp` (a package, one concept per
  module): ``problem`` (``make_stiffness_qp_problem``), ``constraints``
  (active-constraint mask), ``exact`` (``solve_stiffness_qp_exact``, the
  closed-form oracle and fast path), ``program`` (``StiffnessQp``, the
  MathematicalProgram built once; OSQP or Clarabel).
- :mod:`vic_drake.control.references`: contact, penetration rate,
  surface-velocity filter, ``force_references`` of CS, CF, VS-CF, VS-VF,
  ``scalar_sampler`` (fast map lookup).
- :mod:`vic_drake.control.replay`: ``replay_controller_log`` /
  ``replay_bag`` (the real controller's 31-column logs through the same QP
  and tank; ``vic-drake replay-qp``).
"""
