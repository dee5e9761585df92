"""Model against rig: the design's simulated verdict at the signal's speed, beside the
signal's (``read_signal``, ``signal``: the facade's door to a recorded series).

The design (``SignalRequest.design``) is analysed (``gearengine.analysis.analyze``, default
settings) at the signal's shaft speed (its speed, the tach's mean, else the design's own) and
the design's torque. Its spectrum lines (angular frequencies in tau units, ``omega``) are put
in shaft orders through the design's time scale, f = omega / (2 pi t_s), order = f / f_shaft,
so that they overlay the signal's order spectrum, amplitudes in µm of relative displacement
(x times the half backlash); its LLE per tau becomes per second as
lambda / t_s. "Agrees" compares the families: periodic with periodic, chaotic with chaotic,
quasi-periodic with quasi-periodic (null when the signal's verdict is undetermined or
stochastic, which the deterministic model cannot give).

When they disagree, a short sweep asks which uncertain quantity of the design moves the model
towards the rig: the mesh damping, the half backlash and the transmission-error amplitudes,
each halved and doubled (``LEVERS`` x ``FACTORS``, one analysis each), with the model's verdict
for every trial.

A recording over the service's synchronous budget is read as a durable job of kind ``signal``
(``SIGNAL_JOB``): one chunk, the whole reading, whose result is ``read_signal``'s document.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from gearengine.analysis import AnalysisRequest, analyze
from gearengine.model.design import Design
from gearengine.numerics.runs import work
from gearengine.signals.reading import read
from gearengine.signals.schema import LeverTrial, ModelReport, SignalResult, SpectrumLine
from gearengine.signals.series import SignalRequest
from gearengine.studies.jobs import one_chunk_kind

COMPARABLE = frozenset({"periodic", "quasi_periodic", "chaotic"})
FACTORS = (0.5, 2.0)


def _damping(data: dict[str, Any], factor: float) -> str:
    mesh = data["mesh"]
    key = "damping_ratio" if "damping_ratio" in mesh else "damping"
    mesh[key] *= factor
    return f"{mesh[key]:.4g}" + ("" if key == "damping_ratio" else " N s/m")


def _half_backlash(data: dict[str, Any], factor: float) -> str:
    data["mesh"]["half_backlash"] *= factor
    return f"{data['mesh']['half_backlash'] * 1e6:.4g} um"


def _transmission_error(data: dict[str, Any], factor: float) -> str:
    harmonics = (data.get("transmission_error") or {}).get("harmonics", [])
    for h in harmonics:
        h["amplitude"] *= factor
    return ", ".join(f"{h['amplitude'] * 1e6:.4g} um" for h in harmonics) or "none"


LEVERS: dict[str, Callable[[dict[str, Any], float], str]] = {
    "damping": _damping,
    "half_backlash": _half_backlash,
    "transmission_error": _transmission_error,
}
"""The design's uncertain quantities: each scales its field of a design document (SI units)
and says the value tried."""


def short_sweep(design: Design, signal_verdict: str) -> list[LeverTrial]:
    """The model's verdict with each lever halved and doubled (design already at speed)."""
    trials = []
    for name, scale in LEVERS.items():
        for factor in FACTORS:
            data = copy.deepcopy(design.model_dump(exclude_none=True))
            value = scale(data, factor)
            try:
                result = analyze(AnalysisRequest.model_validate({"design": data}))
                verdict: str | None = result.numerics.classification
            except ValueError:  # out of the design's plausible ranges: refused
                verdict = None
            trials.append(LeverTrial(quantity=name, factor=factor, value=value,
                                     classification=verdict,
                                     matches_signal=verdict == signal_verdict))  # fmt: skip
    return trials


def at_speed(design: Design, speed: float) -> Design:
    """The design at driver speed ``speed`` [rad/s] (validated again: derived data follow)."""
    data = design.model_dump(exclude_none=True)
    data["speed"] = speed
    return Design.model_validate(data)


def model_beside(request: SignalRequest, verdict: str) -> ModelReport:
    """The model's verdict for ``request.design`` at the signal's speed."""
    assert request.design is not None and request.shaft_hz is not None
    shaft = request.shaft_hz
    design = at_speed(request.design, 2.0 * math.pi * shaft)
    result = analyze(AnalysisRequest.model_validate({"design": design}))
    eng = result.engineering
    assert eng is not None
    num = result.numerics
    t_s = eng.time_scale_s
    teeth = design.driver.teeth
    lines = []
    for peak in num.spectrum_peaks:
        hz = peak.frequency / (2.0 * math.pi * t_s)
        order = hz / shaft
        k = order / teeth
        label = f"mesh harmonic {round(k)}" if abs(k - round(k)) < 0.01 else f"order {order:.4g}"
        amplitude = peak.amplitude * eng.half_backlash_um
        lines.append(SpectrumLine(frequency_hz=hz, order=order, amplitude=amplitude,
                                  ratio_db=0.0, label=label))  # fmt: skip
    model = num.classification
    agrees = (model == verdict) if verdict in COMPARABLE else None
    lle = None if num.lle is None else num.lle / t_s
    said = {True: "agrees with the signal", False: f"disagrees with the signal ({verdict})",
            None: f"cannot be compared with a {verdict} signal"}[agrees]  # fmt: skip
    sweep = short_sweep(design, verdict) if agrees is False else []
    moves = [f"{t.quantity} x {t.factor:g} ({t.value})" for t in sweep if t.matches_signal]
    if agrees is False:
        said += (f"; the model reads {verdict.replace('_', '-')} with " + ", ".join(moves)
                 if moves else "; halving or doubling the damping, the half backlash or the "
                 "transmission error alone does not make it so")  # fmt: skip
    plural = "s" if num.period and num.period > 1 else ""
    period = f" (period {num.period} forcing period{plural})" if num.period else ""
    return ModelReport(
        speed_rpm=shaft * 60.0, torque_nm=design.torque, classification=model,
        period=num.period, lle_per_second=lle, agrees=agrees, lines=lines, sweep=sweep,
        summary=f"The model at {shaft * 60.0:.6g} rpm and {design.torque:.6g} N m is "
        f"{model.replace('_', '-')}{period}: it {said}.",
    )  # fmt: skip


def read_signal(request: SignalRequest) -> SignalResult:
    """The reading of a recorded series (``signals.reading.read``) and, with a ``design``, the
    model's verdict beside it (``model_beside``): what ``POST /v1/signals`` answers."""
    result = read(request)
    if request.design is None:
        return result
    return result.model_copy(update={"model": model_beside(request, result.verdict)})


def signal(
    values: Sequence[float] | np.ndarray,
    sample_rate: float | str,
    *,
    speed: float | str | None = None,
    teeth: int | None = None,
    tach: dict[str, Any] | None = None,
    quantity: str = "other",
    unit: str = "1",
    design: dict[str, Any] | None = None,
    seed: int = 0,
) -> SignalResult:
    """Read a recorded series: ``gearengine.signal(x, "20 kHz", speed="1500 rpm", teeth=18)``.

    Arguments as the fields of ``SignalRequest`` (quantities as strings with units or SI
    numbers); raises pydantic's ValidationError naming the field for bad input."""
    body: dict[str, Any] = {
        "signal": {"values": np.asarray(values, dtype=float).tolist(),
                   "sample_rate": sample_rate, "quantity": quantity, "unit": unit},
        "seed": seed,
    }  # fmt: skip
    for key, value in (("speed", speed), ("teeth", teeth), ("tach", tach), ("design", design)):
        if value is not None:
            body[key] = value
    return read_signal(SignalRequest.model_validate(body))


def signal_work(request: SignalRequest) -> int:
    """RK4 steps of a reading (the job budget's unit): the model's analysis at the signal's
    speed and, should the model disagree, its six lever trials (``short_sweep``), each costed
    as the analysis; none without a design (the reading itself integrates nothing; its
    samples are bounded by ``MAX_SAMPLES``)."""
    if request.design is None:
        return 0
    analysis = AnalysisRequest.model_validate({"design": request.design})
    return (1 + len(LEVERS) * len(FACTORS)) * work(analysis.params, analysis.settings)


SIGNAL_JOB = one_chunk_kind(
    "signal",
    SignalRequest,
    SignalResult,
    units=lambda request: len(request.signal.values),
    work=signal_work,
    compute=read_signal,
)
"""A recording read as a durable job (the service's ``/v1/signals/jobs``): its result is
``read_signal``'s document for the same request, byte for byte."""
