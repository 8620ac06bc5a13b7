r"""Linear time-invariant building blocks.

State-space models from second-order mechanical models, linear fractional
transformations (LFTs), the Redheffer star product, frequency responses and
the H-infinity norm.  Everything works on :class:`control.StateSpace`
(continuous time) and returns :class:`control.StateSpace`; python-control is
the container, the algorithms here are our own.

The package keeps one idea per module: ``_ss`` (construction and checks:
:func:`ss`, :func:`as_ss`, :func:`check_finite`, :func:`is_real_number`,
:func:`blas_single_thread`), ``_mck`` (:func:`mck_to_ss`, second-order models
with named ports), ``_interconnect`` (:func:`star`, :func:`lft_lower`,
:func:`lft_upper`, :func:`lft_matrix`), ``_freqresp`` (:func:`freqresp`,
:func:`sigma_max`), ``_stability`` (the scale-aware axis rule,
:func:`balance_states`, :func:`stability`, :func:`is_stable`,
:func:`closed_loop_poles`) and ``_hinf`` (:func:`hinf_norm`).  Each imports
only those before it in this list.

References
----------
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996 (LFTs: ch. 10; star product: sec. 10.3).
.. [BS] N. A. Bruinsma and M. Steinbuch, "A fast algorithm to compute the
   H-infinity norm of a transfer function matrix", *Systems & Control
   Letters* 14 (1990) 287-293.
.. [BBK] S. Boyd, V. Balakrishnan and P. Kabamba, "A bisection method for
   computing the H-infinity norm of a transfer matrix and related problems",
   *Math. Control Signals Systems* 2 (1989) 207-219.
"""
from __future__ import annotations

from ._freqresp import freqresp, sigma_max
from ._hinf import HinfNorm, hinf_norm
from ._interconnect import lft_lower, lft_matrix, lft_upper, star
from ._mck import mck_to_ss
from ._ss import as_ss, blas_single_thread, check_finite, is_real_number, ss
from ._stability import Stability, balance_states, closed_loop_poles, is_stable, stability

# private names other modules reach for (mutext.uncertain builds its ports with the same rule)
from ._mck import _port_vector  # noqa: F401
from ._stability import _axis_poles  # noqa: F401

__all__ = [
    "ss", "as_ss", "check_finite", "mck_to_ss", "star", "lft_lower", "lft_upper",
    "lft_matrix", "freqresp", "sigma_max", "hinf_norm", "HinfNorm",
    "balance_states", "is_stable", "stability", "Stability", "closed_loop_poles", "is_real_number",
]
