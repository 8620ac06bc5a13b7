"""Seeded random generalized plants for testing and benchmarking H-infinity synthesis.

The plants satisfy the assumptions of the Riccati (Glover-Doyle) method, so
slycot's ``sb10ad`` can serve as a reference: ``(A, B2)`` stabilizable,
``(C2, A)`` detectable, ``D12`` full column rank, ``D21`` full row rank
(generic random matrices with ``nz >= nu`` and ``nw >= ny``).  They mix
stable and unstable open loops and are deliberately badly scaled: random
diagonal state similarity (up to 10^+/-2), time scaling (10^+/-2) and
channel scaling of ``u`` and ``y``.
"""
from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np

from ..lti import ss

__all__ = ["RandomPlant", "random_plant", "random_plants"]


@dataclass
class RandomPlant:
    """A reproducible random H-infinity problem (:func:`random_plant`).

    Attributes
    ----------
    P : control.StateSpace
        The generalized plant.
    nmeas, ncon : int
        Numbers of measurements and controls (the last outputs and inputs of ``P``).
    seed : int
        Seed it was drawn with.
    open_loop_stable : bool
        Whether ``A`` is stable.
    description : str
        Sizes and properties in words.
    """
    P: ct.StateSpace
    nmeas: int
    ncon: int
    seed: int
    open_loop_stable: bool
    description: str


def random_plant(seed: int, n: int | None = None) -> RandomPlant:
    """One reproducible random plant (order 2-12 unless ``n`` is given).

    Parameters
    ----------
    seed : int
        Seed of the random generator.
    n : int, optional
        Number of states (default: drawn from 2-12).

    Examples
    --------
    >>> from mutext.examples.random_plants import random_plant
    >>> a, b = random_plant(7), random_plant(7)
    >>> bool((a.P.A == b.P.A).all()), random_plant(7, n=3).P.nstates
    (True, 3)
    """
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 13)) if n is None else int(n)
    nu = int(rng.integers(1, 3))
    ny = int(rng.integers(1, 3))
    nz = nu + int(rng.integers(0, 2))
    nw = ny + int(rng.integers(0, 2))
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    stable = bool(rng.random() < 0.5)
    ev = np.linalg.eigvals(A)
    if stable:
        A -= (ev.real.max() + 0.2 + rng.random()) * np.eye(n)
    elif ev.real.max() <= 0:
        A += (0.2 - ev.real.max()) * np.eye(n)
    B1 = rng.standard_normal((n, nw))
    B2 = rng.standard_normal((n, nu))
    C1 = rng.standard_normal((nz, n))
    C2 = rng.standard_normal((ny, n))
    D11 = 0.3 * rng.standard_normal((nz, nw)) if rng.random() < 0.5 else np.zeros((nz, nw))
    D12 = rng.standard_normal((nz, nu))
    D21 = rng.standard_normal((ny, nw))
    D22 = 0.2 * rng.standard_normal((ny, nu)) if rng.random() < 0.2 else np.zeros((ny, nu))
    # bad scaling: time scale, state similarity, u and y units
    alpha = 10.0 ** rng.uniform(-2, 2)
    A, B1, B2 = alpha * A, alpha * B1, alpha * B2
    t = 10.0 ** rng.uniform(-2, 2, n)
    A = (A * t[None, :]) / t[:, None]
    B1, B2 = B1 / t[:, None], B2 / t[:, None]
    C1, C2 = C1 * t[None, :], C2 * t[None, :]
    su = 10.0 ** rng.uniform(-2, 2, nu)
    sy = 10.0 ** rng.uniform(-2, 2, ny)
    B2, D12, D22 = B2 * su, D12 * su, D22 * su
    C2, D21, D22 = C2 * sy[:, None], D21 * sy[:, None], D22 * sy[:, None]
    P = ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]), np.block([[D11, D12], [D21, D22]]))
    desc = (f"n={n} nw={nw} nu={nu} nz={nz} ny={ny} {'stable' if stable else 'unstable'} "
            f"time-scale={alpha:.2g}{' D22' if np.any(D22) else ''}")
    return RandomPlant(P, ny, nu, seed, stable, desc)


def random_plants(count: int = 100, first_seed: int = 0):
    """``count`` plants with seeds ``first_seed, first_seed + 1, ...``.

    Parameters
    ----------
    count : int, optional
        Number of plants.
    first_seed : int, optional
        Seed of the first.
    """
    return [random_plant(s) for s in range(first_seed, first_seed + count)]
