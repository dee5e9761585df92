"""Remedies: the smallest change of a design lever (damping, transmission error, backlash,
stiffness variation, torque ripple) that makes a failing operating envelope pass, with a
Melnikov bound and a numerical bound verified by envelope checks of ``gate.envelope``.

Data flow: ``request`` (envelope, rules, levers, checks across fields) -> ``levers`` (contact
ratio and ISO 1328 class of a lever's value) -> ``search`` (one lever's Melnikov and numerical
bounds) -> ``compute`` (the job: a chunk per lever, the combination, the ranked answer) ->
``results`` (the documents).
"""

from gearengine.gate.remedies.compute import REMEDIES_JOB, remedies
from gearengine.gate.remedies.request import RemediesRequest
from gearengine.gate.remedies.results import RemediesResult

__all__ = ["REMEDIES_JOB", "RemediesRequest", "RemediesResult", "remedies"]
