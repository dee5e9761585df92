"""Basins as a durable job (kind ``basins``): one design's coexisting attractors and the basin
fractions of its starts, the answer of ``gearengine basins FILE --json``, for requests too big
for the synchronous budget of ``POST /v1/analyses``.

The request is an analysis request; without ``settings.basins`` the default basin settings
(16 starts) are used, as ``POST /v1/analyses/basins/plot`` does. The whole analysis is one
chunk (progress counts its starts): the attractors are found by clustering the orbits of all
starts together (``numerics.attractors``), so the chunk is the analysis ``analyze`` computes,
and its result is the CLI's document byte for byte.
"""

from __future__ import annotations

from gearengine.analysis import AnalysisRequest, AnalysisResult, analyze
from gearengine.numerics.settings import BasinSettings
from gearengine.studies.jobs import one_chunk_kind


def with_basins(request: AnalysisRequest) -> AnalysisRequest:
    """``request`` with its basin settings, the defaults when it has none."""
    if request.settings.basins is not None:
        return request
    settings = request.settings.model_copy(update={"basins": BasinSettings()})
    return request.model_copy(update={"settings": settings})


def basins_work(request: AnalysisRequest) -> int:
    """RK4 steps of the analysis with its basin starts (``AnalysisRequest.work``; a train's
    at its ``System.step_cost``)."""
    return with_basins(request).work


BASINS_JOB = one_chunk_kind(
    "basins",
    AnalysisRequest,
    AnalysisResult,
    units=lambda request: with_basins(request).settings.basins.starts,
    work=basins_work,
    compute=lambda request: analyze(with_basins(request)),
)
