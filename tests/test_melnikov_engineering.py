"""The Melnikov answer in gear units: the critical torque and the edge of applicability for
designs (issue 25), one sign convention for margins (issue 26 item 3), speed windows scanned
until they close (issue 26 item 4)."""

from __future__ import annotations

import copy
import json

import pytest

from gearengine.analysis import answer_melnikov
from gearengine.homoclinic.batch import melnikov_batch
from gearengine.homoclinic.schemas import MelnikovRequest
from gearengine.homoclinic.verdict import melnikov
from gearengine.model.design import EXAMPLE_DESIGN
from gearengine.model.params import GearParams
from tests.conftest import PAPER_PARAMS
from tests.test_design import LIGHT, design


def answer(d: dict, **extra: object):
    return answer_melnikov(MelnikovRequest.model_validate({"design": d, **extra}))


def test_the_readme_design_at_40_nm_is_outside_the_criterion() -> None:
    """40 N m deflects the mesh 13.3 µm: F~_m = 0.267 > F_crit = 0.0642; no windows, and the
    summary says why in gear words and names the critical torque."""
    got = answer(EXAMPLE_DESIGN)
    assert got.applicable is False and got.chaos_possible is None
    eng = got.engineering
    assert eng.critical_torque_nm == pytest.approx(40.0 * got.critical_mean_force / (0.8 / 3))
    assert eng.speed_windows_rpm == []
    assert eng.speed_windows_note.startswith("not applicable above T_crit")
    assert "13.3 µm statically" in eng.summary and "numerical verdict still applies" in eng.summary


def test_not_applicable_says_why_t_crit_depends_on_the_load_backlash_and_stiffness() -> None:
    """Where the answer says "not applicable above T_crit", one sentence says why T_crit is a
    function of the design (issue 30): the saddle disappears when the mean force exceeds the
    wells' barrier, which scales with the half backlash, the mesh stiffness and the radius."""
    note = answer(EXAMPLE_DESIGN).engineering.speed_windows_note
    assert note.startswith("not applicable above T_crit = 9.62 N*m: ")
    for words in ("T_crit = F_crit b k_m r_a", "the saddle disappears", "mean mesh force",
                  "half backlash b", "mesh stiffness k_m", "base radius r_a"):  # fmt: skip
        assert words in note


def test_not_applicable_says_the_teeth_are_in_contact_at_rest_only() -> None:
    """The reason read "the teeth stay in contact" above the paragraph saying "impacts on both
    flanks" (basins at 5,750 rpm / 2 N*m; stop-39 leftover): the static load keeps them in
    contact at rest, and the numerical verdict says whether they separate in motion."""
    summary = answer(EXAMPLE_DESIGN).engineering.summary
    assert "stay in contact" not in summary
    assert "at rest the teeth are in contact (in motion they may separate" in summary


@pytest.mark.parametrize("factor", [1 - 1e-6, 1 + 1e-6])
def test_applicability_switches_at_the_critical_torque(factor: float) -> None:
    t_crit = answer(LIGHT).engineering.critical_torque_nm
    assert t_crit == pytest.approx(9.623, abs=1e-3)
    got = answer(design(torque=f"{factor * t_crit!r} N*m"))
    assert got.applicable is (factor < 1)
    assert (got.engineering.speed_windows_note or "").startswith("not applicable") is (factor > 1)


def test_margins_are_positive_on_the_safe_side() -> None:
    """Issue 26 item 3: F_e1 below its threshold and mu above its threshold are both safe and
    both positive, in the thresholds, the batch and the engineering block."""
    safe = GearParams.model_validate({**PAPER_PARAMS, "transmission_error": {
        "frequency": 0.5, "harmonics": [{"amplitude": 0.1}]}})  # fmt: skip
    result = melnikov(safe)
    assert result.chaos_possible is False
    assert result.thresholds["F_e1"].margin > 0 and result.thresholds["mu"].margin > 0
    batch = melnikov_batch([safe])[0]["margins"]
    assert batch["F_e1"]["margin"] > 0 and batch["mu"]["margin"] > 0
    unsafe = GearParams.model_validate(PAPER_PARAMS)  # F_e1 = 0.2 beyond both loops' thresholds
    assert melnikov(unsafe).chaos_possible is True
    assert melnikov(unsafe).thresholds["F_e1"].margin < 0
    assert melnikov_batch([unsafe])[0]["margins"]["F_e1"]["margin"] < 0
    eng = answer(LIGHT).engineering.critical
    assert all(c.margin_to_chaos > 0 for c in eng.values())


def test_an_amplitudes_nearest_critical_value_has_its_sign() -> None:
    """A negative amplitude is a phase shift by pi: the nearest critical stiffness variation of
    the light design is +88 MN/m (growing the 10 MN/m variation), not -30 MN/m through 0."""
    crit = answer(LIGHT).engineering.critical
    for name in ("stiffness_variation_amplitude", "torque_fluctuation_amplitude"):
        c = crit[name]
        assert c.nearest > 0 and c.margin_to_chaos == pytest.approx(c.nearest - c.value), name


def test_speed_windows_do_not_end_at_the_scan() -> None:
    """Issue 26 item 4: the same pair at 1,500 and at 3,000 rpm has the same window (2,735-4,723
    rpm), not one cut at 3 x the design speed."""
    at_1500 = answer(LIGHT).engineering
    fast = copy.deepcopy(LIGHT)
    fast["speed"] = "3000 rpm"
    at_3000 = answer(fast).engineering
    assert len(at_1500.speed_windows_rpm) == len(at_3000.speed_windows_rpm) == 1
    assert at_1500.speed_windows_rpm[0] == pytest.approx(at_3000.speed_windows_rpm[0], rel=1e-6)
    assert at_1500.speed_windows_rpm[0][1] < at_1500.speed_range_rpm[1]
    assert at_1500.speed_windows_note is None


def test_an_open_ended_window_says_so() -> None:
    """Without damping every sinusoid of M changes sign: chaos is possible up to the scan's
    physical bound (10 x the design speed), and the note says the window is open-ended."""
    undamped = copy.deepcopy(LIGHT)
    undamped["mesh"]["damping_ratio"] = 0.0
    eng = answer(undamped).engineering
    assert eng.speed_range_rpm[1] == pytest.approx(15_000.0)
    assert eng.speed_windows_rpm[-1][1] == pytest.approx(15_000.0)
    assert "open-ended" in eng.speed_windows_note


def test_engineering_reads_the_speed_windows_handed_to_it() -> None:
    """The speed-window scan runs once at the top (``homoclinic.boundary.design_windows``,
    right after the verdict) and the engineering block reads the windows handed to it; it
    scans nothing itself, and None (no saddle at this load) reads as no windows."""
    from gearengine.engineering.block import engineering
    from gearengine.homoclinic.boundary import design_windows

    request = MelnikovRequest.model_validate({"design": LIGHT})
    conv, speeds = request.conversion, request.speed_rpm_range()
    mel = melnikov(conv.params)
    scan = design_windows(conv.params, conv.speed_rpm, speeds, mel)
    assert scan is not None
    assert engineering(conv, speeds, mel, scan) == answer(LIGHT).engineering
    made_up = engineering(conv, speeds, mel, ([[1000.0, 1200.0]], speeds[1]))
    assert made_up.speed_windows_rpm == [[1000.0, 1200.0]]
    heavy = MelnikovRequest.model_validate({"design": EXAMPLE_DESIGN})
    mel = melnikov(heavy.conversion.params)
    assert design_windows(heavy.conversion.params, heavy.conversion.speed_rpm,
                          heavy.speed_rpm_range(), mel) is None  # fmt: skip


def test_a_load_dependent_stiffness_has_one_critical_torque() -> None:
    """With ISO 6336 stiffness k_m grows with the load, and T_crit = F_crit b k_m r_a read at
    the design's own torque moved with it (new-user review of issue 30: 18.2 N*m at 5 N*m,
    25.7 at 20, 27.8 at 27.5, while the envelope's verdicts change between 27.3 and 28.2 N*m).
    T_crit is the torque where it holds at its own stiffness: the same from every design
    torque, and the criterion applies just below it and not just above."""
    from gearengine.analysis import DesignRequest, convert
    from gearengine.engineering.block import Engineering
    from tests.conftest import ROOT

    pair = json.loads((ROOT / "examples/remedies-z23-67.json").read_text())["design"]

    def engineering_at(torque: float) -> Engineering:
        doc = {"design": {**pair, "torque": f"{torque!r} N*m"}}
        return convert(DesignRequest.model_validate(doc)).engineering

    t_crit = [engineering_at(t).critical_torque_nm for t in (5.0, 20.0, 40.0)]
    assert max(t_crit) - min(t_crit) < 1e-6 * t_crit[0] and 27.3 < t_crit[0] < 28.2
    below, above = engineering_at(0.999 * t_crit[0]), engineering_at(1.001 * t_crit[0])
    assert not (below.speed_windows_note or "").startswith("not applicable")
    assert above.speed_windows_note.startswith("not applicable above T_crit")
    assert "under 40 N*m the mesh deflects" in engineering_at(40.0).summary  # its own torque


def test_the_stiffness_at_a_torque_is_the_conversions() -> None:
    """T_crit's fixed point reads k_m(T) alone (``iso_mesh_stiffness``): bit for bit the
    ``mesh_stiffness_n_per_m`` of the whole conversion of the design at that torque, below and
    above 100 N/mm."""
    from gearengine.model.design import Design
    from gearengine.model.reduction import convert_design, iso_mesh_stiffness
    from tests.conftest import ROOT

    pair = json.loads((ROOT / "examples/remedies-z23-67.json").read_text())["design"]
    design = Design.model_validate(pair)
    for torque in (0.5, 5.0, 27.9, 400.0):
        whole = convert_design(design.model_copy(update={"torque": torque}))
        assert iso_mesh_stiffness(design, torque) == whole.mesh_stiffness_n_per_m
    assert iso_mesh_stiffness(design, 0.5) < iso_mesh_stiffness(design, 5.0)


def test_a_parameter_without_a_critical_value_is_explained(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``convert`` of the z = 23/67 pair showed "-" for the TE's nearest critical value and
    margin beside "the criterion allows chaos", unexplained (third new-user review): no TE
    amplitude alone flips the verdict there, since the other excitations keep it."""
    from gearengine.cli.main import main
    from tests.conftest import ROOT

    assert main(["convert", str(ROOT / "examples" / "remedies-z23-67.json")]) == 0
    out = capsys.readouterr().out
    row = next(s for s in out.splitlines() if "transmission_error_amplitude [um]" in s)
    assert row.split()[-2:] == ["-", "-"]
    assert "-: no value of that parameter alone flips the verdict" in out
