"""Shared dependencies of the routes: settings, the job queue, API-key auth (``Owner``) and
cached computation. The typed aliases (``Owner``, ``AppSettings``, ``Jobs``, ``AppLimits``,
``AppMetrics``, ``ReadyChecks``) are what routes declare; no route reads ``app.state``."""

from __future__ import annotations

import hashlib
import hmac
import re
import time
from collections.abc import Callable
from pathlib import Path
from typing import Annotated

from fastapi import Depends, Request, Response
from pydantic import ValidationError
from starlette.concurrency import run_in_threadpool

from service.cache import ResponseCache, etag_for
from service.core.config import Settings
from service.errors import ProblemError, engine_refusal
from service.jobs.runtime import JobQueue
from service.limits import Limits
from service.metrics import Metrics

KEYS_FILE = "api_keys.sha256"
"""File in the data directory: one sha256 hex digest of an API key per line (# comments)."""


def key_id(key: str) -> str:
    """Short, non-secret identifier of a key (first 12 hex digits of its sha256)."""
    return hashlib.sha256(key.encode()).hexdigest()[:12]


def load_key_hashes(settings: Settings) -> dict[str, str]:
    """sha256 digest -> key id, from GEARCHAOS_API_KEYS and the data directory's keys file.

    Raises ValueError naming the line when the keys file holds anything but 64-hex digests
    (a typo must not silently leave a key out, or turn auth off).
    """
    digests = {hashlib.sha256(k.encode()).hexdigest() for k in settings.key_list}
    path = Path(settings.data_dir) / KEYS_FILE
    if path.exists():
        for n, line in enumerate(path.read_text().splitlines(), start=1):
            word = line.split("#", 1)[0].strip().lower()
            if not word:
                continue
            if not re.fullmatch(r"[0-9a-f]{64}", word):
                raise ValueError(
                    f"{path}:{n}: not a sha256 hex digest (make one with: printf %s KEY | "
                    "sha256sum)"
                )
            digests.add(word)
    return {d: d[:12] for d in digests}


def presented_key(request: Request) -> str | None:
    auth = request.headers.get("authorization", "")
    if auth.lower().startswith("bearer "):
        return auth[7:].strip()
    return request.headers.get("x-api-key")


async def require_key(request: Request) -> str | None:
    """The caller's key id, or None when auth is off. Raises 401 problem+json otherwise.

    A coroutine, though it awaits nothing: FastAPI runs a plain function dependency in a worker
    thread, and the hop there and back cost 0.1 ms of every request (a third of a Melnikov
    verdict's)."""
    hashes: dict[str, str] = request.app.state.key_hashes
    if not hashes:
        return None
    key = presented_key(request)
    if key:
        digest = hashlib.sha256(key.encode()).hexdigest()
        for known, kid in hashes.items():
            if hmac.compare_digest(digest, known):
                request.scope.setdefault("state", {})["key_id"] = kid
                return kid
    raise ProblemError(
        401,
        "unauthorized",
        "Unauthorized",
        "a valid API key is required: send 'Authorization: Bearer KEY' or 'X-API-Key: KEY'"
        if not key
        else "the API key is not valid",
        headers={"WWW-Authenticate": "Bearer"},
    )


Owner = Annotated[str | None, Depends(require_key)]
"""The caller's key id (None with auth off); 401 problem+json without a valid key."""


def app_settings(request: Request) -> Settings:
    """The settings the app was built with."""
    return request.app.state.settings


def job_queue(request: Request) -> JobQueue:
    """The app's job store and dispatcher."""
    return request.app.state.jobs


def app_limits(request: Request) -> Limits:
    """The app's compute budgets."""
    return request.app.state.limits


def app_metrics(request: Request) -> Metrics:
    """The app's Prometheus metrics."""
    return request.app.state.metrics


def response_cache(request: Request) -> ResponseCache:
    """The app's LRU of computed responses."""
    return request.app.state.cache


def ready_checks(request: Request) -> dict[str, Callable[[], bool]]:
    """The readiness checks by name (kernels warmed, job store reachable, ...)."""
    return request.app.state.ready_checks


AppSettings = Annotated[Settings, Depends(app_settings)]
Jobs = Annotated[JobQueue, Depends(job_queue)]
AppLimits = Annotated[Limits, Depends(app_limits)]
AppMetrics = Annotated[Metrics, Depends(app_metrics)]
ReadyChecks = Annotated[dict[str, Callable[[], bool]], Depends(ready_checks)]


async def cached_compute(
    request: Request,
    route: str,
    canonical: str,
    compute: Callable[[], tuple[bytes, str]],
    on_fresh: Callable[[bytes], None] | None = None,
    inline: bool = False,
) -> Response:
    """Answer from the LRU or run ``compute`` off the event loop; ETag and If-None-Match.

    ``compute`` returns (body, media type); it runs in a worker thread (kernels release the GIL),
    or with ``inline`` on the event loop: for work shorter than the hop to a thread and back
    (0.1 ms or more), such as a one-harmonic Melnikov verdict.
    """
    cache = response_cache(request)
    tag = etag_for(route, canonical)
    headers = {"ETag": tag, "Cache-Control": "no-cache"}
    if tag in _if_none_match(request):
        return Response(status_code=304, headers=headers)
    hit = cache.get(tag)
    if hit is not None:
        app_metrics(request).cache_hits.inc()
        body, media_type = hit
        return Response(body, media_type=media_type, headers={**headers, "X-Cache": "hit"})
    start = time.perf_counter()
    try:
        body, media_type = compute() if inline else await run_in_threadpool(compute)
    except ValueError as exc:
        if isinstance(exc, ValidationError):
            raise
        raise engine_refusal(exc) from None
    elapsed = 1e3 * (time.perf_counter() - start)
    cache.put(tag, body, media_type)
    if on_fresh is not None:
        on_fresh(body)
    headers |= {"X-Cache": "miss", "Server-Timing": f"compute;dur={elapsed:.3f}"}
    return Response(body, media_type=media_type, headers=headers)


def _if_none_match(request: Request) -> set[str]:
    value = request.headers.get("if-none-match", "")
    return {t.strip().removeprefix("W/") for t in value.split(",") if t.strip()}
