"""Robustness: the gears that will actually be built. ``tolerances`` draws quasi-Monte Carlo
samples of a design's tolerances and turns their verdicts into probabilities with intervals;
``sensitivity`` says which tolerance matters (Sobol indices, SALib); ``study`` makes the two a
durable job kind of ``studies.jobs``; ``sequential`` decides probability limits point by point,
sampling each point only until it is decided, within a compute budget (``check --samples auto``).
"""
