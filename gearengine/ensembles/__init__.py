"""Ensembles: one question about a design turned into many runs (starts, samples), each run a
lane of ``numerics.batch.run_lanes``, and the runs read back as one answer with its statistics
(``attractors``: coexisting attractors and their basin fractions)."""
