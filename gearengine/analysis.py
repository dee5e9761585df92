"""The full answer for one design: Melnikov verdict, numerical verdict, and whether they agree.

The Melnikov criterion is first order in the perturbation and only *necessary* for chaos
(a transverse homoclinic tangle may give transient chaos and a periodic attractor). The two
verdicts are consistent unless the numerics find chaos where Melnikov rules it out.

This module joins the homoclinic (Melnikov) and numerics rooms on a request of the model room,
and adds the engineering block (``engineering``: answers in gear units) for a design.
With ``settings.basins`` it adds the attractors of ``numerics.attractors``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, model_validator

from gearengine.engineering.block import Engineering, engineering
from gearengine.engineering.response import IMPACT_WORDS
from gearengine.homoclinic.boundary import design_windows
from gearengine.homoclinic.coefficients import T_CRIT_WHY
from gearengine.homoclinic.schemas import MelnikovRequest, MelnikovResult
from gearengine.homoclinic.train_reduction import train_melnikov
from gearengine.homoclinic.verdict import melnikov, not_applicable
from gearengine.model.design import EXAMPLE_DESIGN, Design
from gearengine.model.errors import InputError
from gearengine.model.examples import PAPER_SECTION_41
from gearengine.model.params import GearParams, request_config
from gearengine.model.reduction import DesignConversion, ParamsOrDesign
from gearengine.numerics.attractors import planned_attractors
from gearengine.numerics.headline import Headline, coexistence, headline, of_starts
from gearengine.numerics.magnitudes import attractor_runs, most_adverse
from gearengine.numerics.physical import in_seconds
from gearengine.numerics.results import Attractor, NumericsResult
from gearengine.numerics.runs import as_system
from gearengine.numerics.settings import RequestSettings, SimulationSettings, plan_work
from gearengine.numerics.simulation import simulate
from gearengine.systems.base import StepPlan, System
from gearengine.systems.designs import design_model
from gearengine.systems.gear_train.modes import modes
from gearengine.systems.gear_train.system import TrainSystem
from gearengine.systems.spur_pair.laws import melnikov_cubic

Agreement = Literal["both_chaotic", "both_regular", "melnikov_only", "numerics_only", "undecided"]


class AnalysisRequest(ParamsOrDesign):
    """``{"params": {...}, "settings": {...}}``: analyse one design."""

    model_config = request_config({"params": PAPER_SECTION_41, "settings": {}})
    TRAINS = True  # systems.gear_train answers for it

    settings: RequestSettings = Field(
        default_factory=SimulationSettings,
        description="Integration settings (defaults: 500 + 500 periods, 200 steps, x0 = "
        "(0.01, 0.01)).",
    )
    _system: GearParams | System | None = PrivateAttr(None)
    _plan: StepPlan | None = PrivateAttr(None)

    @model_validator(mode="after")
    def _carry_system(self) -> AnalysisRequest:
        """Build what the numerics run once, when the request is validated: its params, or
        for a design with a ``train`` its ``TrainSystem`` (``systems.designs.design_model``),
        and its RK4 step plan at ``settings.steps_per_period``; the budget check, the
        analysis and the basins job all read them from here."""
        design = self.design
        if design is not None and design.train is not None:
            self._system = design_model(design)[0]
        else:
            self._system = self.params
        self._plan = as_system(self._system).plan(self.settings.steps_per_period)
        return self

    @property
    def system(self) -> GearParams | System:
        """What the numerics run: the pair's params, or the train's ``TrainSystem``."""
        assert self._system is not None
        return self._system

    @property
    def plan(self) -> StepPlan:
        """The RK4 step plan of ``system`` at ``settings.steps_per_period`` (the runs and the
        basin starts share it: a copy with other basins keeps it)."""
        assert self._plan is not None
        return self._plan

    @property
    def work(self) -> int:
        """RK4 steps of the analysis, basin starts included (``numerics.settings.plan_work``),
        for the compute budgets."""
        return plan_work(self.system, self.settings, self.plan)


class Verdict(BaseModel):
    """How the analytical and the numerical verdicts relate."""

    model_config = ConfigDict(frozen=True)

    agreement: Agreement = Field(
        description="both_chaotic: tangle and chaos; both_regular: no tangle, no chaos; "
        "melnikov_only: tangle but a regular attractor (consistent: Melnikov is necessary, not "
        "sufficient); numerics_only: chaos without a first-order tangle; undecided: Melnikov "
        "not applicable or the state diverged."
    )
    consistent: bool = Field(description="False only for numerics_only.")
    chaotic: bool = Field(
        description="The numerics classify the worst start as chaotic (with settings.basins: "
        "the worst attractor whose basin fraction is above basins.min_fraction)."
    )
    summary: str = Field(description="One readable line.")
    decided_by: str | None = Field(
        None,
        description="With settings.basins: the attractor (or divergence) that decided the "
        "verdict and its basin fraction; null without. numerics.classification, worst_case, "
        "floquet and the records are then the settings' own start's (numerics.notes says so).",
    )
    decided_attractor: int | None = Field(
        None,
        exclude_if=lambda index: index is None,  # an analysis without basins keeps its JSON
        description="With settings.basins: the index in numerics.attractors of the attractor "
        "that decided the verdict (absent without basins, or when the starts diverged).",
    )


class AnalysisResult(BaseModel):
    """The /v1/analyses contract: Melnikov, numerics, settings used, and the verdict."""

    model_config = ConfigDict(frozen=True)

    melnikov: MelnikovResult
    numerics: NumericsResult
    settings: SimulationSettings
    verdict: Verdict
    params: GearParams | None = Field(
        None, description="With a design: the dimensionless parameters used (reproducible)."
    )
    engineering: Engineering | None = Field(
        None, description="With a design: the answer in gear-design units."
    )

    def summary(self) -> str:
        """The verdicts in one line: response, LLE (with a design also in 1/s), contact,
        Melnikov, and with a design the DTE, dynamic factor and Melnikov speed windows (the
        gate's PASS or FAIL line). With basins the LLE and contact are the deciding attractor's,
        the DTE and dynamic factor the largest over the attractors above the basin threshold
        (``magnitudes_text``: named where another attractor holds them)."""
        num = self.numerics
        decided = decision(num, self.settings) or num  # with basins the worst attractor's
        kind = f"periodic {decided.period}T" if decided.period else decided.classification
        if decided is not num:
            kind += f" ({decided.decided_by})"
        who = num if decided is num else decided.attractor  # its LLE and contact (or diverged)
        value, err = (None, None) if who is None else (who.lle, who.lle_stderr)
        lle = "LLE n/a" if value is None else f"LLE {value:+.4g} ± {err or 0:.2g} per unit tau"
        if value is not None and self.engineering is not None:  # tau = omega_n t
            lle += f" = {float(f'{value / self.engineering.time_scale_s:.4g}'):+,g} 1/s"
        regime = None if who is None else who.impact_regime
        contact = IMPACT_WORDS.get(regime or "", "no verdict on impacts")
        mel = {True: "chaos possible", False: "chaos not possible"}.get(
            self.melnikov.chaos_possible, "not applicable, not judged"
        )
        line = f"{kind} ({lle}, {contact}), Melnikov: {mel}"
        eng = self.engineering
        if eng is not None:
            line += magnitudes_text(eng, None if decided is num else decided.attractor)
            lo, hi = eng.speed_range_rpm
            spans = ", ".join(f"{a:,.0f}-{b:,.0f}" for a, b in eng.speed_windows_rpm)
            scanned = (f"at {spans} rpm (scanned {lo:,.0f}-{hi:,.0f} rpm)" if spans
                       else f"nowhere in {lo:,.0f}-{hi:,.0f} rpm (scanned)")  # fmt: skip
            if eng.speed_windows_note and not eng.speed_windows_rpm:  # why T_crit: the block's
                note = eng.speed_windows_note.removesuffix(f": {T_CRIT_WHY}")
                line += f"; Melnikov speed windows: {note}"
            else:
                line += f"; Melnikov chaos possible {scanned}"
        return line

    def __repr__(self) -> str:  # the full document is ~85 kB (time history, spectrum)
        return f"AnalysisResult({self.summary()!r})"

    __str__ = summary


def magnitudes_text(eng: Engineering, decided: Attractor | None) -> str:
    """'; DTE 62 µm, dynamic factor 9.92' of the one-line summary: the settings' run's, or
    with basins the largest over the attractors above the threshold (``most_adverse``), named
    with its basin fraction when it is not the deciding attractor ``decided``'s (once after
    both when one attractor holds both): '; DTE 62 µm, dynamic factor 9.92 (periodic 1T, ...
    from 69 % of starts)'."""
    resp, worst = eng.response, eng.most_adverse
    if worst is None:
        dte = None if resp is None else resp.dte_peak_to_peak_um
        factor = None if resp is None else resp.dynamic_factor
        values = [(dte, ""), (factor, "")]
    else:
        values = []
        for key in ("dte", "dynamic_factor"):
            w = worst.get(key)
            same = w is None or (decided is not None and w.label == decided.label)
            values.append((None if w is None else w.value,
                           "" if same else f" ({of_starts(w.label, w.fraction)})"))  # fmt: skip
    (dte, dte_who), (factor, factor_who) = values
    if dte is not None and factor is not None and dte_who == factor_who:
        dte_who = ""  # one attractor holds both: named once, after both
    out = "" if dte is None else f"; DTE {dte:.3g} µm{dte_who}"
    return out + ("" if factor is None else f", dynamic factor {factor:.3g}{factor_who}")


class MelnikovAnswer(MelnikovResult):
    """The /v1/melnikov contract: the verdict, and with a design its params and engineering."""

    params: GearParams | None = Field(
        None, description="With a design: the dimensionless parameters used (reproducible)."
    )
    engineering: Engineering | None = Field(
        None, description="With a design: the answer in gear-design units."
    )


def verdict(mel: MelnikovResult, num: NumericsResult, decided: Headline | None = None) -> Verdict:
    """Compare the Melnikov verdict with the numerical classification: that of the worst
    start, or with basins of the worst attractor that decides (``decision``)."""
    classification, period_n, decided_by, basins = num.classification, num.period, None, ""
    index = None
    if num.attractors is not None and num.basins is not None:
        basins = f" ({coexistence(num.attractors, num.basins)})"
        if decided is not None:
            classification, period_n = decided.classification, decided.period
            decided_by = decided.decided_by
            if decided.attractor is not None:
                index = num.attractors.index(decided.attractor)
    chaotic = classification == "chaotic"
    period = f" ({period_n}T)" if period_n else ""
    numerics = f"numerics: {classification}{period}{basins}"
    if classification == "diverged" or mel.chaos_possible is None:
        why = "Melnikov not applicable" if mel.chaos_possible is None else "the state diverged"
        return Verdict(agreement="undecided", consistent=True, chaotic=chaotic,
                       summary=f"{numerics}; {why}", decided_by=decided_by,
                       decided_attractor=index)  # fmt: skip
    if mel.chaos_possible and chaotic:
        agreement, text = "both_chaotic", "transverse homoclinic tangle and chaotic response"
    elif mel.chaos_possible:
        agreement = "melnikov_only"
        text = "tangle predicted (necessary for chaos) but the attractor is regular"
    elif chaotic:
        agreement = "numerics_only"
        text = "chaos found although first-order Melnikov rules it out (strong perturbation?)"
    else:
        agreement, text = "both_regular", "no tangle and a regular response"
    possible = "possible" if mel.chaos_possible else "not possible"
    return Verdict(
        agreement=agreement,
        consistent=agreement != "numerics_only",
        chaotic=chaotic,
        summary=f"{numerics}; Melnikov: chaos {possible} — {text}",
        decided_by=decided_by,
        decided_attractor=index,
    )


def whose_note(num: NumericsResult, decided: Headline) -> str:
    """The note that says whose the numerics' detailed fields are when basins decide the
    verdict: the settings' own start's, which need not be the deciding attractor's (a periodic
    start beside a chaotic verdict read as the design's answer; issue 30 review, finding 2)."""
    run = f"periodic ({num.period}T)" if num.period else num.classification.replace("_", "-")
    other = "another attractor's" if decided.kind != run else "the worst attractor's"
    return (f"numerics.classification, period, lle, impact_regime, worst_case, floquet, spectrum, "
            f"poincare and time_history are the settings' own start's answer ({run}), not the "
            f"design's verdict; the verdict is {other} above basins.min_fraction: "
            f"{decided.decided_by} (verdict.decided_by)")  # fmt: skip


def decision(num: NumericsResult, settings: SimulationSettings) -> Headline | None:
    """The worst attractor above ``settings.basins.min_fraction`` that decides the verdict
    (``numerics.headline.headline``); None without basins."""
    if num.attractors is None or num.basins is None or settings.basins is None:
        return None
    return headline(num.attractors, num.basins, settings.basins.min_fraction)


def analyze(
    request: AnalysisRequest | Design | GearParams, settings: SimulationSettings | None = None
) -> AnalysisResult:
    """Melnikov and numerical verdicts of one design (with a design, in its units too).

    ``request`` is a whole request, or (the facade's short form) a ``Design`` in physical units
    or dimensionless ``GearParams``, integrated with ``settings`` (default: the defaults of
    ``SimulationSettings``); ``settings`` with a whole request is refused (it has its own).
    One pipeline for the request's system: its Melnikov answer (the pair's, or a train's
    reduction, ``train_answer``), its numerics (with ``settings.basins`` its attractors and
    the worst one's headline, computed once), the verdict, and with a design the engineering
    block from the values handed to it (a train's with its modes).
    """
    if not isinstance(request, AnalysisRequest):
        key = "design" if isinstance(request, Design) else "params"
        request = AnalysisRequest(**{key: request}, settings=settings or SimulationSettings())
    elif settings is not None:
        raise TypeError("analyze: an AnalysisRequest carries its settings; give one or the other")
    system, settings = request.system, request.settings
    train = system if isinstance(system, TrainSystem) else None
    if train is None:
        mel, conv, no_windows = melnikov(system), request.conversion, None
    else:
        mel, conv, no_windows = train_answer(train)
    scan = None
    if conv is not None:  # the speed windows right after the verdict, handed to engineering
        speeds = request.speed_rpm_range()
        scan = design_windows(conv.params, conv.speed_rpm, speeds, mel, no_windows is None)
    num = simulate(system, settings)
    if conv is not None and train is None:  # the pair's run lengths in seconds too
        ts = conv.time_scale_s
        num = num.model_copy(update={"transient": in_seconds(num.transient, ts),
                                     "record": in_seconds(num.record, ts)})  # fmt: skip
    decided, worst, runs = None, None, None
    if settings.basins is not None:  # the worst attractor above min_fraction decides
        scales = None if conv is None else conv.scales
        found, counts = planned_attractors(system, settings, request.plan, scales)
        num = num.model_copy(update={"attractors": found, "basins": counts})
        decided = headline(found, counts, settings.basins.min_fraction)
        worst = most_adverse(found, decided, settings.basins.min_fraction)  # each magnitude's
        if worst and conv is not None and train is None:  # runs for those read from a history
            runs = attractor_runs(system, settings, found, settings.basins.min_fraction)
        if decided is not None:
            num = num.model_copy(update={"notes": [*num.notes, whose_note(num, decided)]})
    result = AnalysisResult(melnikov=mel, numerics=num, settings=settings,
                            verdict=verdict(mel, num, decided))  # fmt: skip
    if conv is None:
        return result
    eng = engineering(
        conv, speeds, mel, scan, num, decided, no_windows, worst, request.design, runs
    )
    if train is None:
        return result.model_copy(update={"params": conv.params, "engineering": eng})
    notes = [f"gear train: {train.model.size} coordinates; numerics of the train, scales of "
             "its equivalent pair (I_a = I_m + I_p, I_b = I_g + I_l)"]  # fmt: skip
    found_modes = modes(train.model, conv.natural_frequency_hz)
    eng = eng.model_copy(update={"notes": [*eng.notes, *notes], "modes": found_modes})
    return result.model_copy(update={"params": train.params, "engineering": eng})


def train_answer(system: TrainSystem) -> tuple[MelnikovResult, DesignConversion, str | None]:
    """A train's Melnikov answer (that of its mesh-mode reduction, or not applicable with the
    reason, ``homoclinic.train_reduction``), the conversion its engineering block uses (the
    scales of its equivalent pair, ``model.equivalent_design``, with the reduction's params),
    and why there are no Melnikov speed windows (None with a reduction: the windows are the
    reduction's, its frequencies scale with the speed like the pair's)."""
    pair = system.conversion
    reduced = train_melnikov(system)
    if reduced.applicable:
        assert reduced.melnikov is not None and reduced.params is not None
        mel = reduced.melnikov.model_copy(
            update={"notes": [reduced.reason, reduced.reduction, *reduced.melnikov.notes]}
        )
        return mel, pair.model_copy(update={"params": reduced.params}), None
    a, c, _ = melnikov_cubic(system.params.backlash)
    # no critical load either: the equivalent pair's F_crit judges no train without a
    # reduction (its T_crit read "the criterion applies below it")
    mel = not_applicable(a, c, "closed_form", [reduced.reason]).model_copy(
        update={"critical_mean_force": None}
    )
    return mel, pair, "no Melnikov reduction: " + reduced.reason


def answer_melnikov(request: MelnikovRequest) -> MelnikovResult:
    """The Melnikov verdict of a request; with a design, its params and engineering block."""
    mel = melnikov(request.params, method=request.method, mean_load=request.mean_load)
    conv = request.conversion
    if conv is None:
        return mel
    speeds = request.speed_rpm_range()
    scan = design_windows(conv.params, conv.speed_rpm, speeds, mel)
    eng = engineering(conv, speeds, mel, scan, design=request.design)
    return MelnikovAnswer(**dict(mel), params=conv.params, engineering=eng)


class DesignRequest(ParamsOrDesign):
    """``{"design": {...}}``: the design's conversion and its engineering block."""

    model_config = request_config({"design": EXAMPLE_DESIGN})
    TRAINS = True  # the pair's conversion; a train's own answers are in analyses

    ONE_OF = ("design",)  # a conversion needs a design: its schema asks for one


class DesignReport(BaseModel):
    """The /v1/conversions/design contract: Eq. (9)'s parameters of a design, what was derived
    from it, and the Melnikov answer in its units."""

    model_config = ConfigDict(frozen=True)

    conversion: DesignConversion
    engineering: Engineering


def convert(request: DesignRequest) -> DesignReport:
    """The conversion of a design with its engineering block (Melnikov windows, thresholds)."""
    conv = request.conversion
    if conv is None:
        raise InputError("design", "give a design (physical units) to convert")
    mel = melnikov(conv.params)
    speeds = request.speed_rpm_range()
    scan = design_windows(conv.params, conv.speed_rpm, speeds, mel)
    eng = engineering(conv, speeds, mel, scan, design=request.design)
    return DesignReport(conversion=conv, engineering=eng)
