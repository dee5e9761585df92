"""The Melnikov function packed for the compiled kernels: the one door into ``kernels``.

As ``systems.spur_pair.forcing.packed_forcing`` packs the forcing of Eq. (9) for the RK4 kernels,
``packed_terms`` packs what M(tau0) = A + sum_i B_i sin(Omega_i tau0 + phi_i) (Eq. 19) needs:

    terms   shape (5, n): fundamental Omega, harmonic number r, excitation kind, amplitude F_r,
            phase phi_r [rad] of each active harmonic (rows ``kernels.FUNDAMENTAL`` ...)
    system  shape (6,):   mu, a, c, F_m, gcd, lcm (``kernels.MU`` ...)

The per-unit coefficients B_i / F_r are functions of r Omega and of the unperturbed system
(a, c, F_m) alone, so one packed design serves a whole running-speed scan (every frequency
scaled together, ``scan_strength``'s factor). The verdict's strength (``thresholds``), the
Omega_e scan, the batch's closed forms and the chaos map's boundary grid (``grid``) all build
this form and no other.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from gearengine.homoclinic import kernels
from gearengine.model.frequencies import commensurability
from gearengine.model.params import EXCITATIONS, GearParams

Harmonics = list[tuple[float, float]]
"""[(amplitude, phase), ...] of one excitation, harmonic r = 1, 2, ... in order."""


@dataclass(frozen=True)
class PackedTerms:
    """One design's Melnikov function as the kernels take it (see the module docstring)."""

    terms: np.ndarray
    system: np.ndarray

    def strength(self, factor: float = 1.0) -> float:
        """Sign-change strength max_s min(max M_s, -min M_s) with every frequency times
        ``factor`` (``kernels.scan_strength``); NaN when the compiled path must fall back."""
        return float(kernels.scan_strength(factor, 1.0, self.terms, self.system))

    def scan_roots(
        self, omegas: np.ndarray, value: float, xtol: float = 1e-12
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        """``kernels.scan_roots``: critical Omega_e of a running-speed scan over ``omegas``
        (the design's own Omega_e is ``value``), the no-chaos flag of each piece, and ok."""
        return kernels.scan_roots(omegas, xtol, value, self.terms, self.system)


@functools.lru_cache(maxsize=4096)
def _commensurability(frequencies: tuple[float, ...]) -> tuple[float, float]:
    """``commensurability``, remembered (sweeps, grids and scans ask for the same ratios)."""
    return commensurability(list(frequencies))


def system_array(mu: float, a: float, c: float, fm: float, gcd: float, lcm: float) -> np.ndarray:
    """The ``system`` entries in ``kernels``' order."""
    entries = [0.0] * kernels.SYSTEM_SIZE
    for i, v in zip(
        (kernels.MU, kernels.A, kernels.C, kernels.FM, kernels.GCD, kernels.LCM),
        (mu, a, c, fm, gcd, lcm),
        strict=True,
    ):
        entries[i] = v
    return np.array(entries, dtype=float)


def pack(
    excitations: Iterable[tuple[str, float, Harmonics]],
    mu: float,
    a: float,
    c: float,
    fm: float,
    inactive: bool = False,
) -> PackedTerms:
    """The packed form of excitations given as (name, fundamental, harmonics) in the order of
    ``model.params.EXCITATIONS``; harmonics with a zero amplitude are left out, except the first
    harmonic of each excitation with ``inactive`` (as ``melnikov_coefficients``'
    ``include_inactive``: its per-unit coefficient gives the amplitude's threshold).

    Args:
        excitations: (excitation name, fundamental Omega, [(amplitude, phase), ...]).
        mu: damping mu~.
        a, c: the cubic law's coefficients (f_h = -a x + c x^3).
        fm: the mean force F_m in the unperturbed system (0: treated as a perturbation).
        inactive: keep zero-amplitude first harmonics.
    """
    rows = [
        (float(frequency), r, kernels.KIND[name], float(amplitude), float(phase))
        for name, frequency, harmonics in excitations
        for r, (amplitude, phase) in enumerate(harmonics or [(0.0, 0.0)], start=1)
        if amplitude != 0.0 or (inactive and r == 1)
    ]
    terms = np.array(rows, dtype=float).reshape(len(rows), 5).T.copy()
    freqs = terms[kernels.HARMONIC] * terms[kernels.FUNDAMENTAL]
    gcd, lcm = _commensurability(tuple(freqs.tolist()))
    return PackedTerms(terms, system_array(float(mu), a, c, fm, gcd, lcm))


def packed_terms(
    params: GearParams, a: float, c: float, fm: float = 0.0, inactive: bool = False
) -> PackedTerms:
    """The packed form of ``params`` for the cubic law (a, c) and mean load ``fm`` (``pack``)."""
    return pack(
        (
            (name, exc.frequency, [(h.amplitude, h.phase) for h in exc.harmonics])
            for name, exc in params.excitations()
        ),
        params.damping,
        a,
        c,
        fm,
        inactive,
    )


def packed_data(data: dict, a: float, c: float, fm: float = 0.0) -> PackedTerms:
    """``packed_terms`` of the design with dumped (not validated) ``data``."""
    return pack(
        (
            (name, exc["frequency"], [(h["amplitude"], h["phase"]) for h in exc["harmonics"]])
            for name in EXCITATIONS
            if (exc := data.get(name)) is not None
        ),
        data["damping"],
        a,
        c,
        fm,
    )
