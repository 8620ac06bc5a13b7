r"""H-infinity synthesis: Riccati equations and linear matrix inequalities.

Given a generalized plant

.. math::
    P:\quad \dot x = Ax + B_1 w + B_2 u,\quad z = C_1x + D_{11}w + D_{12}u,\quad
    y = C_2x + D_{21}w + D_{22}u,

find a stabilizing controller ``u = K y`` that minimises the H-infinity norm
of the closed loop :math:`w \to z`.

Method
------
1. *Optimal level* (Gahinet and Apkarian [GA]_, Theorem 4.3): a controller with
   closed-loop norm below :math:`\gamma` exists iff there are symmetric
   :math:`R, S` with

   .. math::
       \begin{bmatrix} N_R & 0\\ 0 & I\end{bmatrix}^T
       \begin{bmatrix} AR + RA^T & RC_1^T & B_1\\ C_1R & -\gamma I & D_{11}\\
       B_1^T & D_{11}^T & -\gamma I\end{bmatrix}
       \begin{bmatrix} N_R & 0\\ 0 & I\end{bmatrix} \prec 0,\qquad
       \begin{bmatrix} N_S & 0\\ 0 & I\end{bmatrix}^T
       \begin{bmatrix} A^TS + SA & SB_1 & C_1^T\\ B_1^TS & -\gamma I & D_{11}^T\\
       C_1 & D_{11} & -\gamma I\end{bmatrix}
       \begin{bmatrix} N_S & 0\\ 0 & I\end{bmatrix} \prec 0,\qquad
       \begin{bmatrix} R & I\\ I & S\end{bmatrix} \succeq 0,

   where :math:`N_R` and :math:`N_S` span the null spaces of
   :math:`[B_2^T\ D_{12}^T]` and :math:`[C_2\ D_{21}]`.  These are linear in
   :math:`(R, S, \gamma)`, so the optimal level is a single semidefinite
   program (no bisection).  No rank condition on :math:`D_{12}, D_{21}` is
   needed: singular problems that the Riccati method refuses are handled.
   For *regular* problems (:math:`D_{12}` full column rank, :math:`D_{21}`
   full row rank) the level is found instead by bisection on the exact
   Riccati conditions of Zhou, Doyle and Glover [ZDG]_ Theorem 17.1
   (:func:`riccati_feasible`, the gamma iteration of the Riccati method): two
   Hamiltonian Schur forms per step, about 40 steps to 1e-10, a fraction of a
   second at 40 states where the LMIs take minutes.  The LMIs take over where
   that iteration finds no level, and remain the route for singular problems
   (``method="lmi"`` forces them).
2. *Controller* at a level slightly above the optimum (``backoff``): the
   central controller of Glover and Doyle from the Riccati solutions
   :math:`X_\infty, Y_\infty` (:func:`central_controller`, in descriptor
   form) where they exist at that level; for singular problems the central
   controllers of regularised plants (:math:`\epsilon u` appended to ``z``,
   :math:`\epsilon v` added to ``y``) for decreasing :math:`\epsilon`; and the
   LMI reconstruction from the linearising change of variables of Scherer,
   Gahinet and Chilali [SGC]_, with an objective that keeps :math:`I - XY`
   well conditioned so the controller has no needlessly fast poles.
3. *Independent check* of every candidate: the closed loop is rebuilt from
   ``P`` and ``K``, its stability decided by the scale-aware rule of
   :func:`mutext.lti.stability`, and its norm recomputed by our Hamiltonian
   algorithm (:func:`mutext.lti.hinf_norm`), by SLICOT's ``AB13DD`` (through
   slycot) and on a frequency grid.  The first controller that achieves its
   target level is returned (``HinfResult.construction`` says which).

Numerics: the plant's states are balanced by a diagonal similarity
(powers of two) and the control and measurement channels normalised before
the LMIs are formed; the two-mass plant of the thesis needs this (its
optimal level is off by about 3 % without it).

The package keeps one idea per module: ``_plant`` (partition and assumption
checks), ``_lmi`` (the LMI level and controller), ``_riccati`` (Riccati
solutions, existence conditions, gamma iteration), ``_central`` (the central
controller), ``_level`` (working coordinates and the level by either route),
``_search`` (the controller search over back-offs and constructions),
``_verify`` (the check of every controller and :class:`HinfResult`),
``_slycot`` (slycot's norm and synthesis as references) and ``_synth``
(:func:`hinfsyn`).

References
----------
.. [GA] P. Gahinet and P. Apkarian, "A linear matrix inequality approach to
   H-infinity control", *Int. J. Robust Nonlinear Control* 4 (1994) 421-448.
.. [SGC] C. Scherer, P. Gahinet and M. Chilali, "Multiobjective
   output-feedback control via LMI optimization", *IEEE TAC* 42 (1997) 896-911.
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996, ch. 16-17.
"""
from __future__ import annotations

from ._central import central_controller
from ._level import CENTRAL, CENTRAL_REGULARISED, LMI_CONTROLLER  # noqa: F401  (the construction names)
from ._plant import PlantParts, check_plant
from ._riccati import riccati_feasible
from ._slycot import SlycotReference, slycot_hinf_norm, slycot_hinfsyn
from ._synth import hinfsyn
from ._verify import HinfResult

# a private name the tests reach for
from ._plant import _uncontrollable_modes  # noqa: F401

__all__ = ["hinfsyn", "HinfResult", "check_plant", "PlantParts", "slycot_hinf_norm", "slycot_hinfsyn",
           "SlycotReference", "central_controller", "riccati_feasible"]
