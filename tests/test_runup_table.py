"""The run-up table says the counts the JSON has (issue 30 item 5): entries onto the drive flank
and onto the back flank, not one 'impacts' column holding the back-flank count alone."""

from __future__ import annotations

from types import SimpleNamespace

from gearengine.cli.runup import branch_table
from gearengine.studies.runup.results import RunupBin, RunupBranch


def table_of_one_bin(contact: str, separation: float, drive_impacts: int) -> list[str]:
    """The header and the line of a run-up table holding one bin at 3,500-3,550 rpm."""
    b = RunupBin.model_construct(
        speed_rpm=[3500.0, 3550.0], time_s=[0.0, 0.025], dte_peak_to_peak_um=30.0,
        dynamic_factor=2.0, contact=contact, separation_fraction=separation,
        back_flank_fraction=0.0, back_flank_impacts=0, drive_flank_impacts=drive_impacts,
        lle=None, chaotic=None,
    )  # fmt: skip
    result = SimpleNamespace(quasi_static=SimpleNamespace(up=SimpleNamespace(points=[])))
    return branch_table("up", RunupBranch.model_construct(bins=[b], jumps=[]), result)[1:]


def test_impact_counts_of_both_flanks_are_in_the_table() -> None:
    header, line = table_of_one_bin("single_sided", 0.3, 57)
    assert "impacts drive/back" in header
    assert line.split()[-2:] == ["57/0", "-"]


def test_a_bin_that_separates_at_times_is_labelled_separation() -> None:
    """Not 'no_contact' (which read as never touching) for teeth apart 1 % of the time."""
    from gearengine.studies.runup import run_local
    from gearengine.studies.runup.profile import validated_runup
    from tests.test_runup import _request

    r = validated_runup(_request(from_speed="4300 rpm", to_speed="4500 rpm", rate="4000 rpm/s",
                           direction="up", ensemble={"size": 1}))  # fmt: skip
    bins = run_local(r).up.bins  # type: ignore[union-attr]
    apart = [b for b in bins if b.separation_fraction and b.back_flank_fraction == 0]
    assert apart and {b.contact for b in apart} == {"separation"}


def test_a_bin_labelled_separation_shows_how_long_the_teeth_are_apart() -> None:
    """A bin is separation when the teeth are apart for any time in it (docs/units.md); the
    table gave the share to two decimals, so 0.2 % read '0.00' beside 'separation' (issue 30
    review, item 7). It is in % to two significant digits now."""
    header, line = table_of_one_bin("separation", 0.002, 3)
    assert "sep %  back %" in header
    assert line.split()[-5:-2] == ["separation", "0.2", "0"]
