"""Ensembles: one question answered by many runs of the engine (point x start x sample), each a
lane of ``numerics.batch.run_lanes``. ``tolerances`` draws the gears that will actually be built
(quasi-Monte Carlo samples of a design's tolerances) and turns their verdicts into probabilities
with intervals; ``sensitivity`` says which tolerance matters (Sobol indices, SALib);
``robustness`` makes the two a durable job kind of ``gearengine.jobs``.
"""
