"""The signals room: a recorded series read as periodic, quasi-periodic, chaotic or noise.

Data flow: ``series`` (the request: values, sample rate, speed or tach, teeth; refused when
unusable) -> ``orders`` (angle-domain resampling, order spectrum, strobes, the period by
synchronous averaging) -> ``embedding`` (delay by mutual information, dimension by false
nearest neighbours) -> ``zero_one`` (Gottwald-Melbourne 0-1 test), ``surrogates`` (IAAFT
surrogate test), ``rosenstein`` (largest Lyapunov exponent) -> ``reading`` (the verdict and
its evidence, the ``schema`` documents) and ``rig`` (the model's verdict beside the signal's).
Imports the model room, and the numerics room for the model's side; docs/signals.md.
"""

from gearengine.signals.reading import read
from gearengine.signals.schema import SignalResult
from gearengine.signals.series import SignalRequest

__all__ = ["SignalRequest", "SignalResult", "read"]
