"""Signals: reading a time series, simulated or measured, with array functions only.

The numerics hand their runs to ``periodicity`` (the period of a stroboscopic series),
``lyapunov`` (Benettin's estimate and its error from recorded log-stretchings), ``classify``
(periodic, quasi-periodic, chaotic, diverged), ``diagnostics`` (DTE, spectrum, contact regime)
and ``nolds_check`` (an independent Rosenstein exponent).

A recorded series goes through ``series`` (the request: values, sample rate, speed or tach,
teeth; refused when unusable) -> ``orders`` (angle-domain resampling, order spectrum, strobes,
the period by synchronous averaging) -> ``embedding`` (delay by mutual information, dimension
by false nearest neighbours) -> ``zero_one`` (Gottwald-Melbourne 0-1 test), ``surrogates``
(IAAFT surrogate test), ``rosenstein`` (largest Lyapunov exponent) -> ``reading`` (the verdict
and its evidence, the ``schema`` documents); ``gearengine.rig`` puts the model's verdict beside
it. The room imports only the model, so a rig's recording and a simulation are read by the same
code (docs/signals.md).
"""
