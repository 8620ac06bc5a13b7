"""Matplotlib on demand: pyplot, decibels and saving a figure (shared by :mod:`mutext.plots` and
:mod:`mutext.report`, so neither needs the other)."""
from __future__ import annotations

import os

import numpy as np


def pyplot():
    """``matplotlib.pyplot``, imported on first use (it falls back to Agg without a display)."""
    import matplotlib.pyplot as plt
    return plt


def db(x):
    """``20 log10 |x|``, with zero mapped to about -6000 dB instead of -inf."""
    return 20.0 * np.log10(np.maximum(np.abs(x), 1e-300))


def save(fig, outdir, name) -> str:
    """Save ``fig`` as ``outdir/name`` (PNG, tight layout), close it and return the path."""
    fig.tight_layout()
    path = os.path.join(outdir, name)
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return path
