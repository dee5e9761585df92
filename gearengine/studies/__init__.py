"""Studies: every long answer of the engine as a durable job kind of ``studies.jobs``.

``sweep`` (grids of designs and bifurcation branches), ``runup`` (run-ups and run-downs) and
``robustness`` (probabilities over tolerances); ``jobs`` is the one registry of kinds, which
also names the remedies job of ``gate.remedies`` (a search over the gate's rules).
"""
