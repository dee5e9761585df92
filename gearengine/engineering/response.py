"""The response of an analysis in gear units: DTE, mesh and contact forces, dynamic factor,
how the teeth meet, period and dominant frequency (``Response``, ``response``)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from gearengine.model.answers import Answer
from gearengine.model.params import GearParams
from gearengine.model.reduction import DesignConversion
from gearengine.model.units import in_si, response_values, shown, to_physical
from gearengine.numerics.magnitudes import adverse_over
from gearengine.numerics.results import Attractor, NumericsResult, WorstValue
from gearengine.systems.spur_pair.forcing import contact_force_of, static_error


class Contact(Answer):
    """How the teeth meet over the recorded response (x in units of the half backlash b)."""

    regime: str | None = Field(description="no_impact | single_sided | double_sided.")
    separation_fraction: float = Field(description="Fraction of time with |x| <= 1 (apart).")
    back_flank_fraction: float = Field(description="Fraction of time with x < -1 (back flank).")


class Response(Answer):
    """The numerical response in physical units (last recorded periods) of the recorded run:
    the worst of the settings' own starts (``numerics.worst_case``). With settings.basins the
    verdict is the worst attractor's (``verdict.decided_by``) and the DTE, dynamic factor and
    forces shown and gated are ``most_adverse``'s, over the attractors."""

    dte_peak_to_peak_um: float | None = Field(
        description="Dynamic transmission error p-p [µm]: x = r_a theta_a - r_b theta_b - e(t) "
        "(Eq. 7), the static transmission error e(t) excluded, over every step of the record."
    )
    te_with_static_peak_to_peak_um: float | None = Field(
        None,
        description="Transmission error with the static TE, p-p [µm]: r_a theta_a - r_b theta_b "
        "= x + e(t), what a pair of shaft encoders measures; from the recorded time history.",
    )
    dynamic_mesh_force_max_n: float | None = Field(
        description="Largest mesh force of the model [N]: k_m (K(t) f_h(x) + 2 mu x'), whose "
        "damping term acts in the clearance too (nonzero while the teeth are apart)."
    )
    dynamic_mesh_force_min_n: float | None = Field(
        description="Smallest mesh force of the model [N] (negative: back-flank contact, or the "
        "damping term while apart)."
    )
    contact_force_max_n: float | None = Field(
        None,
        description="Largest tooth contact force [N]: the model's force where a flank touches "
        "(|x| > 1; drive flank >= 0, back flank <= 0), zero while the teeth are apart; from "
        "the recorded time history.",
    )
    contact_force_min_n: float | None = Field(
        None, description="Smallest tooth contact force [N] (negative: back-flank contact)."
    )
    static_force_n: float = Field(description="Mean mesh force F^_m [N].")
    dynamic_factor: float | None = Field(description="max force / static force.")
    contact: Contact | None
    period_ms: float | None = Field(description="Response period [ms], null if not periodic.")
    period_mesh_periods: float | None = Field(description="Response period / mesh period.")
    dominant_frequency_hz: float | None = Field(description="Largest spectral peak [Hz].")
    dominant_shaft_order: float | None = Field(description="That frequency / driver speed.")


IMPACT_WORDS = {
    "no_impact": "the teeth always in contact",
    "single_sided": "tooth separation and impacts on the drive flank",
    "double_sided": "impacts on both flanks (back-flank contact)",
}


def response(params: GearParams, num: NumericsResult, conv: DesignConversion) -> Response:
    """The response of an analysis in physical units: DTE, mesh forces and dynamic factor from
    the kernel's extremes over every step of the record (``model.units.response_values``, as a
    sweep point's), the contact fractions from the recorded time history."""
    scales = conv.scales
    hist = num.time_history
    contact = None
    forces = [None if f is None else to_physical("mesh_force", f, scales)
              for f in (num.force_max, num.force_min)]  # fmt: skip
    values = response_values(num.x_peak_to_peak, num.force_max, scales)
    te, touching = None, [None, None]
    if hist is not None and hist.x:
        x = np.asarray(hist.x)
        t, v = np.asarray(hist.t), np.asarray(hist.v)
        te = shown(to_physical("dte", float(np.ptp(x + static_error(params, t))), scales))
        force = contact_force_of(params, t, x, v)
        touching = [
            shown(to_physical("mesh_force", float(f), scales)) for f in (force.max(), force.min())
        ]
        contact = Contact(
            regime=num.impact_regime,
            separation_fraction=float(np.mean(np.abs(x) <= 1.0)),
            back_flank_fraction=float(np.mean(x < -1.0)),
        )
    period = None if num.period is None else num.period * num.sampling_interval
    period_s = None if period is None else in_si("time", period, scales)
    peaks = num.spectrum_peaks
    peak = to_physical("frequency", peaks[0].frequency, scales) if peaks else None
    shaft_hz = conv.speed_rpm / 60.0
    return Response(
        dte_peak_to_peak_um=values["dte"],
        dynamic_mesh_force_max_n=forces[0],
        dynamic_mesh_force_min_n=forces[1],
        te_with_static_peak_to_peak_um=te,
        contact_force_max_n=touching[0],
        contact_force_min_n=touching[1],
        static_force_n=scales.static_force,
        dynamic_factor=values["dynamic_factor"],
        contact=contact,
        period_ms=None if period is None else to_physical("time", period, scales),
        period_mesh_periods=None if period_s is None else period_s * conv.mesh_frequency_hz,
        dominant_frequency_hz=peak,
        dominant_shaft_order=None if peak is None else peak / shaft_hz,
    )


HISTORY_MAGNITUDES = {
    "te_with_static": ("te_with_static_peak_to_peak_um", "um", max),
    "contact_force_max": ("contact_force_max_n", "N", max),
    "contact_force_min": ("contact_force_min_n", "N", min),
}
"""The magnitudes of ``engineering.Response`` read from a run's time history (the TE an
encoder sees, with the static TE; the contact force, zero while apart): ``most_adverse``'s
table for them."""


def history_magnitudes(conv: DesignConversion, found: list[Attractor],
                       runs: dict[int, NumericsResult]) -> dict[str, WorstValue]:  # fmt: skip
    """``HISTORY_MAGNITUDES`` at their most adverse over ``runs`` (attractor index in
    ``found``: its own run, ``numerics.magnitudes.attractor_runs``), each run read as the
    recorded run is (``response``)."""
    read = {k: response(conv.params, run, conv) for k, run in runs.items()}
    return adverse_over(found, read, HISTORY_MAGNITUDES)
