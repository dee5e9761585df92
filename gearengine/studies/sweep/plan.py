"""The plan of a sweep: its points split into chunks (the unit of work of the job queue), and
its cost in RK4 steps.

Chunk i depends only on (request, i, chunk size), so a chunk computed twice gives the same bytes
and an interrupted sweep resumes exactly.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from gearengine.numerics.runs import work
from gearengine.studies.sweep.request import SweepBranch, SweepRequest

DEFAULT_CHUNK_POINTS = 64
"""Fewest points per chunk of ``balanced_chunk_points`` (and a continuation's default)."""
LARGEST_CHUNK_POINTS = 1024
"""Most points per chunk of ``balanced_chunk_points``."""
CHUNKS_PER_WORKER = 4
"""Chunks per worker that ``balanced_chunk_points`` aims at."""


def balanced_chunk_points(n_points: int, workers: int, smallest: int = DEFAULT_CHUNK_POINTS) -> int:
    """Points per chunk of a sweep of ``n_points`` on ``workers`` workers: about
    ``CHUNKS_PER_WORKER`` chunks each (so the last chunks to finish leave little idle time),
    within [smallest, ``LARGEST_CHUNK_POINTS``].

    A chunk is one call of the lock-step kernel, whose lanes take the chunk's next point as
    soon as theirs stops early (adaptive stopping): small chunks leave lanes idle behind their
    slowest (chaotic) points. On the 100 x 100 chaos map through a warm service, 64-point
    chunks took 3.5 s, 256-point chunks 3.0 s (``benchmarks/bench_map_serve.py``).
    """
    share = math.ceil(n_points / (CHUNKS_PER_WORKER * max(1, workers)))
    return max(smallest, min(LARGEST_CHUNK_POINTS, share))


FREQUENCY_ALIASES = frozenset({"Omega_k", "Omega_e", "Omega_p"})


def moves_frequency_ratios(parameter: str) -> bool:
    """True for an axis that changes the ratios of the excitation frequencies (and so the steps
    per T0): one excitation's frequency, an order or a tooth count. ``speed`` and ``Omega`` scale
    every frequency together and keep the ratios."""
    return parameter in FREQUENCY_ALIASES or parameter.endswith((".order", ".teeth"))


def sweep_work(request: SweepRequest) -> int:
    """RK4 steps of the whole sweep, for the compute budget.

    The steps per T0 depend on how the excitation frequencies line up, so every combination of
    values of the axes that move their ratios is costed; the other axes (amplitudes, damping,
    mean force, running speed) only switch an excitation on or off, so their corners bound them.
    """
    grids = request.grids()
    freq = [k for k, a in enumerate(request.axes) if moves_frequency_ratios(a.parameter)]
    rest = [k for k, a in enumerate(request.axes) if not moves_frequency_ratios(a.parameter)]
    per_combination = request.n_points() // math.prod(request.axes[k].num for k in freq)
    corners = list(itertools.product(*((grids[k][0], grids[k][-1]) for k in rest)))
    names = [a.parameter for a in request.axes]
    total = 0
    for values in itertools.product(*(grids[k] for k in freq)):
        point = {names[k]: v for k, v in zip(freq, values, strict=True)}
        total += per_combination * max(
            work(
                request.point({**point, **{names[k]: v for k, v in zip(rest, c, strict=True)}}),
                request.settings,
            )
            for c in corners
        )
    return total


@dataclass(frozen=True)
class Chunk:
    """A unit of work: grid points in the order computed, and how."""

    index: int
    points: list[tuple[int, ...]]
    """Grid indices (i0, i1?) per point, in computation order."""
    branch: SweepBranch | None
    """With continuation: the branch of this line; None without continuation."""


@dataclass(frozen=True)
class SweepPlan:
    """Deterministic split of a request's points into chunks.

    Without continuation: ``chunk_points`` consecutive grid points per chunk (first axis
    fastest). With continuation: one line along the first axis per chunk, for each value of the
    second axis and each branch (up lines first).
    """

    request: SweepRequest
    chunk_points: int = DEFAULT_CHUNK_POINTS

    def _grid_index(self, k: int) -> tuple[int, ...]:
        """Grid indices (i0, i1?) of the k-th point, first axis fastest."""
        out = []
        for a in self.request.axes:
            k, i = divmod(k, a.num)
            out.append(i)
        return tuple(out)

    def n_chunks(self) -> int:
        """Number of chunks."""
        req = self.request
        if req.continuation:
            lines = req.axes[1].num if len(req.axes) == 2 else 1
            return lines * len(req.branches())
        return math.ceil(req.n_points() / self.chunk_points)

    def chunk(self, index: int) -> Chunk:
        """Chunk ``index`` (0 <= index < n_chunks())."""
        req = self.request
        if not 0 <= index < self.n_chunks():
            raise IndexError(f"chunk {index} out of range 0..{self.n_chunks() - 1}")
        if req.continuation:
            lines = req.axes[1].num if len(req.axes) == 2 else 1
            branch = req.branches()[index // lines]
            rest = () if len(req.axes) == 1 else (index % lines,)
            line = [(i0, *rest) for i0 in range(req.axes[0].num)]
            return Chunk(index, line if branch == "up" else line[::-1], branch)
        lo = index * self.chunk_points
        hi = min(lo + self.chunk_points, req.n_points())
        return Chunk(index, [self._grid_index(k) for k in range(lo, hi)], None)

    def point_counts(self) -> list[int]:
        """Number of points of each chunk."""
        return [len(self.chunk(i).points) for i in range(self.n_chunks())]
