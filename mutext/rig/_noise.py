r"""Measurement noise of the virtual rig: circular complex Gaussian, relative to :math:`|G|` plus a floor."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..errors import ModelError


@dataclass(frozen=True)
class Noise:
    r"""Measurement noise of the virtual rig.

    At each frequency the measured response is

    .. math::
        \hat G(j\omega) = G(j\omega) + \sigma(\omega)\,\frac{n_r + j n_i}{\sqrt2},
        \qquad \sigma = \text{relative}\cdot|G(j\omega)| + \text{floor},

    with :math:`n_r, n_i` independent standard normal, i.e. circular complex
    Gaussian noise with :math:`E|\hat G - G|^2 = \sigma^2` ([Pin]_).  The
    relative part models the gain/phase scatter of the sine-sweep
    correlation, the floor the sensor noise that dominates away from the
    resonances (the reason for truncating the thesis sweeps at 225 Hz).

    Attributes
    ----------
    relative : float
        Standard deviation relative to :math:`|G|` [-], e.g. 0.01 for 1 %.
    floor : float
        Absolute standard deviation in SI response units (m/N or m/A).
    """
    relative: float = 0.0
    floor: float = 0.0

    def __post_init__(self):
        for name in ("relative", "floor"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ModelError(f"Noise.{name} must be finite and >= 0, got {v}")


def _as_noise(noise) -> Noise | None:
    if noise is None:
        return None
    if isinstance(noise, Noise):
        return noise
    if isinstance(noise, (int, float)):
        return Noise(relative=float(noise))
    if isinstance(noise, (tuple, list)) and len(noise) == 2:
        return Noise(relative=float(noise[0]), floor=float(noise[1]))
    if isinstance(noise, Mapping):
        return Noise(**noise)
    raise ModelError(f"noise must be None, a Noise, a relative level (float) or a pair "
                     f"(relative, floor); got {noise!r}")



def _active(nz: Noise | None) -> bool:
    """Whether ``nz`` (from :func:`_as_noise`) adds any noise."""
    return nz is not None and (nz.relative > 0 or nz.floor > 0)


def _generator(rng) -> np.random.Generator:
    """``rng`` if it is a generator, else a generator seeded with it (None: fresh entropy)."""
    return rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)


def _noisy(G: np.ndarray, sigma, gen: np.random.Generator) -> np.ndarray:
    """``G`` plus circular complex Gaussian noise of standard deviation ``sigma`` (:class:`Noise`), drawn from
    ``gen`` (the real parts first, then the imaginary parts)."""
    return G + sigma * (gen.standard_normal(G.size) + 1j * gen.standard_normal(G.size)) / np.sqrt(2.0)
