r"""Exercise ex08: model-based identification on the three-mass rig (thesis ch. 3, Fig. 3.3).

Fill in the four functions below, then check that your file runs with::

    mutext check ex08_mbi exercises/ex08_mbi.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

Three carts on a track (the ECP rig of thesis Table 3.1): the chain
``m1 --k1-- m2 --k2-- m3 --k3-- ground`` with a damper ``c_i`` from each cart
to the ground,

.. math::
    M = \operatorname{diag}(m_1, m_2, m_3),\quad
    K = \begin{bmatrix} k_1 & -k_1 & 0\\ -k_1 & k_1 + k_2 & -k_2\\ 0 & -k_2 & k_2 + k_3\end{bmatrix},\quad
    C = \operatorname{diag}(c_1, c_2, c_3).

Every function receives the dictionary ``rig``:

``rig["true"]``, ``rig["engineering"]``
    ``[m1, m2, m3, k1, k2, k3, c1, c2, c3]`` (kg, N/m, N s/m) of the true rig
    and of the engineering model.
``rig["changed"]``, ``rig["rel"]``
    The name of the one true parameter that is uncertain (``"k3"``, ``"m3"``
    or ``"c3"``) and its relative uncertainty: the true rigs are those with
    ``p = p0 (1 + rel delta)``, ``delta`` real in ``[-1, 1]``.
``rig["excitation"]``, ``rig["measurement"]``, ``rig["control"]``
    0-based carts: where the excitation force ``w`` acts on both systems,
    where their displacements are compared, and where the engineering model
    gets the force ``-u`` and gives the displacement ``y``.
``rig["Ww"]``, ``rig["eps_u"]``, ``rig["eps_y"]``
    Size of the excitation [N]; control penalty [1/N] and sensor noise [m]
    that make the H-infinity problem regular.

The plant of thesis Fig. 3.3 (book chapter "Model-based identification")
has inputs ``[w_unc, w, n, u]`` and outputs ``[z_unc, z, z_u, y]``:

.. math::
    z = \frac{x_t - x_e}{W_z},\qquad z_u = \varepsilon_u u,\qquad y = x_{e,\text{control}} + \varepsilon_y n,

with ``x_t`` and ``x_e`` the true and engineering displacements at the
measurement cart for the excitation ``W_w w``, the force ``-u`` on the
engineering model's control cart, and ``w_unc = delta z_unc`` the
uncertainty channel of the true rig (any scaling of ``w_unc`` and ``z_unc``).
Robust performance is ``mu <= 1`` for the structure ``diag(delta, Delta_p)``:
one real ``1 x 1`` block and a full complex ``2 x 2`` performance block
(``[z, z_u]`` to ``[w, n]``).  The controller ``u = K y`` then stands for the
missing dynamic stiffness ``K(s) ~ D_u(s) = dm s^2 + dc s + dk``.

Rules
-----
* You may import numpy, scipy, control, ``mutext.lti``, ``mutext.hinf``,
  ``mutext.uncertain``, ``mutext.mu`` and ``mutext.dk`` (e.g.
  ``mutext.dk.dk_iteration`` for the D-K iteration).  ``mutext.mbi``
  (which computes these answers), ``mutext.examples`` and
  ``mutext.grading`` are blocked and score 0.
* Arguments arrive as JSON (lists, dicts); ``K`` as a ``control.StateSpace``.
* SI units: kg, N/m, N s/m, N, m, rad/s.  Each function has a time limit of
  60 s: one D-K run with ``max_iter=1`` or 2 on the grid ``omega`` given takes
  a few seconds; keep the searches short.
"""
import numpy as np
import control as ct


def mbi_plant(rig, Wz):
    """(a) The generalized plant of thesis Fig. 3.3.

    Parameters
    ----------
    rig : dict
        As in the module docstring.
    Wz : float
        Allowed error of the measured displacement [m].

    Returns
    -------
    control.StateSpace (or (A, B, C, D))
        Inputs ``[w_unc, w, n, u]``, outputs ``[z_unc, z, z_u, y]`` (4 and 4).
        Graded by closing ``w_unc = delta z_unc`` for several ``delta`` in
        ``[-1, 1]`` and comparing the frequency responses of ``[w, n, u] ->
        [z, z_u, y]`` (relative tolerance 1e-4).
    """
    raise NotImplementedError


def synthesize(rig, Wz, omega):
    """(b) A controller with robust performance at ``Wz`` by D-K iteration.

    Parameters
    ----------
    rig : dict
    Wz : float
        Allowed error [m] (loose enough that ``mu < 1`` can be reached).
    omega : list of float
        Frequency grid [rad/s] for the D steps.

    Returns
    -------
    control.StateSpace
        ``K``, input ``y`` [m], output ``u`` [N], at most 60 states.  The
        grader closes it around its own plant: the loop must be stable (0.5
        point), the peak of the mu upper bound at most 1 (1.5; 0.75 up to
        1.1), and ``K(j omega)`` must follow the rig's ``D_u`` on the band
        where it is identifiable (1).
    """
    raise NotImplementedError


def smallest_wz(rig, wz_low, wz_high, omega):
    """(c) The W_z rule: the smallest ``Wz`` at which D-K reaches ``mu <= 1``.

    Parameters
    ----------
    rig : dict
    wz_low, wz_high : float
        A bracket [m]: ``mu > 1`` at ``wz_low`` (no controller can do it),
        ``mu < 1`` at ``wz_high``.
    omega : list of float
        Frequency grid [rad/s].

    Returns
    -------
    float
        ``Wz`` [m] with ``mu <= 1`` and within 15 % of the smallest such value
        (mu scales roughly like ``1/Wz``: a secant step in ``log Wz``
        followed by bisection needs a few D-K runs).
    """
    raise NotImplementedError


def read_controller(rig, Wz, K, omega):
    """(d) Read ``K``: the mass, damper and spring it stands for, on its identifiable band.

    Parameters
    ----------
    rig : dict
    Wz : float
        The ``Wz`` at which ``K`` was found [m].
    K : control.StateSpace
        The identified controller.
    omega : list of float
        Frequency grid [rad/s].

    Returns
    -------
    numpy array of 5 numbers
        ``[dm, dc, dk, omega_lo, omega_hi]``: the least-squares fit
        ``K(j omega) ~ dk + j omega dc - omega^2 dm`` on the identifiable
        band, each frequency weighted by ``|s(omega)|``, and the band's
        lowest and highest frequency on the grid [rad/s].  The band is where
        a 100 % error of ``K`` would exceed the allowed error,
        ``|s(omega) K(j omega)| >= 1`` with the nominal channels of (a)
        (``delta = 0``, ``n = 0``):
        ``s = P_zu P_yw / (1 - P_yu K)^2``.
        The fit is compared through its response on the band (2 %), the band
        edges to one grid point.
    """
    raise NotImplementedError
