"""The system a design runs as: the studies' one door from a design to the numerics.

A design without a ``train`` is the paper's spur pair, given as its parameter point of Eq. (9)
(``GearParams``, which the lock-step kernels of ``numerics.batch`` run many at a time); a design
with a ``train`` is its ``TrainSystem`` (``systems.gear_train``), on the scales of its equivalent
pair. The studies (sweeps, the envelope gate) read every answer through the ``System``
interface and the returned conversion's scales, with no branch of their own per system.
"""

from __future__ import annotations

from gearengine.model.design import Design
from gearengine.model.params import GearParams
from gearengine.model.reduction import DesignConversion, convert_design
from gearengine.systems.base import System
from gearengine.systems.gear_train.model import train_of
from gearengine.systems.gear_train.system import train_system


def design_model(design: Design) -> tuple[GearParams | System, DesignConversion]:
    """(what the numerics run, the conversion whose scales read its answers) for ``design``:
    (the pair's ``GearParams``, its conversion), or with a train (its ``TrainSystem``, the
    conversion of its equivalent pair, I_a = I_m + I_p, I_b = I_g + I_l)."""
    if design.train is not None:
        model, pair = train_of(design)
        return train_system(model, pair), pair
    conversion = convert_design(design)
    return conversion.params, conversion


def params_of(model: GearParams | System) -> GearParams:
    """The parameter point of Eq. (9) of ``model``: itself, or the one its system shares."""
    return model if isinstance(model, GearParams) else model.params
