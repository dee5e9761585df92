"""The numerics room: integrate Eq. (9) and read the response.

Data flow: ``settings`` (periods, steps, starts; what a run costs on a step plan) ->
``forcing`` (the excitations as kernel arrays, the RK4 step plan) -> ``kernels`` (numba RK4
with the tangent equation; kink splitting for the piecewise law; a SIMD batch) -> ``runs`` (one
start: ``periodicity``, ``lyapunov``, ``classify``; ``work``, the cost of a run on its system's
plan) -> ``simulation`` (one design: ``diagnostics``,
``nolds_check``, ``floquet``: multipliers and stability margin of a periodic response) and
``batch`` (many designs; ``run_lanes``, the one door of ensembles: every run of a request,
point x start x sample, is a lane), with the documents in ``results``; ``bifurcations`` locates the
bifurcation points along a line of parameter values. Imports only the model room.
"""

from gearengine.numerics.batch import Lane, run_lanes, simulate_batch
from gearengine.numerics.results import BatchPoint, NumericsResult
from gearengine.numerics.runs import work
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.simulation import lyapunov, poincare, simulate, warm_up

__all__ = [
    "BatchPoint",
    "Lane",
    "NumericsResult",
    "SimulationSettings",
    "lyapunov",
    "poincare",
    "run_lanes",
    "simulate",
    "simulate_batch",
    "warm_up",
    "work",
]
