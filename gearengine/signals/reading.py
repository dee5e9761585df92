"""The reading of a recorded series: periodic, quasi-periodic, chaotic, stochastic, or
undetermined, with the evidence that decided it.

Order of the reading (docs/signals.md):

1. Reference: with a speed or a tach the series is resampled per shaft angle (``orders``) and
   a cycle is a mesh period (teeth known) or a revolution; without, the cycle is the
   fundamental of the line spectrum when every line is one of its harmonics. With a speed
   the spectrum must show the line it implies (the mesh order, or order 1 without teeth),
   else the verdict is ``undetermined`` and says which speed the strongest line implies.
2. Period: the smallest n <= 64 cycles whose synchronous average leaves at most 5 % of the
   variance (``orders.period_of``): ``periodic``.
3. Otherwise the 0-1 test (``zero_one``) on one sample per cycle (the strobes, less their
   average over the n cycles that explain most: a chaotic band hugging a 4T orbit reads as
   its 4-cycle hops otherwise), or without a cycle on the series taken every embedding delay:
   K <= ``K_REGULAR``: ``quasi_periodic`` (bounded, not periodic); K >= ``K_DIFFUSIVE``: the
   strobes diffuse, and the IAAFT surrogate test (``surrogates``) tells deterministic chaos
   (rejected, p <= 0.05, and a positive Rosenstein exponent: ``chaotic``) from linear noise
   (not rejected: ``stochastic``); between the two: ``undetermined``.

The largest Lyapunov exponent (``rosenstein``), the embedding (``embedding``) and the
correlation dimension (nolds.corr_dim) are reported whatever the verdict. Work is bounded
whatever the length: spectrum and averages are O(n log n) on the whole record, the rest runs
on at most ``rosenstein.MAX_POINTS`` decimated points, ``zero_one.MAX_POINTS`` strobes and
``surrogates.MAX_POINTS`` points.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from gearengine.signals import orders
from gearengine.signals.embedding import delay_by_mutual_information, delay_vectors, embed
from gearengine.signals.rosenstein import MAX_POINTS, largest_exponent
from gearengine.signals.schema import (
    EmbeddingReport,
    LyapunovReport,
    Periodicity,
    Record,
    Reference,
    SignalResult,
    Spectrum,
    SpectrumLine,
    SurrogateReport,
    Verdict,
    ZeroOneReport,
)
from gearengine.signals.series import SignalRequest
from gearengine.signals.surrogates import ALPHA, surrogate_test
from gearengine.signals.zero_one import MIN_POINTS, zero_one_test

BAND_FRACTION = 0.5
"""The strobes are read less their n-cycle average when that average explains at least half
of the variance (a chaotic band around a periodic orbit), as they are otherwise."""
K_REGULAR = 0.3
K_DIFFUSIVE = 0.7
DELAY_SAMPLES = 4
"""The analysed series is decimated to about this many samples per embedding delay."""
TRAJECTORY_PERIODS = 8
"""Rosenstein's divergence is followed over this many mean periods."""
SPECTRUM_POINTS = 2048
PATH_POINTS = 2000
STROBES_SHOWN = 512
CORR_DIM_POINTS = 2000
LINES_SHOWN = 8
ATTRACTOR_POINTS = 2000


@dataclass(frozen=True)
class Angle:
    """The analysed series: uniform in shaft angle (or time), and its cycle."""

    y: np.ndarray
    dt: float
    """Mean time between samples, s."""
    per_cycle: int | None
    reference: Reference
    spectrum: Spectrum
    mismatch: str | None


def _pooled(values: np.ndarray, axis: np.ndarray) -> tuple[list[float], list[float]]:
    """Max-pool a spectrum to <= SPECTRUM_POINTS points (lines stay visible)."""
    step = max(1, math.ceil(values.size / SPECTRUM_POINTS))
    n = values.size // step * step
    pooled = values[:n].reshape(-1, step).max(axis=1)
    return axis[:n:step].tolist(), pooled.tolist()


def _label(order: float | None, teeth: int | None, tol: float) -> str:
    if order is None:
        return ""
    if teeth:
        for den in (1, 2, 3, 4, 8):
            k = order * den / teeth
            if abs(k - round(k)) * teeth / den <= tol and round(k) >= 1:
                num = round(k)
                return f"mesh harmonic {num}" if den == 1 else f"{num}/{den} mesh order"
    if abs(order - round(order)) <= tol and round(order) >= 1:
        return f"shaft order {round(order)}"
    return f"order {order:.4g}"


def spectrum_lines(
    amp: np.ndarray, bin_width: float, shaft_hz: float | None, teeth: int | None
) -> list[SpectrumLine]:
    """Lines of an amplitude spectrum whose bins are ``bin_width`` apart (orders when
    ``shaft_hz`` is given, else Hz)."""
    out = []
    for ln in orders.lines(amp, bin_width)[:LINES_SHOWN]:
        order = ln.frequency if shaft_hz else None
        hz = ln.frequency * shaft_hz if shaft_hz else ln.frequency
        label = _label(order, teeth, max(2.0 * bin_width, 0.01)) if shaft_hz else f"{hz:.6g} Hz"
        out.append(SpectrumLine(frequency_hz=hz, order=order, amplitude=ln.amplitude,
                                ratio_db=20.0 * math.log10(ln.ratio), label=label))  # fmt: skip
    return out


def _line_at(amp: np.ndarray, index: float) -> float:
    """Height (ratio) over the local floor of the largest bin within 2 bins of ``index``."""
    k = round(index)
    if not 2 <= k < amp.size - 2:
        return 0.0
    peak = float(amp[k - 2 : k + 3].max())
    lo, hi = max(1, k - orders.FLOOR_BINS), min(amp.size, k + orders.FLOOR_BINS + 1)
    return peak / max(float(np.median(amp[lo:hi])), 1e-300)


def angle_domain(request: SignalRequest) -> Angle:
    """Step 1: the reference, the series per angle (or time), its spectrum and the speed check."""
    sig = request.signal
    x, fs = sig.array, sig.sample_rate
    shaft, teeth = request.shaft_hz, request.mesh_teeth
    if shaft is not None:
        per_rev_cycles = teeth or 1
        per_cycle = max(2, round(fs / (shaft * per_rev_cycles)))
        spr = per_cycle * per_rev_cycles
        tach = None if request.tach is None else request.tach.revolutions()
        y = orders.angle_resample(x, fs, spr, shaft, tach)
        amp = orders.amplitude_spectrum(y)
        revs = y.size / spr
        order_axis = np.arange(amp.size) / revs
        xs, ys = _pooled(amp, order_axis)
        found = spectrum_lines(amp, 1.0 / revs, shaft, teeth)
        source = "tach" if request.tach is not None else "speed"
        mismatch = None
        if _line_at(amp, per_rev_cycles * revs) < orders.LINE_RATIO:
            mismatch = _speed_mismatch(found, shaft, teeth, source)
        reference = Reference(
            source=source, shaft_hz=shaft, shaft_rpm=shaft * 60.0, teeth=teeth,
            mesh_hz=None if teeth is None else shaft * teeth,
            cycle="mesh_period" if teeth else "revolution", cycle_hz=shaft * per_rev_cycles,
            samples_per_cycle=per_cycle, cycles=revs * per_rev_cycles,
        )  # fmt: skip
        spectrum = Spectrum(axis="order", x=xs, amplitude=ys, lines=found)
        return Angle(y, 1.0 / (spr * shaft), per_cycle, reference, spectrum, mismatch)
    amp = orders.amplitude_spectrum(x)
    bin_hz = fs / x.size
    raw = orders.lines(amp, bin_hz)
    f0 = orders.fundamental(raw, bin_hz, sig.duration)
    xs, ys = _pooled(amp, np.arange(amp.size) * bin_hz)
    spectrum = Spectrum(axis="frequency_hz", x=xs, amplitude=ys,
                        lines=spectrum_lines(amp, bin_hz, None, None))  # fmt: skip
    if f0 is None:
        reference = Reference(source="none", shaft_hz=None, shaft_rpm=None, teeth=None,
                              mesh_hz=None, cycle=None, cycle_hz=None, samples_per_cycle=None,
                              cycles=None)  # fmt: skip
        return Angle(x, 1.0 / fs, None, reference, spectrum, None)
    per_cycle = max(2, round(fs / f0))
    y = orders.angle_resample(x, fs, per_cycle, f0)
    reference = Reference(source="spectrum", shaft_hz=None, shaft_rpm=None, teeth=None,
                          mesh_hz=None, cycle="fundamental", cycle_hz=f0,
                          samples_per_cycle=per_cycle, cycles=sig.duration * f0)  # fmt: skip
    return Angle(y, 1.0 / (per_cycle * f0), per_cycle, reference, spectrum, None)


def _speed_mismatch(found: list[SpectrumLine], shaft: float, teeth: int | None, source: str) -> str:
    what = f"the mesh order {teeth}" if teeth else "order 1"
    text = (f"the {source} ({shaft * 60:.6g} rpm) does not match the spectrum: no line at "
            f"{what} ({shaft * (teeth or 1):.6g} Hz)")  # fmt: skip
    if found:
        top = found[0]
        implied = top.frequency_hz / (teeth or 1) * 60.0
        text += (f"; the strongest line is at {top.frequency_hz:.6g} Hz, which is {what} at "
                 f"{implied:.6g} rpm")  # fmt: skip
    return text


def mean_period(y: np.ndarray, dt: float) -> float:
    """1 / power-weighted mean frequency of y, s (Rosenstein et al. 1993: the mean period)."""
    power = np.abs(np.fft.rfft(y - y.mean())) ** 2
    f = np.fft.rfftfreq(y.size, dt)
    centroid = float(np.sum(f[1:] * power[1:]) / max(np.sum(power[1:]), 1e-300))
    return 1.0 / centroid if centroid > 0.0 else y.size * dt


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def read(request: SignalRequest) -> SignalResult:
    """The reading of ``request``'s series (see the module's steps)."""
    sig = request.signal
    x = sig.array
    notes: list[str] = []
    record = Record(samples=x.size, sample_rate_hz=sig.sample_rate, duration_s=sig.duration,
                    quantity=sig.quantity, unit=sig.unit, rms=float(np.std(x)),
                    peak_to_peak=float(np.ptp(x)))  # fmt: skip
    if request.speed is None and request.tach is None and request.design is not None:
        notes.append(f"speed from the design: {request.shaft_hz * 60.0:.6g} rpm")
    ang = angle_domain(request)
    ref = ang.reference
    periodicity = None
    if ang.per_cycle is not None:
        u = orders.synchronous_residuals(ang.y, ang.per_cycle, orders.MAX_PERIOD)
        noise = orders.noise_share(ang.y)
        bound = orders.periodic_bound(u, noise)
        n = orders.period_of(u, bound)
        cycle_s = 1.0 / ref.cycle_hz if ref.cycle_hz else None
        per_rev = (ref.teeth or 1) if ref.shaft_hz else None
        periodicity = Periodicity(
            cycles=n, seconds=None if n is None or cycle_s is None else n * cycle_s,
            revolutions=None if n is None or per_rev is None else n / per_rev,
            unexplained=u, threshold=bound, noise_share=noise,
        )  # fmt: skip
    # embedding on the series decimated to ~DELAY_SAMPLES samples per delay; a delay of at
    # most a quarter cycle (the mutual information of a chaotic gear response has its first
    # minimum beyond a whole mesh period, where the slow drifts of the response dominate)
    delay0, _, _ = delay_by_mutual_information(ang.y)
    if ang.per_cycle is not None:
        delay0 = min(delay0, max(1, ang.per_cycle // 4))
    q = max(1, delay0 // DELAY_SAMPLES)
    z = np.ascontiguousarray(ang.y[::q][-MAX_POINTS:])
    dz = ang.dt * q
    emb = embed(z, None if ang.per_cycle is None else max(1, ang.per_cycle // (4 * q)))
    embedding = EmbeddingReport(
        delay_samples=emb.delay, delay_s=emb.delay * dz, dimension=emb.dimension,
        delay_rule=emb.delay_rule, decimation=q, sample_interval_s=dz,
        mutual_information=emb.mutual_information, false_neighbours=emb.false_neighbours,
        attractor=delay_vectors(z, 3, emb.delay)[-ATTRACTOR_POINTS:].tolist(),
    )  # fmt: skip
    strobes = np.empty(0)
    if ang.per_cycle is not None:
        series = strobes = orders.strobes(ang.y, ang.per_cycle)
        spacing = ang.per_cycle * ang.dt
        what = f"one sample per {(ref.cycle or 'cycle').replace('_', ' ')}"
        u = [] if periodicity is None or periodicity.cycles else periodicity.unexplained
        if u and min(u) <= BAND_FRACTION:  # a chaotic band around an n-cycle orbit
            best = int(np.argmin(u)) + 1
            series = orders.less_average(strobes, best)
            plural = "s" if best > 1 else ""
            what += f", less its average over {best} {ref.cycle or 'cycle'}{plural}".replace(
                "_", " "
            )
    else:
        series = z[:: emb.delay]
        spacing = emb.delay * dz
        what = "the series every embedding delay"
    zero_one = surrogates = None
    if series.size >= MIN_POINTS:
        zo = zero_one_test(series, request.seed)
        step = max(1, math.ceil(zo.p.size / PATH_POINTS))
        zero_one = ZeroOneReport(
            k=zo.k, k_quartiles=list(zo.k_quartiles), k_range=list(zo.k_range),
            frequencies=zo.frequencies, points=zo.points, series=what, spacing_s=spacing,
            path_c=zo.c_path, p=zo.p[::step].tolist(), q=zo.q[::step].tolist(),
        )  # fmt: skip
        st = surrogate_test(series, max(2, emb.dimension), 1, request.seed)
        surrogates = SurrogateReport(
            statistic=f"nearest-neighbour prediction error, one step ahead, of {what} "
            f"embedded in {max(2, emb.dimension)} dimensions (normalised by its std)",
            value=st.statistic, surrogate_values=st.surrogate_statistics, p_value=st.p_value,
            rejected=st.rejected, alpha=ALPHA, surrogates=st.surrogates, points=st.points,
            method="IAAFT (pyunicorn Surrogates.refined_AAFT_surrogates)",
        )  # fmt: skip
    else:
        notes.append(f"{what}: {series.size} points, the 0-1 and surrogate tests need "
                     f"{MIN_POINTS}")  # fmt: skip
    cycle = None if ang.per_cycle is None else max(1, round(ang.per_cycle / q))
    lyapunov = _lyapunov(z, dz, emb.dimension, emb.delay, cycle, ref, notes)
    verdict, evidence = decide(ang, periodicity, zero_one, surrogates, lyapunov)
    return SignalResult(
        verdict=verdict, summary=summary(verdict, evidence), evidence=evidence, record=record,
        reference=ref, spectrum=ang.spectrum, periodicity=periodicity,
        strobes=strobes[-STROBES_SHOWN:].tolist(),
        embedding=embedding, zero_one=zero_one, lyapunov=lyapunov,
        correlation_dimension=_corr_dim(z, emb.dimension, emb.delay),
        surrogates=surrogates, model=None, notes=notes,
    )  # fmt: skip


def _lyapunov(
    z: np.ndarray,
    dz: float,
    dimension: int,
    delay: int,
    cycle: int | None,
    ref: Reference,
    notes: list[str],
) -> LyapunovReport | None:
    """Rosenstein's exponent of z; neighbours at least a cycle (samples of z) apart, else a
    mean period."""
    tsep = cycle or max(1, round(mean_period(z, dz) / dz))
    span = z.size - (dimension - 1) * delay
    length = min(TRAJECTORY_PERIODS * tsep, span // 4)
    if length < 8 or span - length < 2 * tsep + 2:
        notes.append("too short for Rosenstein's exponent at this embedding")
        return None
    r = largest_exponent(z, dz, dimension, delay, tsep, length)
    lam = _finite(r.exponent)
    curve = r.divergence.curve
    ok = np.isfinite(curve)
    return LyapunovReport(
        per_second=lam,
        per_revolution=None if lam is None or not ref.shaft_hz else lam / ref.shaft_hz,
        per_mesh_period=None if lam is None or not ref.mesh_hz else lam / ref.mesh_hz,
        implementation=r.divergence.implementation, points=r.divergence.points,
        dimension=dimension, delay_s=delay * dz, min_separation_s=tsep * dz,
        fit_range_s=[r.fit_range[0] * dz, (r.fit_range[1] - 1) * dz],
        divergence_t_s=(np.flatnonzero(ok) * dz).tolist(), divergence=curve[ok].tolist(),
    )  # fmt: skip


def _corr_dim(z: np.ndarray, dimension: int, delay: int) -> float | None:
    """nolds.corr_dim of the last CORR_DIM_POINTS points (Grassberger-Procaccia)."""
    import nolds

    data = z[-CORR_DIM_POINTS:]
    if data.size < 10 * (dimension * delay + 1):
        return None
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            value = nolds.corr_dim(data[::delay] if delay > 1 else data, dimension, fit="poly")
        except (ValueError, np.linalg.LinAlgError):
            return None
    return _finite(float(value))


def decide(
    ang: Angle,
    periodicity: Periodicity | None,
    zero_one: ZeroOneReport | None,
    surrogates: SurrogateReport | None,
    lyapunov: LyapunovReport | None,
) -> tuple[Verdict, list[str]]:
    """The verdict and the sentences of evidence that decided it (the module's rules)."""
    ref = ang.reference
    cycle = (ref.cycle or "cycle").replace("_", " ")
    if ang.mismatch is not None:
        return "undetermined", [ang.mismatch]
    evidence = []
    if periodicity is not None and periodicity.cycles is not None:
        n, u = periodicity.cycles, periodicity.unexplained[periodicity.cycles - 1]
        plural = "s" if n > 1 else ""
        evidence.append(f"the average over {n} {cycle}{plural} leaves {100 * u:.2g} % of the "
                        f"variance (periodic at <= {100 * periodicity.threshold:.2g} %; white "
                        f"noise {100 * periodicity.noise_share:.2g} %)")  # fmt: skip
        return "periodic", evidence
    if periodicity is not None and periodicity.unexplained:
        evidence.append(f"no period up to {len(periodicity.unexplained)} {cycle}s: the "
                        f"synchronous averages leave at least "
                        f"{100 * min(periodicity.unexplained):.2g} % of the variance, the "
                        f"noise {100 * periodicity.noise_share:.2g} %")  # fmt: skip
    elif periodicity is None:
        evidence.append("no speed, tach or harmonic line spectrum: no cycle to average over")
    if zero_one is None:
        return "undetermined", [*evidence, "too few points for the 0-1 test"]
    k = zero_one.k
    lo, hi = zero_one.k_quartiles
    evidence.append(f"0-1 test K = {k:.3f} (quartiles {lo:.2f}-{hi:.2f} over "
                    f"{zero_one.frequencies} c) on {zero_one.series}")  # fmt: skip
    if k <= K_REGULAR:
        return "quasi_periodic", [*evidence, "bounded (regular) but not periodic"]
    if k < K_DIFFUSIVE:
        return "undetermined", [*evidence, f"K between {K_REGULAR} and {K_DIFFUSIVE}"]
    assert surrogates is not None
    sur = (f"prediction error {surrogates.value:.3g} against {surrogates.surrogates} IAAFT "
           f"surrogates, p = {surrogates.p_value:.3g}")  # fmt: skip
    lam = None if lyapunov is None else lyapunov.per_second
    if not surrogates.rejected:
        return "stochastic", [*evidence, f"{sur}: not more predictable than linear noise"]
    if lam is not None and lam > 0.0:
        return "chaotic", [*evidence, f"{sur}: deterministic",
                           f"largest Lyapunov exponent {lam:.4g} /s"]  # fmt: skip
    return "undetermined", [*evidence, f"{sur}, but no positive Lyapunov exponent"]


WORDS: dict[str, str] = {
    "periodic": "Periodic",
    "quasi_periodic": "Quasi-periodic",
    "chaotic": "Chaotic",
    "stochastic": "Stochastic (noise-like)",
    "undetermined": "Undetermined",
}


def summary(verdict: str, evidence: list[str]) -> str:
    """One plain sentence: the verdict and its evidence."""
    return f"{WORDS[verdict]}: {'; '.join(evidence)}."
