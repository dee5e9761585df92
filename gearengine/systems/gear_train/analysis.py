"""``gearengine.analyze`` for a design with a ``train``: the numerical verdict from the train's
kernel, the Melnikov verdict of its mesh-mode reduction (or not applicable with the reason),
and the engineering block on the scales of its equivalent pair (``model.equivalent_design``).

The Melnikov speed windows are those of the reduction (its frequencies scale with the speed like
the pair's); without a reduction there are none, and the note says why.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gearengine.engineering import engineering, summary
from gearengine.homoclinic.verdict import not_applicable
from gearengine.model.backlash import melnikov_cubic
from gearengine.model.errors import InputError
from gearengine.numerics.simulation import simulate
from gearengine.systems.gear_train.model import train_of
from gearengine.systems.gear_train.modes import modes
from gearengine.systems.gear_train.reduction import train_melnikov
from gearengine.systems.gear_train.response import train_system

if TYPE_CHECKING:
    from gearengine.analysis import AnalysisRequest, AnalysisResult


def analyze_train(request: AnalysisRequest) -> AnalysisResult:
    """The analysis of a train design (module docstring)."""
    from gearengine.analysis import AnalysisResult, verdict  # the caller's module: no cycle

    design = request.design
    assert design is not None and design.train is not None
    if request.settings.basins is not None:
        raise InputError(
            "settings.basins",
            "basins of a gear train are not built yet; remove settings.basins (the train's "
            "verdict is over the settings' starts)",
        )
    model, pair = train_of(design)
    system = train_system(model, pair)
    num = simulate(system.params, request.settings, system)
    reduced = train_melnikov(system)
    if reduced.applicable:
        assert reduced.melnikov is not None and reduced.params is not None
        mel = reduced.melnikov.model_copy(
            update={"notes": [reduced.reason, reduced.reduction, *reduced.melnikov.notes]}
        )
        conv = pair.model_copy(update={"params": reduced.params})
    else:
        a, c, _ = melnikov_cubic(system.params.backlash)
        mel = not_applicable(a, c, "closed_form", [reduced.reason])
        conv = pair
    eng = engineering(conv, request.speed_rpm_range(), mel, num)
    if not reduced.applicable:
        lo, hi = eng.speed_range_rpm
        eng = eng.model_copy(
            update={
                "speed_windows_rpm": [],
                "speed_windows_note": "no Melnikov reduction: " + reduced.reason,
                "summary": summary(conv, mel, [], (lo, hi), eng.response, num),
            }
        )
    notes = [f"gear train: {model.size} coordinates; numerics of the train, scales of its "
             "equivalent pair (I_a = I_m + I_p, I_b = I_g + I_l)"]  # fmt: skip
    found = modes(model, pair.natural_frequency_hz)
    eng = eng.model_copy(update={"notes": [*eng.notes, *notes], "modes": found})
    return AnalysisResult(
        melnikov=mel,
        numerics=num,
        settings=request.settings,
        verdict=verdict(mel, num),
        params=system.params,
        engineering=eng,
    )
