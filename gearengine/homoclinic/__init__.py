"""The homoclinic room, the Melnikov analysis: can the stable and unstable manifolds of the
saddle intersect transversally?

Data flow: ``loops`` (the saddle and the two homoclinic loops of x'' = a x - c x^3 + F_m, the
mean load in the unperturbed system; none for |F_m| >= F_crit) -> ``coefficients`` (the
sinusoids of M(tau0), Eq. 19, closed form or quadrature) -> ``extrema`` (min and max of M over
tau0) -> ``thresholds`` (critical values of each control parameter; ``margins``: their sets and the
design's margin) ->
``verdict`` (``melnikov``: the whole answer, with ``perturbations``: how far first-order theory
is stretched), with the request and result documents in ``schemas``; ``batch``
(``melnikov_batch``) gives verdicts and margins of many designs at once, ``grid`` the chaos
map's boundary grid; ``terms`` packs a design for ``kernels``, the compiled inner loops (the one
door into them). Imports only the model room.
"""

from pathlib import Path

from gearengine.homoclinic.batch import MelnikovBatchRequest, MelnikovBatchResult, melnikov_batch
from gearengine.homoclinic.schemas import MelnikovRequest, MelnikovResult, ThresholdCurve
from gearengine.homoclinic.thresholds import chaos_possible, threshold_curve
from gearengine.homoclinic.verdict import melnikov
from gearengine.jitcache import drop_stale

__all__ = [
    "MelnikovBatchRequest",
    "MelnikovBatchResult",
    "MelnikovRequest",
    "MelnikovResult",
    "ThresholdCurve",
    "chaos_possible",
    "melnikov",
    "melnikov_batch",
    "threshold_curve",
]

_HERE = Path(__file__).parent
# batch's compiled verdict calls kernels.py's, which call loops.py's, and freezes
# extrema.NEGLIGIBLE and kernels' row numbers (gearengine.jitcache says why this matters); numba
# loads a cached kernel on its first call, so this runs first
drop_stale(
    "kernels,batch,loops",
    [_HERE / "kernels.py", _HERE / "batch.py", _HERE / "extrema.py", _HERE / "loops.py"],
    _HERE / "__pycache__",
)
