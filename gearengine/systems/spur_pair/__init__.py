"""The paper's spur pair (Eq. 9): ``system`` (the ``SpurPair`` system and its integrators per
backlash law), ``forcing`` (the forcing terms packed for the kernels, the step plan) and
``kernels`` (numba RK4 with the tangent equation: smooth, kink-splitting, lock-step lanes,
monodromy, ramp)."""
