"""The numerical verdict of a gear train at its design point, in the train's own words
(``simulate_train``).

A start (x0, v0) of the settings sets the mesh deflection delta and its rate
(``TrainSystem.start_state``); the verdict of each start is the pair's (``runs.start_verdict``:
strobes of (delta, delta'), Benettin on the 2n-dimensional tangent, ``signals.classify``).
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from gearengine.model.design import Design
from gearengine.model.errors import InputError
from gearengine.model.units import response_values
from gearengine.numerics.runs import integrate, start_verdict
from gearengine.numerics.settings import MAX_TOTAL_STEPS, SimulationSettings
from gearengine.signals.classify import severity
from gearengine.signals.diagnostics import ImpactRegime, impact_regime
from gearengine.systems.gear_train.model import train_of
from gearengine.systems.gear_train.system import TrainSystem, train_system


class TrainResponse(BaseModel):
    """The numerical verdict of a train at its design point (worst start)."""

    model_config = ConfigDict(frozen=True)

    classification: str = Field(description="periodic, chaotic, quasi_periodic or diverged.")
    period: int | None = Field(description="Period in forcing periods T0 (periodic only).")
    lle: float | None = Field(description="Largest Lyapunov exponent per unit tau (Benettin, "
                              "2n-dimensional tangent).")  # fmt: skip
    lle_stderr: float | None = Field(description="Its standard error (block estimates).")
    impact_regime: ImpactRegime | None = Field(description="Contact regime of delta.")
    delta_peak_to_peak: float | None = Field(description="Peak to peak of delta [units of b].")
    force_max: float | None = Field(description="Largest mesh force [units of b k_m].")
    dte_um: float | None = Field(description="DTE: peak to peak of delta [um].")
    dynamic_factor: float | None = Field(description="Largest mesh force / static force.")
    steps_per_period: int = Field(description="RK4 steps per T0 used.")
    sampling_interval: float = Field(description="T0 [units of tau].")
    notes: list[str] = Field(description="Remarks on the run.")


def simulate_train(design: Design, settings: SimulationSettings | None = None) -> TrainResponse:
    """The numerical verdict of a design with a ``train`` (module docstring)."""
    settings = settings or SimulationSettings()
    model, pair = train_of(design)
    return respond(train_system(model, pair), settings)


def respond(system: TrainSystem, settings: SimulationSettings) -> TrainResponse:
    """Run every start of ``settings`` on ``system``; the worst start's verdict."""
    plan = system.plan(settings.steps_per_period)
    total = (
        (settings.transient_periods + settings.record_periods) * plan.steps * len(settings.starts())
    )
    if total > MAX_TOTAL_STEPS:
        raise InputError(
            "steps_per_period",
            f"the train needs {plan.steps} RK4 steps per T0, {total} steps in all, over the cap "
            f"{MAX_TOTAL_STEPS}; lower the periods or soften the stiffest shaft or bearing",
        )
    commensurate = plan.omega0 is not None
    runs = []
    for start in settings.starts():
        run = integrate(system, settings, system.start_state(*start), plan)
        runs.append((run, start_verdict(run, start, plan.period, commensurate)))
    worst, verdict = max(runs, key=lambda rv: severity(rv[1].classification, rv[1].period))
    if worst.diverged:
        ptp = fmax = None
        regime = None
    else:
        ptp, fmax = float(worst.xmax - worst.xmin), float(worst.fmax)
        regime = impact_regime(worst.xmin, worst.xmax)
    values = response_values(ptp, fmax, system.conversion.scales)
    est = verdict.lle
    return TrainResponse(
        classification=verdict.classification,
        period=verdict.period,
        lle=None if est is None else est.lle,
        lle_stderr=None if est is None else est.stderr,
        impact_regime=regime,
        delta_peak_to_peak=ptp,
        force_max=fmax,
        dte_um=values["dte"],
        dynamic_factor=values["dynamic_factor"],
        steps_per_period=plan.steps,
        sampling_interval=plan.period,
        notes=list(plan.notes),
    )
