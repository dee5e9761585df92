"""Prometheus metrics of one app instance (own registry, so tests can run several apps)."""

from __future__ import annotations

from dataclasses import dataclass, field

from prometheus_client import CollectorRegistry, Counter, Histogram, generate_latest


@dataclass
class Metrics:
    """Request counts and latencies, analyses by classification."""

    registry: CollectorRegistry = field(default_factory=CollectorRegistry)

    def __post_init__(self) -> None:
        self.requests = Counter(
            "gearchaos_requests_total",
            "HTTP requests by route, method and status.",
            ["route", "method", "status"],
            registry=self.registry,
        )
        self.latency = Histogram(
            "gearchaos_request_duration_seconds",
            "HTTP request latency by route.",
            ["route"],
            buckets=(0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30),
            registry=self.registry,
        )
        self.analyses = Counter(
            "gearchaos_analyses_total",
            "Numerical analyses by classification.",
            ["classification"],
            registry=self.registry,
        )
        self.cache_hits = Counter(
            "gearchaos_cache_hits_total", "Responses served from the LRU.", registry=self.registry
        )

    def exposition(self) -> bytes:
        """The text exposition format."""
        return generate_latest(self.registry)
