"""An independent integration of a gear train for the tests: the physical equations in SI units
and seconds, integrated with scipy's DOP853, stopped at the backlash edges (events), from the
design's own numbers (not from the engine's dimensionless form or forcing arrays).

    M q'' + C_s q' + K_s q + w W = (T_m(t), 0, 0, -T_l, 0, 0)
    W = k(t) b f_h(delta / b) + c_m delta',   delta = w . q - e(t)
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from gearengine.model.design import Design
from gearengine.systems.gear_train.model import TrainModel


def harmonics(design: Design) -> tuple[list, list, list, float, float, float]:
    """(stiffness, error, torque) harmonics as (amplitude, r omega [rad/s], phase) in SI, from
    the design's fields, and the half backlash b, mean torque and braking torque."""
    w_a = design.speed
    mesh = design.mesh
    k_terms = [
        (h.amplitude, r * design.driver.teeth * w_a, h.phase)
        for r, h in enumerate(mesh.stiffness_harmonics or [], start=1)
    ]
    te = design.transmission_error
    e_terms = []
    if te is not None:
        order = design.driver.teeth if te.order is None else te.order
        e_terms = [(h.amplitude, r * order * w_a, h.phase) for r, h in enumerate(te.harmonics, 1)]
    tf = design.torque_fluctuation
    t_terms = []
    if tf is not None:
        t_terms = [
            (h.amplitude, r * tf.order * w_a, h.phase) for r, h in enumerate(tf.harmonics, 1)
        ]
    braking = design.torque * design.driven.base_radius / design.driver.base_radius
    return k_terms, e_terms, t_terms, mesh.half_backlash, design.torque, braking


def series(terms: list, t: float) -> tuple[float, float]:
    """sum a cos(w t + p) and its time derivative."""
    value = sum(a * math.cos(w * t + p) for a, w, p in terms)
    rate = -sum(a * w * math.sin(w * t + p) for a, w, p in terms)
    return value, rate


def dop853_delta(
    design: Design,
    model: TrainModel,
    q0: np.ndarray,
    qd0: np.ndarray,
    t_trans: float,
    t_rec: float,
    samples: int,
    law: str = "piecewise",
) -> np.ndarray:
    """delta(t) / b at ``samples`` equally spaced times of [t_trans, t_trans + t_rec] [s] and at
    every backlash-edge event in it; DOP853, rtol 1e-10, on q scaled to O(1)."""
    k_terms, e_terms, t_terms, b, t_m, t_l = harmonics(design)
    w = model.mesh_direction
    minv = np.linalg.inv(model.mass)
    k_s, c_s, k_m, c_m = (model.structure_stiffness, model.structure_damping,
                          model.mesh_stiffness, model.mesh_damping)  # fmt: skip
    n = model.size
    rp, rg = model.radii
    scale = np.array([b / rp, b / rp, b / rg, b / rg, b, b])[:n]  # q / scale ~ x in units of b
    rate_scale = math.sqrt(k_m * 4.0)  # velocity scale (order of the mesh mode)
    scales = np.concatenate([scale, scale * rate_scale])

    def fh(x: float, region: int) -> float:
        """The law of ``region`` (Eq. 8 with alpha = 0, extended past its edges), or the cubic."""
        if law != "piecewise":
            return -x / 6.0 + x**3 / 6.0
        return x - region if region else 0.0

    def rhs(t: float, z: np.ndarray, region: int) -> np.ndarray:
        q, qd = z[:n] * scale, z[n:] * scale * rate_scale
        k = k_m + sum(a * math.cos(om * t + p) for a, om, p in k_terms)
        e, ed = series(e_terms, t)
        torque = t_m + sum(a * math.cos(om * t + p) for a, om, p in t_terms)
        delta, deltad = w @ q - e, w @ qd - ed
        force = np.zeros(n)
        force[0], force[3] = torque, -t_l
        W = k * b * fh(delta / b, region) + c_m * deltad
        acc = minv @ (force - k_s @ q - c_s @ qd - w * W)
        return np.concatenate([qd, acc]) / scales

    def delta_of(t: float, z: np.ndarray) -> float:
        return (w @ (z[:n] * scale) - series(e_terms, t)[0]) / b

    def edge(level: float, direction: float):
        def event(t: float, z: np.ndarray, region: int) -> float:
            return delta_of(t, z) - level

        event.terminal, event.direction = True, direction
        return event

    def side(t: float, z: np.ndarray, region: int, tau: float) -> float:
        """The sign of delta(t + tau) - delta(t) ~ delta' tau + delta'' tau^2 / 2 at an edge: the
        side delta moves to, grazing contacts (delta' ~ 0) included."""
        rate = w @ (z[n:] * scale * rate_scale) - series(e_terms, t)[1]
        acc = w @ (rhs(t, z, region)[n:] * scale * rate_scale) + sum(
            a * om * om * math.cos(om * t + p) for a, om, p in e_terms
        )
        return rate + 0.5 * acc * tau

    leave = {  # the edges a region is left through, crossed in the leaving direction
        1: [edge(1.0, -1.0)],
        -1: [edge(-1.0, 1.0)],
        0: [edge(1.0, 1.0), edge(-1.0, -1.0)],
    }
    t, t_end = 0.0, t_trans + t_rec
    # events are seen as sign changes between steps: no step longer than 1/40 of the fastest
    # forcing period, so that no excursion across an edge and back fits inside one
    max_step = 2.0 * math.pi / max(om for _, om, _ in k_terms + e_terms + t_terms) / 40.0
    z = np.concatenate([q0, qd0]) / scales
    x0 = delta_of(0.0, z)
    region = 0 if law != "piecewise" or abs(x0) <= 1.0 else int(np.sign(x0))
    grid = np.linspace(t_trans, t_end, samples)
    out: list[float] = []
    while True:
        sol = solve_ivp(rhs, (t, t_end), z, method="DOP853", rtol=1e-10, atol=1e-10,
                        args=(region,), events=leave[region] if law == "piecewise" else None,
                        dense_output=True, max_step=max_step)  # fmt: skip
        stop = sol.t[-1]
        inside = grid[(grid >= t) & (grid <= stop)]
        out += [delta_of(tk, sol.sol(tk)) for tk in inside]
        if sol.status != 1:
            return np.array(out)
        t, z = stop, sol.y[:, -1]
        level = round(delta_of(t, z))
        if t >= t_trans:
            out.append(float(level))
        region = (
            level if side(t, z, region, max_step) * level > 0.0 else 0
        )  # the side delta moves to
