"""gearchaos engine: periodic or chaotic? Melnikov and numerical verdicts for spur-gear pairs.

The public facade, short verbs on a design (as ChaosTools.jl):

    >>> from gearengine import GearParams, melnikov, analyze, AnalysisRequest
    >>> p = GearParams.model_validate(PAPER_SECTION_41)
    >>> melnikov(p).chaos_possible
    True

Rooms (subpackages) follow the data flow: ``model`` -> ``homoclinic`` (the Melnikov analysis
of the homoclinic orbits) -> ``numerics`` ->
``analysis`` -> ``sweeps`` -> ``plots`` -> ``cli``; ``docs/architecture.md`` draws it. The
engine imports no web code.
"""

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.homoclinic import MelnikovResult, chaos_possible, melnikov, threshold_curve
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import GearParams
from gearengine.numerics import (
    SimulationSettings,
    lyapunov,
    poincare,
    simulate,
    simulate_batch,
    warm_up,
)
from gearengine.sweeps import SweepRequest, SweepResult
from gearengine.sweeps import run_local as run_sweep

__all__ = [
    "PAPER_SECTION_41",
    "AnalysisRequest",
    "AnalysisResult",
    "GearParams",
    "MelnikovResult",
    "SimulationSettings",
    "SweepRequest",
    "SweepResult",
    "analyze",
    "chaos_possible",
    "lyapunov",
    "melnikov",
    "poincare",
    "run_sweep",
    "simulate",
    "simulate_batch",
    "threshold_curve",
    "warm_up",
]
