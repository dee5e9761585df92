"""Answers in gear-design units: the engineering block of every response to a ``design``.

From the design's conversion (``model.design``) and the dimensionless verdicts this room
gives what a gearbox engineer asks, in three modules:

* ``thresholds``: the critical value of each control parameter in its unit, and
  ``margin_to_chaos``: the threshold's margin in that unit, positive on the safe side, negative
  inside the chaos-possible region (Eqs. 23, 24 generalised); a threshold figure's axes in gear
  units;
* ``response``: for analyses, DTE b (x_max - x_min), the dynamic mesh force b k_m [K(t) f_h(x)
  + 2 mu~ x'] and the dynamic factor (max force / static force F^_m), the fractions of time
  apart (|x| <= 1) and on the back flank (x < -1), the period and dominant response frequency;
* ``block``: the ``Engineering`` block that joins them with ``speed_windows_rpm`` (the driver
  speeds where the Melnikov criterion allows chaos at the design's torque,
  ``homoclinic.boundary.speed_window_scan``: a change of speed scales every excitation
  frequency together, scanned past the requested range to ``WINDOW_BOUND`` times the design
  speed, then open-ended), ``critical_torque_nm`` (the mean driver torque T_crit at which the
  static mesh force reaches F_crit of the cubic fit; above it the unperturbed system has no
  saddle and the criterion does not apply, ``docs/melnikov-under-load.md``) and ``summary``:
  plain sentences for a design review.

Every dimensionless number crosses to gear units through ``model.units.to_physical`` (the
``OUTPUTS`` table) with the design's ``Scales``.
"""
