r"""The structured singular value :math:`\mu`: block structures, bounds and frequency sweeps.

For a complex matrix :math:`M` and a set :math:`\boldsymbol\Delta` of
block-diagonal perturbations,

.. math::
    \mu_{\boldsymbol\Delta}(M) = \Big(\min\{\bar\sigma(\Delta) : \Delta\in\boldsymbol\Delta,\
    \det(I - M\Delta) = 0\}\Big)^{-1},

and :math:`\mu = 0` if no :math:`\Delta` makes :math:`I - M\Delta` singular
(Packard and Doyle [PD]_; [ZDG]_ ch. 11; [SP]_ ch. 8).  ``M`` maps
the inputs ``w`` of the uncertainty channels to their outputs ``z``;
``Delta`` maps ``z`` back to ``w``.  A block of :math:`\Delta` is

* ``"full"``: a complex ``rows x cols`` matrix (unmodelled dynamics, the
  performance block of a robust-performance test);
* ``"scalar"``: a repeated complex scalar :math:`\delta I_n`;
* ``"real"``: a repeated real scalar :math:`\delta I_n`, :math:`\delta\in\mathbb R`
  (an uncertain physical parameter).

Bounds computed here
--------------------
*Upper bound, LMI form* (:func:`mu_upper`, ``method="lmi"``).  For every
positive definite :math:`D` commuting with the structure,
:math:`\mu(M)\le\bar\sigma(D_\ell^{1/2} M D_r^{-1/2})` ([PD]_).  The best
such bound is the smallest :math:`\beta` for which the linear matrix inequality

.. math::
    M^H D_\ell M + j\,(G M - M^H G^H) - \beta^2 D_r \preceq 0

has a solution :math:`D \succ 0` (block structure of :math:`\boldsymbol\Delta`) and,
with ``real="dg"``, a Hermitian :math:`G` that is nonzero only on real blocks
(Fan, Tits and Doyle [FTD]_; [ZDG]_ ch. 11).  For fixed :math:`\beta` this is
a convex feasibility problem (an SDP solved by Clarabel through cvxpy); the
smallest :math:`\beta` is found by bisection, accelerated by evaluating the
exact generalised eigenvalue of the :math:`(D, G)` found at each level.  The
LMI is posed for :math:`M` balanced by the best diagonal scaling (below), so
that its own scalings stay well conditioned when the optimal :math:`D` spans
many decades.  Every value returned is recomputed from the scalings returned
with it (:func:`dg_bound` does the same from scratch), so it is a certified
bound and not a solver tolerance.

*Upper bound, independent* (``method="osborne"``).  Osborne balancing of the
matrix of block norms gives a starting :math:`D`; the function
:math:`x\mapsto\log\bar\sigma(e^{X}Me^{-X})`, :math:`X = \operatorname{diag}(x)`,
is convex (Sezginer and Overton [SO]_), and is minimised by the ellipsoid
method with the exact subgradient :math:`\|u_k\|^2 - \|v_k\|^2` (``u``, ``v`` the
top singular vectors).  Only diagonal scalings (one scalar per block) are
used, so the two bounds agree for complex full and ``1 x 1`` blocks and this
one is conservative for repeated scalars (and ignores that real blocks are real).

*Upper bound, fast* (``method="fast"``).  The same D-G bound without an SDP.
With :math:`D = LL^H` and :math:`G = \beta_0 L\hat GL^H` the LMI is congruent to
:math:`\lambda_{\max}\big(A^HA + j\beta_0(\hat GA - A^H\hat G)\big) \le \beta^2`,
:math:`A = L_\ell^HML_r^{-H}`, a form in which :math:`\hat G` is
dimensionless (Young, Newlin and Doyle [YND]_ scale G by the level in the same
way).  Its logarithm is minimised over the factors of :math:`D` (log
diagonal) and :math:`\hat G` by BFGS with the weak Wolfe line search that
suits eigenvalue functions (Lewis and Overton [LO]_), with the exact gradient
from the top eigenvector.  Along a frequency grid each descent starts from the
previous frequency's scalings and Hessian approximation, so that it takes a
handful of steps; :func:`mu_sweep` then polishes the values near its peak and
checks the largest by the LMI.

*Lower bound* (:func:`mu_lower`).  For complex blocks, the power iteration of
Packard, Fan and Doyle [PFD]_ (also [PD]_) alternates between the dominant
eigenvectors of :math:`MQ` and the structured unitary :math:`Q` that aligns them;
:math:`\rho(MQ)` is a lower bound and :math:`\Delta = Q e^{-j\arg\lambda}/|\lambda|`
makes :math:`I - M\Delta` singular with :math:`\bar\sigma(\Delta) = 1/\rho`.  It
is a local method; :func:`mu_bounds` restarts it from the singular vectors of
the scaled matrix of the upper bound, which closes the gap whenever the upper
bound is exact (:math:`2S + F \le 3` [PD]_) and its largest singular
value simple.  With one real block :math:`\delta I`, :math:`\mu` is the largest
real eigenvalue of :math:`M` in modulus.  With several real blocks only,
:math:`\min\|\delta\|_\infty` subject to :math:`\lambda(M\Delta(\delta)) = 1` is
solved locally (SLSQP with eigenvalue derivatives) from several starting
directions.  With real and complex blocks, a search over the real
perturbations ``Delta_r`` is made and the complex blocks are handled on the
partially closed loop:

.. math::
    \mu \ \ge\ \min\Big(\frac{1}{\bar\sigma(\Delta_r)},\
    \mu_{\rm complex}\big(\mathcal F_u(M, \Delta_r)\big)\Big),

because :math:`\det(I - M\Delta) = \det(I - M_{11}\Delta_r)\,
\det(I - \mathcal F_u(M,\Delta_r)\Delta_c)`.  Every lower bound comes with the
perturbation that proves it, and its value is recomputed from that
perturbation.  Real :math:`\mu` can be discontinuous in :math:`M` and the
searches with real blocks are local: their lower bounds can be far below
:math:`\mu`, and 0 means "no destabilising perturbation found".

*Upper bound, branch and bound* (:func:`mu_upper_branch`, :func:`branch_peak`).
With wide parameter ranges the D-G bound can lie well above mixed
:math:`\mu` (up to 31 % on random matrices with three real scalars, SLICOT's
AB13MD alike).  Cutting the box of the real parameters into sub-boxes, each
bounded by the D-G bound of its own re-centred matrix, closes the gap as the
boxes shrink (Newlin and Young); a level is proved when every sub-box passes.

*Frequency sweeps* (:func:`mu_sweep`).  Bounds at each frequency of a grid;
the frequencies around lightly damped poles are added and the largest local
maxima are refined by golden-section search, so that a resonance narrower
than the grid spacing is not missed.

Modules
-------
The implementation is split along these ideas; import everything from
``mutext.mu`` (the modules below are private and may move):

``_structure``
    :class:`Block`, :class:`BlockStructure`; the checks of ``M`` and of a
    structure given as a list or a ``blk`` spec.
``_certificate``
    Bounds from given scalings: :func:`dg_bound`, :func:`scaled_sigma` and
    the result :class:`MuUpper` (every upper bound is recomputed here).
``_osborne``
    Diagonal scalings: Osborne balancing and the ellipsoid method.
``_lmi``
    The D and D-G scaling LMI (cvxpy, Clarabel) and its bisection.
``_fast``
    The D-G bound by quasi-Newton descent (``method="fast"``).
``_upper``
    :func:`mu_upper`, which dispatches to the three methods.
``_disc``
    :func:`dg_disc`: the D-G bound as an equivalent complex problem (each
    real parameter's interval replaced by a disc), the form a D-G-K step needs.
``_lower``
    :class:`MuLower` and :func:`mu_lower`: power iteration, real and mixed searches.
``_bounds``
    :class:`MuBounds` and :func:`mu_bounds`: both bounds at one matrix.
``_sweep``
    :func:`default_grid`, :class:`MuSweep` and :func:`mu_sweep`.

References
----------
.. [PD] A. Packard and J. C. Doyle, "The complex structured singular value",
   *Automatica* 29 (1993) 71-109.
.. [PFD] A. Packard, M. K. H. Fan and J. C. Doyle, "A power method for the
   structured singular value", *Proc. 27th IEEE CDC* (1988) 2132-2137.
.. [FTD] M. K. H. Fan, A. L. Tits and J. C. Doyle, "Robustness in the presence
   of mixed parametric uncertainty and unmodeled dynamics", *IEEE TAC* 36
   (1991) 25-38.
.. [SO] R. Sezginer and M. Overton, "The largest singular value of
   e^X A e^-X is convex on convex sets of commuting matrices", *IEEE TAC* 35
   (1990) 229-230.
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996, ch. 11.
.. [SP] S. Skogestad and I. Postlethwaite, *Multivariable Feedback Control*,
   2nd ed., Wiley, 2005, ch. 8.
.. [YND] P. M. Young, M. P. Newlin and J. C. Doyle, "Computing bounds for the
   mixed mu problem", *Int. J. Robust Nonlinear Control* 5 (1995) 573-590.
.. [LO] A. S. Lewis and M. L. Overton, "Nonsmooth optimization via quasi-Newton
   methods", *Math. Programming* 141 (2013) 135-163.
"""
from __future__ import annotations

from ._bounds import MuBounds, mu_bounds
from ._branch import BranchPeak, MuBranch, branch_certifies, branch_peak, mu_upper_branch
from ._certificate import MuUpper, dg_bound, scaled_sigma
from ._disc import DiscForm, dg_disc, disc_transform
from ._lmi import _LMIProblem  # noqa: F401  (tests patch the LMI solver through mutext.mu)
from ._lower import MuLower, mu_lower
from ._structure import Block, BlockStructure
from ._sweep import MuSweep, default_grid, mu_sweep
from ._upper import mu_upper

__all__ = ["Block", "BlockStructure", "MuUpper", "MuLower", "MuBounds", "MuSweep", "MuBranch",
           "BranchPeak", "mu_upper_branch", "branch_certifies", "branch_peak",
           "mu_upper", "mu_lower", "mu_bounds", "mu_sweep", "default_grid", "scaled_sigma",
           "dg_bound", "DiscForm", "dg_disc", "disc_transform"]
