"""The gear train: motor, input shaft, pinion, gear, output shaft, load and bearings around the
mesh of Eq. (2) (``docs/gear-trains.md``), the second ``System``.

* ``model``: the train's matrices in physical and dimensionless coordinates (``TrainModel``).
* ``modes``: natural frequencies, damping ratios, mode shapes and mesh strain-energy shares.
* ``campbell``: natural frequencies against driver speed with the order lines and crossings.
* ``kernel``: the n-dimensional RK4 with its tangent equation (numba).
* ``system``: ``TrainSystem``, the train as a ``System`` (step plan, one run).

Above this room: ``numerics.trains`` (the train's verdict in its own words, its budget),
``homoclinic.train_reduction`` (the Melnikov verdict of the mesh-mode reduction) and
``analysis.analyze`` (``analysis.train_answer``).
"""
