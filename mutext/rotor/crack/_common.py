"""The crack package's shared pieces: the cracked rig's constants and the input checks.

The checks work the same on floats, numpy arrays and CasADi expressions
(a symbolic depth ratio passes unchecked; a numeric one must be finite and
in range).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ...errors import ModelError

#: Largest depth ratio a/D for which the strip integration is used ([Pap04]_).
MAX_DEPTH_RATIO = 0.5

#: Cracked rig of [Mad]_ ch. 4: shaft diameter 0.625 in, in metres.
RIG_SHAFT_DIAMETER = 0.625 * 0.0254
#: Crack depth of the rig: 40 % of the diameter ([Mad]_ sec. 4.2).
RIG_CRACK_DEPTH_RATIO = 0.4
#: Station of the crack in the thesis station table (1-based, as in the thesis).
RIG_CRACK_STATION = 15
#: Young's modulus of the station tables, 30 Mpsi, in Pa.
RIG_YOUNGS_MODULUS = 30e6 * 6894.757293168361


# ----------------------------------------------------------------------------
# helpers: the same code works on floats, numpy arrays and CasADi expressions
# ----------------------------------------------------------------------------

def _symbolic(*xs) -> bool:
    return any(isinstance(x, (ca.SX, ca.MX)) for x in xs)


def _scalar(x, name: str):
    """Float for numeric input (DM and 1x1 arrays included), unchanged for SX/MX."""
    if isinstance(x, (ca.SX, ca.MX)):
        if x.numel() != 1:
            raise ModelError(f"{name} must be a scalar expression, got shape {x.shape}")
        return x
    try:
        v = float(np.asarray(x, dtype=float).reshape(()))
    except (TypeError, ValueError):
        raise ModelError(f"{name} must be a real scalar (or a CasADi scalar), got {x!r}") from None
    if not np.isfinite(v):
        raise ModelError(f"{name} must be finite, got {v}")
    return v


def _positive(x, name: str, unit: str):
    x = _scalar(x, name)
    if not _symbolic(x) and x <= 0:
        raise ModelError(f"{name} must be positive [{unit}], got {x}")
    return x


def _depth(depth_ratio):
    d = _scalar(depth_ratio, "depth_ratio")
    if not _symbolic(d) and not 0.0 <= d <= MAX_DEPTH_RATIO:
        raise ModelError(f"depth_ratio a/D must lie in [0, {MAX_DEPTH_RATIO}] (crack depth over "
                         f"shaft diameter; the fracture-mechanics strip model is not valid beyond "
                         f"half the diameter), got {d}")
    return d


def _matrix(rows):
    """Matrix from nested lists of floats or CasADi scalars."""
    flat = [e for r in rows for e in r]
    if _symbolic(*flat):
        return ca.vertcat(*[ca.horzcat(*r) for r in rows])
    return np.array(rows, dtype=float)
