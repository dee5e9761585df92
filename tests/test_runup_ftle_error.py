"""The run-up FTLE's standard error is never a collapsed ensemble's 0 (issue 30 item 5): two
members that settle on one periodic orbit agree to the last bit, so the error comes from the
rates of every member's blocks in the bin."""

from __future__ import annotations

from gearengine.studies.runup import run_local
from gearengine.studies.runup.profile import validated_runup
from tests.test_runup import _request


def test_ftle_standard_error_is_positive_where_the_members_agree() -> None:
    r = validated_runup(_request(from_speed="1000 rpm", to_speed="1200 rpm", rate="4000 rpm/s",
                           direction="up", ensemble={"size": 2}))  # fmt: skip
    bins = run_local(r).up.bins  # type: ignore[union-attr]
    assert bins and all(b.lle is not None and b.lle < 0 for b in bins)  # a periodic response
    assert all(b.lle_stderr is not None and b.lle_stderr > 0 for b in bins)
    assert not any(b.chaotic for b in bins)


def test_ftle_is_read_from_500_rpm_on() -> None:
    """The 23/67 pair settled 100 mesh periods at 500 rpm (~1e4 tau in one block): the tangent
    underflowed to 0 and every bin's FTLE was null; it is the damping's contraction, ~ -mu."""
    from tests.test_robustness import DESIGN

    r = validated_runup({"design": DESIGN, "from_speed": "500 rpm", "to_speed": "700 rpm",
                   "rate": "4000 rpm/s", "direction": "up", "ensemble": {"size": 2}})  # fmt: skip
    bins = run_local(r).up.bins  # type: ignore[union-attr]
    assert bins and all(b.lle is not None for b in bins)
    mu = r.params.damping
    assert all(abs(b.lle + mu) < 0.1 * mu for b in bins)
