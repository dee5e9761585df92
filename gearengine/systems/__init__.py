"""Systems: the forced oscillators the numerics drive, each a ``System`` of state dimension n
(``base``: the interface and its contract, the step plan and the run); ``spur_pair`` is the
paper's single-degree-of-freedom pair (Eq. 9) with its backlash laws' kernels.
"""

from gearengine.systems.base import Run, StepPlan, StroboscopicFlow, System

__all__ = ["Run", "StepPlan", "StroboscopicFlow", "System"]
