"""The run-up room: the gear while its driver speed changes (non-stationary integration and its
reading).

Data flow: ``request`` (profile, validation) -> ``profile`` (segments linear in time, forcing on
the integrated driver angle, step plan) -> ``compute`` (a job: one chunk per ensemble member
through ``systems.spur_pair.kernels.ramp``, two quasi-static continuation lines through the sweeps
room)
-> ``reading`` (bins against speed, jumps, finite-time Lyapunov exponent, lag behind the
quasi-static loop) -> ``results`` (the document).
"""

from gearengine.studies.runup.compute import RUNUP_JOB, run_local
from gearengine.studies.runup.request import RunupRequest
from gearengine.studies.runup.results import RunupResult

__all__ = ["RUNUP_JOB", "RunupRequest", "RunupResult", "run_local"]
