"""gearchaos engine: periodic or chaotic? Melnikov and numerical verdicts for spur-gear pairs.

The public facade, short verbs on a design (as ChaosTools.jl):

    >>> from gearengine import GearParams, Design, melnikov, analyze, run_sweep
    >>> p = GearParams.model_validate(PAPER_SECTION_41)
    >>> melnikov(p).chaos_possible
    True
    >>> analyze(Design.model_validate(doc["design"])).summary()   # one line; repr is short too
    >>> run_sweep(SweepRequest.model_validate(sweep)).to_pandas()  # pip install 'gearchaos[pandas]'

Rooms (subpackages) follow the data flow, a diamond rather than a chain: ``model`` feeds both
``homoclinic`` (the Melnikov analysis of the homoclinic orbits) and ``numerics``, which know
nothing of each other; ``numerics.attractors`` runs many starts of one design, ``analysis``
and ``engineering`` join them, then ``studies.sweep`` -> ``plots`` -> ``cli``;
``docs/architecture.md`` draws it. The engine imports no web code.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gearengine.lazyload import lazy_names

if TYPE_CHECKING:  # what the names below load lazily, for type checkers and IDEs
    from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
    from gearengine.gate.remedies import RemediesRequest, RemediesResult, remedies
    from gearengine.homoclinic import MelnikovResult, chaos_possible, melnikov, threshold_curve
    from gearengine.model.design import Design
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
    from gearengine.numerics.attractors import of_design as attractors
    from gearengine.rig import signal
    from gearengine.signals.schema import SignalResult
    from gearengine.signals.series import SignalRequest
    from gearengine.studies.runup import RunupRequest, RunupResult
    from gearengine.studies.runup import run_local as run_runup
    from gearengine.studies.sweep import SweepRequest, SweepResult
    from gearengine.studies.sweep import run_local as run_sweep

__all__ = [
    "PAPER_SECTION_41",
    "AnalysisRequest",
    "AnalysisResult",
    "Design",
    "GearParams",
    "MelnikovResult",
    "RemediesRequest",
    "RemediesResult",
    "RunupRequest",
    "RunupResult",
    "SignalRequest",
    "SignalResult",
    "SimulationSettings",
    "SweepRequest",
    "SweepResult",
    "analyze",
    "attractors",
    "chaos_possible",
    "lyapunov",
    "melnikov",
    "poincare",
    "remedies",
    "run_runup",
    "run_sweep",
    "signal",
    "simulate",
    "simulate_batch",
    "threshold_curve",
    "warm_up",
]

_HOMES: dict[str, tuple[str, str]] = {
    "PAPER_SECTION_41": ("gearengine.model.examples", "PAPER_SECTION_41"),
    "AnalysisRequest": ("gearengine.analysis", "AnalysisRequest"),
    "AnalysisResult": ("gearengine.analysis", "AnalysisResult"),
    "Design": ("gearengine.model.design", "Design"),
    "GearParams": ("gearengine.model.params", "GearParams"),
    "MelnikovResult": ("gearengine.homoclinic", "MelnikovResult"),
    "RemediesRequest": ("gearengine.gate.remedies", "RemediesRequest"),
    "RemediesResult": ("gearengine.gate.remedies", "RemediesResult"),
    "RunupRequest": ("gearengine.studies.runup", "RunupRequest"),
    "RunupResult": ("gearengine.studies.runup", "RunupResult"),
    "SignalRequest": ("gearengine.signals.series", "SignalRequest"),
    "SignalResult": ("gearengine.signals.schema", "SignalResult"),
    "SimulationSettings": ("gearengine.numerics", "SimulationSettings"),
    "SweepRequest": ("gearengine.studies.sweep", "SweepRequest"),
    "SweepResult": ("gearengine.studies.sweep", "SweepResult"),
    "analyze": ("gearengine.analysis", "analyze"),
    "attractors": ("gearengine.numerics.attractors", "of_design"),
    "chaos_possible": ("gearengine.homoclinic", "chaos_possible"),
    "lyapunov": ("gearengine.numerics", "lyapunov"),
    "melnikov": ("gearengine.homoclinic", "melnikov"),
    "poincare": ("gearengine.numerics", "poincare"),
    "remedies": ("gearengine.gate.remedies", "remedies"),
    "run_runup": ("gearengine.studies.runup", "run_local"),
    "run_sweep": ("gearengine.studies.sweep", "run_local"),
    "signal": ("gearengine.rig", "signal"),
    "simulate": ("gearengine.numerics", "simulate"),
    "simulate_batch": ("gearengine.numerics", "simulate_batch"),
    "threshold_curve": ("gearengine.homoclinic", "threshold_curve"),
    "warm_up": ("gearengine.numerics", "warm_up"),
}
"""(module, attribute) of each public name, imported on first use: ``import gearengine`` (every
command and the service go through it) then costs nothing, where the eager facade loaded
numba, scipy, pint and nolds in ~0.7 s."""

_SUBMODULES = frozenset(
    {
        "analysis",
        "cli",
        "engineering",
        "homoclinic",
        "jitcache",
        "jsonio",
        "lazyload",
        "model",
        "numerics",
        "plots",
        "rig",
        "gate",
        "signals",
        "studies",
        "systems",
    }
)
"""The package's own modules: ``gearengine.numerics`` after a bare ``import gearengine`` still
works (the eager facade used to import them). No public name may be one of these, or caching it
would hide the submodule (``gearengine.melnikov`` is the verb, there is no such module)."""


__getattr__, __dir__ = lazy_names(__name__, _HOMES, _SUBMODULES)
