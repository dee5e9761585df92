"""``gearengine.analyze`` of a design with a ``train`` (issue 32): the train's numerical verdict,
the Melnikov answer of its reduction, its modes in the engineering block."""

from __future__ import annotations

import json
from pathlib import Path

import gearengine
from gearengine.cli.melnikov import render_engineering
from gearengine.model.design import Design
from gearengine.model.train import EXAMPLE_TRAIN
from gearengine.numerics.settings import SimulationSettings
from gearengine.numerics.trains import simulate_train

ROOT = Path(__file__).resolve().parents[1]
PAIR = json.loads((ROOT / "examples" / "design-direct.json").read_text())["design"]
SETTINGS = SimulationSettings(transient_periods=200, record_periods=60)


def test_analysis_of_a_train_is_the_trains() -> None:
    design = Design.model_validate({**PAIR, "train": EXAMPLE_TRAIN})
    result = gearengine.analyze(design, SETTINGS)
    train = simulate_train(design, SETTINGS)
    num, eng = result.numerics, result.engineering
    assert num.classification == train.classification == "periodic"
    assert num.period == train.period and num.lle == train.lle
    assert eng.response.dte_peak_to_peak_um == train.dte_um
    assert eng.response.dynamic_factor == train.dynamic_factor
    # Floquet of the train's periodic response: 2n = 10 multipliers (tests/test_train_floquet.py)
    assert num.floquet is not None and num.floquet.converged and num.floquet_note is None
    assert len(num.floquet.multipliers) == 10 and num.floquet.stability_margin > 0
    assert not result.melnikov.applicable and "56.5%" in result.melnikov.notes[0]
    assert result.verdict.agreement == "undecided"
    assert [round(m.frequency_hz, 1) for m in eng.modes.modes][-1] == 2799.9
    assert eng.speed_windows_rpm == [] and "no Melnikov reduction" in eng.speed_windows_note
    # the pair alone: no train's answer in its JSON
    pair = gearengine.analyze(Design.model_validate(PAIR), SETTINGS)
    text = pair.model_dump_json()
    assert '"modes"' not in text and '"train"' not in text
    assert pair.numerics.lle != num.lle


def test_a_train_without_a_reduction_gets_no_single_dof_words() -> None:
    """The example train (56.5 % of the mesh mode's strain energy in the mesh, no one-mode
    reduction) was told the equivalent pair's critical torque ("T_crit = 9.623 N*m (the
    criterion applies below it)") and that the criterion does not apply because its torque is
    above it, and its gear-units header named the stiff limit's f_n as its natural frequency.
    Now: no critical torque, the summary says why the criterion does not apply, and the header
    names the train's mesh mode."""
    design = Design.model_validate({**PAIR, "train": EXAMPLE_TRAIN})
    eng = gearengine.analyze(design, SETTINGS).engineering
    assert eng.critical_torque_nm is None
    assert "the Melnikov criterion does not apply: the mesh mode holds 56.5%" in eng.summary
    assert "critical torque" not in eng.summary and "rules chaos out" not in eng.summary
    text = render_engineering(eng)
    assert "T_crit" not in text and "nearest critical" not in text
    assert "the train's mesh mode 2799.88 Hz, 57% of its strain energy in the mesh" in text
