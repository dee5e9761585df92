"""Bounded LRU of response bodies keyed by the canonical request, with strong ETags.

The key is sha256(route + canonical JSON of the validated request): the same design asked twice,
whatever its whitespace or key order, is the same entry, and results are deterministic, so the
ETag of a request is known before any compute and If-None-Match can answer 304 at once.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict


def etag_for(route: str, canonical: str) -> str:
    """Strong ETag of a canonical request on a route."""
    return '"' + hashlib.sha256(f"{route}\n{canonical}".encode()).hexdigest()[:40] + '"'


class ResponseCache:
    """Thread-safe LRU: ETag -> (body, media type)."""

    def __init__(self, capacity: int) -> None:
        self.capacity = capacity
        self._items: OrderedDict[str, tuple[bytes, str]] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: str) -> tuple[bytes, str] | None:
        with self._lock:
            item = self._items.get(key)
            if item is not None:
                self._items.move_to_end(key)
            return item

    def put(self, key: str, body: bytes, media_type: str) -> None:
        if self.capacity <= 0:
            return
        with self._lock:
            self._items[key] = (body, media_type)
            self._items.move_to_end(key)
            while len(self._items) > self.capacity:
                self._items.popitem(last=False)

    def __len__(self) -> int:
        return len(self._items)
