r"""A plainly written finite-element model of the thesis rotor, apart from ``mutext.rotor``.

Purpose: "measured" data for :func:`mutext.diagnose.diagnose` that do not come from the
code being diagnosed.  Only the *numbers* are shared with the package: the station table
is read (and converted to SI) by :func:`mutext.rotor.table.read_station_table`, the rest of
``mutext/data/rotor.toml`` (bearings, exciter, speed, Poisson's ratio, modal damping ratio)
by :mod:`tomllib`.  Elements, assembly, damping and the frequency response are written
here with numpy/scipy.

Model (Friswell, Penny, Garvey and Lees, *Dynamics of Rotating Machines*, CUP 2010, ch. 5)
-----------------------------------------------------------------------------------------
* Shaft: two-plane Timoshenko beam elements between consecutive stations (the element
  starting at station *i* has the length, diameters, E and density of table row *i*), with
  consistent translational and rotary mass, stiffness with the shear parameter
  :math:`\Phi = 12EI/(\kappa G A L^2)`, :math:`G = E/(2(1+\nu))`, :math:`\nu = 0.3`,
  :math:`\kappa = 6(1+\nu)/(7+6\nu)` (solid circular section), and the gyroscopic
  matrix :math:`G_e = \int \rho I_p (b a^T - a b^T) dz` of the spinning shaft, built from
  the rotary mass matrix (:math:`I_p = 2I`).  ``n_sub`` > 1 splits every table element into
  that many equal sub-elements (a finer mesh: a genuine model-form difference from the
  package, which uses one element per table row).
* Table rows with added mass / inertias: rigid lumped disks, :math:`\mathrm{diag}(m, m, I_d,
  I_d)` and the gyroscopic pair :math:`\pm I_p` on the two rotations.
* Bearings: isotropic springs to ground (the ``[[bearing]]`` tables: stations 2 and 29,
  1e7 N/m, no damping); a hidden ``("cross", s, ...)`` effect adds cross-coupled stiffness to
  the bearing block on (u, v): ``K[u, v] += kxy``, ``K[v, u] += kyx`` (the bearing's force on
  the shaft is ``-K q``).
* Exciter: force per ampere (40 N/A) at station 12 in x; no negative stiffness.
* Damping: 1 % modal, :math:`C = M\Phi\,\mathrm{diag}(2\zeta\omega_r)\Phi^T M` with
  :math:`\Phi^T M \Phi = I` the undamped modes of :math:`(K, M)` at zero speed (all DOFs
  of both planes; modes with :math:`\omega_r^2 \le 10^{-12}\max\omega^2` get none, as
  ``mutext.rotor.assembly.modal_damping_matrix`` defines it).  It is computed **after** the
  hidden effect has been added to M and K, as the package's extended model file does.
* Equation of motion at the spin speed :math:`\Omega` (600 rpm):
  :math:`M\ddot q + (C + \Omega G)\dot q + Kq = b\,i`, the response
  :math:`H(\omega) = e_o^T (K - \omega^2 M + j\omega(C + \Omega G))^{-1} b` [m/A].

Coordinates.  Shaft along +z, spinning about +z.  x-z plane: displacement ``u`` and
rotation ``psi`` about y, with ``psi = du/dz``; y-z plane: displacement ``v`` and rotation
``theta`` about x, with ``theta = -dv/dz`` (right-handed rotations).  The DOFs are ordered
plane by plane -- all (u, psi) pairs of the x-z plane first, then all (v, theta) pairs --
unlike the package's station-by-station (u, v, theta, psi); see :func:`dof`.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from mutext.rotor.table import read_station_table

MODEL_FILE = Path(__file__).resolve().parents[1] / "mutext" / "data" / "rotor.toml"


# ---------------------------------------------------------------------------------------------
# the numbers of the model file
# ---------------------------------------------------------------------------------------------

def _model_numbers(path=MODEL_FILE):
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    assert doc.get("units", "SI") == "SI" and doc.get("planes", 2) == 2
    table = read_station_table(Path(path).parent / doc["shaft"]["station_table"])
    return {
        "stations": list(table),
        "nu": float(doc["shaft"]["poisson_ratio"]),
        "speed": float(doc["speed_rpm"]) * 2.0 * math.pi / 60.0,
        "bearings": {int(b["station"]): float(b["stiffness"]) for b in doc["bearing"]},
        "bearing_damping": {int(b["station"]): float(b.get("damping", 0.0)) for b in doc["bearing"]},
        "exciter": (int(doc["exciter"][0]["station"]), float(doc["exciter"][0]["force_per_ampere"]),
                    float(doc["exciter"][0].get("negative_stiffness", 0.0))),
        "zeta": float(doc["damping"]["modal"]),
    }


# ---------------------------------------------------------------------------------------------
# element matrices (one bending plane, DOFs (w1, slope1, w2, slope2) with slope = dw/dz)
# ---------------------------------------------------------------------------------------------

def timoshenko_plane(E, nu, rho, L, d):
    """Stiffness, translational mass and rotary mass (with rho*I) of a solid circular element."""
    A = math.pi * d ** 2 / 4.0
    I = math.pi * d ** 4 / 64.0
    G = E / (2.0 * (1.0 + nu))
    kappa = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)
    P = 12.0 * E * I / (kappa * G * A * L ** 2)          # shear parameter Phi

    K = E * I / ((1.0 + P) * L ** 3) * np.array([
        [12.0, 6 * L, -12.0, 6 * L],
        [6 * L, (4 + P) * L ** 2, -6 * L, (2 - P) * L ** 2],
        [-12.0, -6 * L, 12.0, -6 * L],
        [6 * L, (2 - P) * L ** 2, -6 * L, (4 + P) * L ** 2]])

    m1 = 312 + 588 * P + 280 * P ** 2
    m2 = 44 + 77 * P + 35 * P ** 2
    m3 = 108 + 252 * P + 140 * P ** 2
    m4 = 26 + 63 * P + 35 * P ** 2
    m5 = 8 + 14 * P + 7 * P ** 2
    m6 = 6 + 14 * P + 7 * P ** 2
    Mt = rho * A * L / (840.0 * (1 + P) ** 2) * np.array([
        [m1, m2 * L, m3, -m4 * L],
        [m2 * L, m5 * L ** 2, m4 * L, -m6 * L ** 2],
        [m3, m4 * L, m1, -m2 * L],
        [-m4 * L, -m6 * L ** 2, -m2 * L, m5 * L ** 2]])

    m7 = 3 - 15 * P
    m8 = 4 + 5 * P + 10 * P ** 2
    m9 = 1 + 5 * P - 5 * P ** 2
    Mr = rho * I / (30.0 * (1 + P) ** 2 * L) * np.array([
        [36.0, m7 * L, -36.0, m7 * L],
        [m7 * L, m8 * L ** 2, -m7 * L, -m9 * L ** 2],
        [-36.0, -m7 * L, 36.0, -m7 * L],
        [m7 * L, -m9 * L ** 2, -m7 * L, m8 * L ** 2]])
    return K, Mt, Mr


# y-z plane: slope dv/dz = -theta, so its (v, theta) matrices are S X S with S = diag(1, -1, 1, -1)
_S = np.diag([1.0, -1.0, 1.0, -1.0])


# ---------------------------------------------------------------------------------------------
# assembly
# ---------------------------------------------------------------------------------------------

@dataclass
class PlainRotor:
    """Matrices (SI) of the plain model and its DOF helpers.

    ``M, C, K, G`` are ``ndof x ndof``; the velocity matrix at speed is ``C + speed * G``.
    ``node_of[s]`` is the mesh node of station ``s`` (1-based stations; nodes 0-based).
    """
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    G: np.ndarray
    b: np.ndarray                 # input vector of the exciter current [N/A on its DOF]
    speed: float                  # rad/s
    n_nodes: int
    node_of: dict
    positions: np.ndarray         # axial position of the mesh nodes [m]

    @property
    def ndof(self):
        return self.M.shape[0]

    def dof(self, station, what="u"):
        """0-based DOF index of ``what`` in {"u"/"x", "psi", "v"/"y", "theta"} at ``station``."""
        n = self.node_of[int(station)]
        off = {"u": 0, "x": 0, "psi": 1, "v": 2 * self.n_nodes, "y": 2 * self.n_nodes,
               "theta": 2 * self.n_nodes + 1}[what]
        return off + 2 * n

    def translational(self, station):
        """(u, v) DOFs of a station."""
        return [self.dof(station, "u"), self.dof(station, "v")]


def modal_damping(M, K, zeta):
    r""":math:`C = M\Phi\,\mathrm{diag}(2\zeta\omega_r)\Phi^T M` (mass-normalised undamped modes)."""
    lam, Phi = sla.eigh(0.5 * (K + K.T), M)
    lam_max = float(np.max(np.abs(lam)))
    w = np.where(lam > 1e-12 * lam_max, np.sqrt(np.clip(lam, 0.0, None)), 0.0)
    MP = M @ Phi
    return (MP * (2.0 * zeta * w)) @ MP.T


def plain_rotor(extra=None, *, n_sub=1, path=MODEL_FILE) -> PlainRotor:
    """The thesis rotor's M, C, K, G with the hidden effects ``extra`` added.

    Parameters
    ----------
    extra : sequence of (kind, station, size), optional
        ``("spring", s, k)``: isotropic grounded spring k [N/m] at station s;
        ``("mass", s, m)``: point mass m [kg] (translation only) at station s;
        ``("bearing", s, dk)``: the stiffness of the bearing at station s changed by dk [N/m]
        (both directions); ``("cross", s, q)``: cross-coupled stiffness in the bearing at station s,
        skew ``kxy = q``, ``kyx = -q`` [N/m] (or ``("cross", s, (kxy, kyx))``).  Modal damping is
        computed from M and K *with* the effects (from the symmetric part of K, which a skew
        cross-coupling leaves unchanged).
    n_sub : int
        Sub-elements per table element (1: the package's mesh).
    """
    num = _model_numbers(path)
    st = num["stations"]
    ns = len(st)
    # mesh: station s (1-based) is node (s-1)*n_sub
    node_of = {s: (s - 1) * n_sub for s in range(1, ns + 1)}
    n_nodes = (ns - 1) * n_sub + 1
    N = 4 * n_nodes
    M, K, G = np.zeros((N, N)), np.zeros((N, N)), np.zeros((N, N))
    xz = lambda n: [2 * n, 2 * n + 1, 2 * n + 2, 2 * n + 3]                                # noqa: E731
    yz = lambda n: [2 * n_nodes + 2 * n, 2 * n_nodes + 2 * n + 1,                         # noqa: E731
                    2 * n_nodes + 2 * n + 2, 2 * n_nodes + 2 * n + 3]
    pos = np.zeros(n_nodes)
    for k, row in enumerate(st[:-1]):
        assert row.inner_diameter == 0.0
        Ke, Mt, Mr = timoshenko_plane(row.youngs_modulus, num["nu"], row.density, row.length / n_sub,
                                      row.outer_diameter)
        Me = Mt + Mr
        for j in range(n_sub):
            n = k * n_sub + j
            pos[n + 1] = pos[n] + row.length / n_sub
            ix, iy = np.ix_(xz(n), xz(n)), np.ix_(yz(n), yz(n))
            K[ix] += Ke
            M[ix] += Me
            K[iy] += _S @ Ke @ _S
            M[iy] += _S @ Me @ _S
            # gyroscopic: psi = a^T q (x-z plane), theta = b^T q = -(S a)^T q_yz, Ip = 2 I
            G[np.ix_(yz(n), xz(n))] += -2.0 * _S @ Mr
            G[np.ix_(xz(n), yz(n))] += 2.0 * Mr @ _S
    # lumped disks of the table
    for s, row in enumerate(st, start=1):
        n = node_of[s]
        u, psi, v, th = 2 * n, 2 * n + 1, 2 * n_nodes + 2 * n, 2 * n_nodes + 2 * n + 1
        M[u, u] += row.added_mass
        M[v, v] += row.added_mass
        M[psi, psi] += row.added_transverse_inertia
        M[th, th] += row.added_transverse_inertia
        G[th, psi] += row.added_polar_inertia          # Id theta'' + Omega Ip psi' = M_theta
        G[psi, th] -= row.added_polar_inertia          # Id psi'' - Omega Ip theta' = M_psi

    rot = PlainRotor(M, None, K, G, np.zeros(N), num["speed"], n_nodes, node_of, pos)
    for s, kb in num["bearings"].items():
        for d in rot.translational(s):
            K[d, d] += kb
    C0 = np.zeros((N, N))
    for s, cb in num["bearing_damping"].items():
        for d in rot.translational(s):
            C0[d, d] += cb
    s_exc, ki, kx = num["exciter"]
    rot.b[rot.dof(s_exc, "u")] = ki
    K[rot.dof(s_exc, "u"), rot.dof(s_exc, "u")] -= kx

    for kind, s, size in (extra or ()):
        dofs = rot.translational(s)
        if kind == "spring":
            for d in dofs:
                K[d, d] += size
        elif kind == "mass":
            for d in dofs:
                M[d, d] += size
        elif kind == "bearing":
            if s not in num["bearings"]:
                raise ValueError(f"no bearing at station {s}")
            for d in dofs:
                K[d, d] += size
        elif kind == "cross":
            if s not in num["bearings"]:
                raise ValueError(f"no bearing at station {s}")
            kxy, kyx = (size, -size) if np.ndim(size) == 0 else size
            u, v = dofs
            K[u, v] += kxy
            K[v, u] += kyx
        else:
            raise ValueError(f"unknown effect kind {kind!r}")
    rot.C = C0 + modal_damping(M, K, num["zeta"])
    return rot


def plain_frf(freq_hz, out_station, direction="x", extra=None, *, n_sub=1, rotor=None, force_at=None):
    """Response [m/A] from the exciter current to the displacement of ``out_station`` in x or y.

    ``force_at = (station, "x" or "y")``: the response [m/N] to a unit force there instead."""
    r = plain_rotor(extra, n_sub=n_sub) if rotor is None else rotor
    w = 2.0 * np.pi * np.asarray(freq_hz, dtype=float)
    D = r.C + r.speed * r.G
    Z = r.K[None] - (w ** 2)[:, None, None] * r.M[None] + 1j * w[:, None, None] * D[None]
    b = r.b
    if force_at is not None:
        b = np.zeros(r.ndof)
        b[r.dof(force_at[0], "u" if force_at[1] == "x" else "v")] = 1.0
    X = np.linalg.solve(Z, np.broadcast_to(b[:, None], (w.size, r.ndof, 1)))[:, :, 0]
    return X[:, r.dof(out_station, "u" if direction == "x" else "v")]


def plain_natural_frequencies(extra=None, *, n_sub=1, rotor=None, speed=None):
    """Damped natural frequencies [Hz] at ``speed`` (default: the model's), lowest first."""
    r = plain_rotor(extra, n_sub=n_sub) if rotor is None else rotor
    sp = r.speed if speed is None else speed
    N = r.ndof
    A = np.block([[np.zeros((N, N)), np.eye(N)],
                  [-np.linalg.solve(r.M, r.K), -np.linalg.solve(r.M, r.C + sp * r.G)]])
    lam = np.linalg.eigvals(A)
    f = np.abs(lam[lam.imag > 0].imag) / (2 * np.pi)
    return np.sort(f)
