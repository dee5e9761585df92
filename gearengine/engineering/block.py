"""The engineering block of a design's answer (``Engineering``): the speed windows, the
critical torque, the thresholds and the response in gear units, and the plain sentences of a
design review (``summary``)."""

from __future__ import annotations

import math

from pydantic import Field

from gearengine.engineering.response import IMPACT_WORDS, Response, history_magnitudes, response
from gearengine.engineering.thresholds import CONTROLS, Critical, critical
from gearengine.homoclinic.boundary import WINDOW_BOUND, critical_torque
from gearengine.homoclinic.coefficients import T_CRIT_WHY
from gearengine.homoclinic.schemas import MelnikovResult
from gearengine.model.answers import Answer
from gearengine.model.design import Design
from gearengine.model.reduction import Derived, DesignConversion
from gearengine.model.units import to_physical
from gearengine.numerics.headline import Headline
from gearengine.numerics.magnitudes import worst_words
from gearengine.numerics.results import NumericsResult, WorstValue
from gearengine.systems.gear_train.modes import Modes


class Engineering(Answer):
    """The answer in gear-design units."""

    natural_frequency_hz: float
    time_scale_s: float
    mesh_frequency_hz: float
    half_backlash_um: float = Field(
        description="The half backlash b [µm], the unit of x in the dimensionless results."
    )
    speed_rpm: float
    speed_range_rpm: list[float] = Field(description="Driver speeds scanned [rpm].")
    speed_windows_rpm: list[list[float]] = Field(
        description="[low, high] driver speeds [rpm] where the Melnikov criterion allows chaos "
        "at this torque (every excitation frequency scales with speed); empty where the "
        "criterion does not apply (above the critical torque)."
    )
    speed_windows_note: str | None = Field(
        None,
        description="Why there are no windows (not applicable above T_crit), or which window is "
        "open-ended (still open at the end of the scan).",
    )
    critical_torque_nm: float | None = Field(
        None,
        description="T_crit [N m]: the mean driver torque below which the Melnikov criterion "
        "applies (the static mesh force reaches F_crit of the cubic fit there; null without "
        "one).",
    )
    critical: dict[str, Critical] = Field(description="Thresholds in physical units.")
    derived: dict[str, Derived]
    response: Response | None = Field(
        None,
        description="For analyses: the response of the recorded run (the worst of the "
        "settings' own starts, numerics.worst_case); with settings.basins see most_adverse.",
    )
    most_adverse: dict[str, WorstValue] | None = Field(
        None,
        exclude_if=lambda worst: worst is None,  # an analysis without basins keeps its JSON
        description="With settings.basins: the magnitudes shown and gated (dte [um], "
        "dynamic_factor, force_max [N], force_min [N]; for a pair also te_with_static [um] and "
        "contact_force_max / contact_force_min [N], each attractor run again from a start that "
        "reached it) at their most adverse over the attractors whose basin fraction is above "
        "basins.min_fraction (the largest; force_min and contact_force_min the smallest), each "
        "naming the attractor it comes from. The verdict is the worst attractor by class "
        "(verdict.decided_by); a magnitude's attractor may be another one. The summary, the "
        "one-line summary and gearengine check read these.",
    )
    summary: str = Field(description="Plain sentences for a design review.")
    notes: list[str]
    modes: Modes | None = Field(
        None,
        exclude_if=lambda modes: modes is None,  # a pair's JSON stays the pair's
        description="With a train: its modes linearised in contact (docs/gear-trains.md).",
    )


def load_words(conv: DesignConversion, f_crit: float, t_crit: float) -> str:
    """Why the criterion does not apply at this torque (F~_m >= F_crit), in gear words."""
    fm, b_um = conv.params.mean_force, to_physical("displacement", 1.0, conv.scales)
    r_a = float(conv.derived["base_radius_driver"].value)  # type: ignore[arg-type]
    torque = to_physical("mesh_force", abs(fm), conv.scales) * r_a  # at the design's own k_m
    return (
        f"under {torque:,.3g} N*m the mesh deflects {abs(fm) * b_um:.3g} µm statically (half "
        f"backlash {b_um:.3g} µm) and at rest the teeth are in contact (in motion they may "
        "separate: the numerical verdict says), beyond the reach of the backlash nonlinearity's "
        "saddle, which exists only below the critical torque "
        f"{t_crit:,.3g} N*m; the homoclinic mechanism of chaos does not exist at this load; the "
        "numerical verdict still applies"
    )


def _windows_text(windows: list[list[float]], rng: tuple[float, float]) -> str:
    if not windows:
        return f"allows no chaos at any speed from {rng[0]:,.0f} to {rng[1]:,.0f} rpm"
    spans = ", ".join(f"{a:,.0f}-{b:,.0f} rpm" for a, b in windows)
    return f"allows chaos at {spans} (scanned {rng[0]:,.0f} to {rng[1]:,.0f} rpm)"


def summary(
    conv: DesignConversion,
    mel: MelnikovResult,
    windows: list[list[float]],
    rng: tuple[float, float],
    resp: Response | None,
    num: NumericsResult | None,
    decided: Headline | None,
    t_crit: float | None,
    over: bool,
    worst: dict[str, WorstValue] | None = None,
) -> str:
    """Two or three sentences an engineer can paste into a design review; with basins the
    response named is the worst attractor's above the basin threshold (``decided``, with its
    fraction and LLE), and the contact and the LLE that follow are the recorded run's when that
    run settled elsewhere (said so); the DTE and dynamic factor are ``worst``'s with basins
    (the largest over the attractors, each named), else the run's; ``t_crit`` the critical torque
    (``critical_torque``); ``over`` True above the critical load (no saddle, no speed windows
    looked for)."""
    f_crit = mel.critical_mean_force if over and t_crit is not None else None
    if f_crit or not mel.applicable:  # its load, or its notes' reason (a train, no reduction)
        why = load_words(conv, f_crit, t_crit) if f_crit and t_crit else mel.notes[0]
        text = f"At {conv.speed_rpm:,.0f} rpm the Melnikov criterion does not apply: {why}."
    else:
        here = "allows chaos" if mel.chaos_possible else "rules chaos out"
        text = (
            f"At {conv.speed_rpm:,.0f} rpm the Melnikov criterion {here}; at this torque it "
            f"{_windows_text(windows, rng)}."
        )
        outside = abs(conv.params.mean_force) >= (mel.critical_mean_force or math.inf)
        if t_crit is not None and mel.mean_load == "perturbation" and outside:
            text += (f" This is the paper's first-order answer outside its domain: above the "
                     f"critical torque {t_crit:,.3g} N*m the loaded system has no "
                     "saddle.")  # fmt: skip
        elif t_crit is not None:
            text += f" It applies below the critical torque {t_crit:,.3g} N*m."
    if num is not None and resp is not None:
        kind = f"periodic ({num.period}T)" if num.period else num.classification.replace("_", "-")
        other = decided is not None and decided.kind != kind  # the worst attractor is not the run
        if decided is None:
            text += f" The simulated response is {kind}"
        elif not other:
            text += f" The simulated response is {kind} ({decided.decided_by})"
        else:  # its LLE here; contact, DTE, dynamic factor and LLE below are the recorded run's
            lle = decided.attractor.lle if decided.attractor else None
            text += (f" The simulated response is {decided.kind} ({decided.decided_by}, the worst "
                     f"attractor{lle_words(lle, conv)}); the recorded run from the settings' "
                     f"start is {kind}")  # fmt: skip
        if resp.contact is not None:
            text += f" with {IMPACT_WORDS.get(resp.contact.regime or '', 'no verdict on impacts')}"
            if resp.contact.separation_fraction > 0.0:
                text += f" (teeth apart {100 * resp.contact.separation_fraction:.0f} % of the time)"
        if worst is None and resp.dte_peak_to_peak_um is not None:
            text += f", dynamic transmission error {resp.dte_peak_to_peak_um:.3g} µm peak to peak"
            text += static_te_words(resp)
        if worst is None and resp.dynamic_factor is not None:
            text += f", dynamic factor {resp.dynamic_factor:.3g}"
        a = None if decided is None or other else decided.attractor  # tau = omega_n t
        text += lle_words(num.lle if a is None else a.lle, conv) + "."
        text += worst_words(worst or {})
    return text


def static_te_words(resp: Response) -> str:
    """ " (the static transmission error excluded; with it 23 µm, what shaft encoders read)"
    beside a DTE where a static TE moves the encoders' number (an NVH engineer reads "DTE" as
    the loaded TE an encoder measures: 0.856 µm here was 23.04 µm there, unsaid), else ""."""
    te, dte = resp.te_with_static_peak_to_peak_um, resp.dte_peak_to_peak_um
    if te is None or dte is None or f"{te:.3g}" == f"{dte:.3g}":
        return ""
    return (
        f" (the static transmission error excluded; with it {te:.3g} µm, what shaft encoders read)"
    )


def lle_words(lle: float | None, conv: DesignConversion) -> str:
    """The LLE in words, ", largest Lyapunov exponent ... 1/s (... per unit tau)", or ""."""
    if lle is None:
        return ""
    per_s = float(f"{lle / conv.time_scale_s:.3g}")  # 3 digits, no exponent below 1e6
    return f", largest Lyapunov exponent {per_s:+,g} 1/s ({lle:+.3g} per unit tau)"


def engineering(
    conv: DesignConversion,
    rpm_range: tuple[float, float],
    mel: MelnikovResult,
    scan: tuple[list[list[float]], float] | None,
    num: NumericsResult | None = None,
    decided: Headline | None = None,
    no_windows: str | None = None,
    worst: dict[str, WorstValue] | None = None,
    design: Design | None = None,
    runs: dict[int, NumericsResult] | None = None,
) -> Engineering:
    """The engineering block of a design's Melnikov verdict (and analysis, given ``num``;
    ``decided`` the worst attractor of its basins, ``numerics.headline.headline``) from the
    values handed to it: ``scan`` the speed windows [rpm] and the end of their scan
    (``homoclinic.boundary.design_windows``, None above the critical load).
    ``no_windows``: why the speed windows are not looked for (a train without a Melnikov
    reduction), said in their note; the range stays the scan's. ``worst``: with basins each
    magnitude at its most adverse over the attractors (``numerics.magnitudes.most_adverse``);
    ``design`` for a load-dependent T_crit (``critical_torque``); ``runs`` the attractors' own
    runs (``numerics.magnitudes.attractor_runs``), whose histories add ``HISTORY_MAGNITUDES``
    to ``worst``."""
    params = conv.params
    resp = None if num is None else response(params, num, conv)
    if runs and num is not None and num.attractors is not None and worst is not None:
        worst = worst | history_magnitudes(conv, num.attractors, runs)
    t_crit = critical_torque(conv, mel, design)
    crit = {
        CONTROLS[name]: critical(name, t, conv.scales)
        for name, t in mel.thresholds.items()
        if name in CONTROLS and t.value is not None and (t.critical_values or t.note is None)
    }
    note = None
    lo, hi = rpm_range
    if scan is None:  # no saddle at this load: a critical torque exists
        windows: list[list[float]] = []
        note = f"not applicable above T_crit = {t_crit:,.3g} N*m: {T_CRIT_WHY}"
    else:
        windows, hi = scan
        if windows and windows[-1][1] >= hi and hi > rpm_range[1]:
            note = (
                f"the window from {windows[-1][0]:,.0f} rpm is open-ended: chaos is still "
                f"possible at {hi:,.0f} rpm, {WINDOW_BOUND:g} x the design speed, where the "
                "scan stops"
            )
        elif windows and windows[-1][1] >= hi:
            note = f"the window from {windows[-1][0]:,.0f} rpm reaches the end of the scan"
    if no_windows is not None:
        note = no_windows
    return Engineering(
        natural_frequency_hz=conv.natural_frequency_hz,
        time_scale_s=conv.time_scale_s,
        mesh_frequency_hz=conv.mesh_frequency_hz,
        half_backlash_um=to_physical("displacement", 1.0, conv.scales),
        speed_rpm=conv.speed_rpm,
        speed_range_rpm=[lo, hi],
        speed_windows_rpm=windows,
        speed_windows_note=note,
        critical_torque_nm=t_crit,
        critical=crit,
        derived=conv.derived,
        response=resp,
        most_adverse=worst if num is not None and decided is not None else None,
        summary=summary(
            conv,
            mel,
            windows,
            (lo, hi),
            resp,
            num,
            decided,
            t_crit,
            scan is None,
            worst if decided is not None else None,
        ),
        notes=conv.notes,
    )
