"""Ensembles: one question answered by many runs of the engine (point x start x sample), each a
lane of ``numerics.batch.run_lanes``. ``tolerances`` draws the gears that will actually be built
(quasi-Monte Carlo samples of a design's tolerances) and turns their verdicts into probabilities
with intervals; ``sensitivity`` says which tolerance matters (Sobol indices, SALib);
``robustness`` makes the two a durable job kind of ``gearengine.jobs``. ``remedies`` searches
the design levers (damping, transmission error, backlash, stiffness variation, torque ripple)
for the smallest change that makes a failing operating envelope pass, with a Melnikov bound and
a numerical bound verified by an envelope run per lever (its chunks are envelope checks).
``attractors`` groups many starts of one design by the orbit they settle on: coexisting
attractors and their basin fractions.
"""
