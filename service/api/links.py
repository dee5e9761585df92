"""OpenAPI links from each job's submit operation to the operations on that job.

Every ``POST /v1/<kind>`` of a durable job answers 202 with the job (``Job.id``); its status,
result, figure and cancel operations live under ``/v1/<kind>/{job_id}``. The links say so in
the document (OpenAPI 3.1 "links": ``job_id`` is ``$response.body#/id``), so a client generator,
and schemathesis' stateful phase, follow a submitted job to the routes that serve it instead of
calling them with made-up ids (404).
"""

from __future__ import annotations

import re
from typing import Any

SUBMITTED = ("201", "202")
"""Responses of a submit operation that carry the new job."""
JOB_PATH = re.compile(r"^(?P<base>/v1/[^{}]+?)/\{job_id\}(?P<rest>/[^{}]*)?$")


def link_name(method: str, rest: str) -> str:
    """'GetJob', 'CancelJob', 'GetResult', 'GetPlot', ...: the link's name from the operation's
    method and the path after ``{job_id}``."""
    if not rest:
        return {"get": "GetJob", "delete": "CancelJob"}.get(method, f"{method.title()}Job")
    words = "".join(w.title() for w in re.split(r"[/_-]+", rest) if w)
    return f"{method.title()}{words}"


def add_job_links(spec: dict[str, Any]) -> dict[str, Any]:
    """``spec`` with a ``links`` object on each job submit response, naming every operation
    on ``/v1/<kind>/{job_id}...`` with ``job_id`` from the response body's ``id``; returned
    for chaining (changed in place)."""
    paths = spec.get("paths", {})
    targets: dict[str, dict[str, str]] = {}
    for path, ops in paths.items():
        match = JOB_PATH.match(path)
        if match is None:
            continue
        for method, op in ops.items():
            if isinstance(op, dict) and "operationId" in op:
                name = link_name(method, match.group("rest") or "")
                targets.setdefault(match.group("base"), {})[name] = op["operationId"]
    for base, named in targets.items():
        post = paths.get(base, {}).get("post")
        if post is None:
            continue
        for code in SUBMITTED:
            response = post.get("responses", {}).get(code)
            if response is None:
                continue
            response["links"] = {
                name: {
                    "operationId": op_id,
                    "parameters": {"job_id": "$response.body#/id"},
                    "description": f"The submitted job ({op_id}).",
                }
                for name, op_id in sorted(named.items())
            }
    return spec
