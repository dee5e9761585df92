"""What every figure shares: the symbol table of the parameters and the one render path.

Rendering only (matplotlib, Agg): every number drawn comes from a result object of the engine.
"""

from __future__ import annotations

import io
from typing import Literal

import matplotlib

matplotlib.use("Agg")

from matplotlib.figure import Figure

ImageFormat = Literal["png", "svg"]
MEDIA_TYPES: dict[ImageFormat, str] = {"png": "image/png", "svg": "image/svg+xml"}

SYMBOLS = {
    "mu": r"$\tilde{\mu}$",
    "F_m": r"$\tilde{F}_m$",
    "k_p1": r"$\tilde{k}_{p1}$",
    "F_e1": r"$\tilde{F}_{e1}$",
    "F_p1": r"$\tilde{F}_{p1}$",
    "Omega_k": r"$\Omega_k$",
    "Omega_e": r"$\Omega_e$",
    "Omega_p": r"$\Omega_p$",
}
"""Axis labels of the parameter aliases (all dimensionless, the paper's symbols of Eq. 9)."""

LLE_LABEL = r"$\lambda_{\max}$ (per unit $\tau$)"


def symbol(alias: str) -> str:
    """The math symbol of a parameter alias (the alias itself when it has none)."""
    return SYMBOLS.get(alias, alias)


def figure_bytes(fig: Figure, fmt: ImageFormat) -> bytes:
    """Figure to PNG (150 dpi) or SVG bytes; deterministic (no timestamps, fixed hash salt),
    cropped to what is drawn so no title is clipped. Figures are made with ``Figure()``, not
    pyplot (~0.2 s to import, and a registry of open figures to close): nothing to release."""
    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "gearchaos"}):
        metadata = {"Date": None} if fmt == "svg" else {"Software": "gearchaos"}
        fig.savefig(buf, format=fmt, dpi=150, metadata=metadata, bbox_inches="tight")
    return buf.getvalue()
