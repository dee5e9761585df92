"""Signals: reading a time series, simulated or measured, with array functions only.

``periodicity`` (the period of a stroboscopic series), ``lyapunov`` (Benettin's estimate and its
error from recorded log-stretchings), ``classify`` (periodic, quasi-periodic, chaotic,
diverged), ``diagnostics`` (DTE, spectrum, contact regime of a deflection record) and
``nolds_check`` (an independent Rosenstein exponent). They take arrays and know nothing of the
system that made them, so a rig's recording and a simulation are read by the same code; the
numerics room hands its runs to them (this room sits below numerics and imports only the model).
"""
