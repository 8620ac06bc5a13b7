"""ex08, a common mistake: the control force enters the engineering model as +u (the plant of Fig. 3.3 applies -u); (b)-(d) use that plant."""
from __future__ import annotations

import numpy as np

PARAMS = ("m1", "m2", "m3", "k1", "k2", "k3", "c1", "c2", "c3")


def _mck(values):
    v = dict(zip(PARAMS, values))
    M = np.diag([v["m1"], v["m2"], v["m3"]])
    K = np.array([[v["k1"], -v["k1"], 0.0], [-v["k1"], v["k1"] + v["k2"], -v["k2"]],
                  [0.0, -v["k2"], v["k2"] + v["k3"]]])
    return M, np.diag([v["c1"], v["c2"], v["c3"]]), K, v


def _plant_matrices(rig, Wz):
    Mt, Ct, Kt, vt = _mck(rig["true"])
    Me, Ce, Ke, _ = _mck(rig["engineering"])
    exc, meas, ctl = rig["excitation"], rig["measurement"], rig["control"]
    Ww, rel, name = rig["Ww"], rig["rel"], rig["changed"]
    e = np.eye(3)
    Z = np.zeros((3, 3))
    Mti, Mei = np.linalg.inv(Mt), np.linalg.inv(Me)
    At = np.block([[Z, np.eye(3)], [-Mti @ Kt, -Mti @ Ct]])
    Ae = np.block([[Z, np.eye(3)], [-Mei @ Ke, -Mei @ Ce]])
    A = np.block([[At, np.zeros((6, 6))], [np.zeros((6, 6)), Ae]])
    # inputs [w_unc, w, n, u], outputs [z_unc, z, z_u, y]
    B = np.zeros((12, 4))
    C = np.zeros((4, 12))
    D = np.zeros((4, 4))
    B[3:6, 0] = -Mti @ e[2]                          # w_unc: a force -e3 w_unc on the true rig
    B[3:6, 1] = Mti @ e[exc] * Ww
    B[9:12, 1] = Mei @ e[exc] * Ww
    B[9:12, 3] = Mei @ e[ctl]                        # +u on the engineering model
    p = vt[name]
    if name == "k3":
        C[0, 2] = rel * p
    elif name == "c3":
        C[0, 5] = rel * p
    else:                                            # rel m3 q3'': the third row of the true rig's acceleration
        C[0, :6] = rel * p * At[5]
        D[0, 0] = rel * p * B[5, 0]
        D[0, 1] = rel * p * B[5, 1]
    C[1, meas] = 1.0 / Wz
    C[1, 6 + meas] = -1.0 / Wz
    D[2, 3] = rig["eps_u"]
    C[3, 6 + ctl] = 1.0
    D[3, 2] = rig["eps_y"]
    return A, B, C, D


def mbi_plant(rig, Wz):
    return _plant_matrices(rig, Wz)


def _structure():
    from mutext.mu import Block, BlockStructure
    return BlockStructure([Block.real(1, "parameter"), Block.full(2, 2, "performance")])


def _dk(rig, Wz, omega, more=False):
    """D-K at ``Wz``: the first K step (python-control's hinfsyn with unit scalings) and the peak of the mu
    upper bound on ``omega``; with ``more``, :func:`mutext.dk.dk_iteration` continues if that is above 1."""
    import control as ct
    from mutext.lti import lft_lower
    from mutext.mu import mu_sweep
    P = ct.ss(*_plant_matrices(rig, Wz))
    omega = np.asarray(omega, float)
    K = ct.hinfsyn(P, 1, 1)[0]
    mu = float(mu_sweep(lft_lower(P, K, 1, 1), _structure(), omega, lower="none").peak_upper)
    if more and mu > 1.0:
        from mutext.dk import dk_iteration
        res = dk_iteration(P, _structure(), 1, 1, omega=omega, max_iter=2)
        K, mu = res.K, float(res.mu_upper)
    return K, mu


def synthesize(rig, Wz, omega):
    return _dk(rig, Wz, omega, more=True)[0]


def smallest_wz(rig, wz_low, wz_high, omega):
    lo, hi = float(wz_low), float(wz_high)          # mu > 1 at lo, mu <= 1 at hi
    Wz = hi
    _, mu = _dk(rig, Wz, omega)
    for _ in range(6):
        trial = Wz * mu / 0.99                       # secant: mu Wz is about constant
        if not lo < trial < hi:
            trial = float(np.sqrt(lo * hi))          # bisection in log Wz
        _, mu_t = _dk(rig, trial, omega)
        if mu_t <= 1.0:
            hi = trial
            if mu_t >= 0.95:
                break
        else:
            lo = trial
        Wz, mu = trial, mu_t
        if hi / lo < 1.05:
            break
    return float(hi)


def read_controller(rig, Wz, K, omega):
    import control as ct
    w = np.asarray(omega, float)
    A, B, C, D = _plant_matrices(rig, Wz)
    P = ct.ss(A, B[:, 1:], C[1:], D[1:, 1:])          # delta = 0: inputs [w, n, u], outputs [z, z_u, y]
    H = P(1j * w)                                    # (3, 3, nw)
    Pzu, Pyw, Pyu = H[0, 2], H[2, 0], H[2, 2]
    Kj = np.asarray(ct.ss(K)(1j * w)).reshape(-1)
    s = np.abs(Pzu * Pyw / (1 - Pyu * Kj) ** 2)
    band = s * np.abs(Kj) >= 1.0
    if band.sum() < 3:                               # no band to speak of: the whole grid
        band = np.ones_like(band)
    wb, sb, kb = w[band], s[band], Kj[band]
    X = np.zeros((2 * wb.size, 3))
    X[:wb.size, 0] = -wb ** 2
    X[:wb.size, 2] = 1.0
    X[wb.size:, 1] = wb
    W = np.concatenate([sb, sb])
    col = np.linalg.norm(X * W[:, None], axis=0)
    coef, *_ = np.linalg.lstsq(X * W[:, None] / col, np.concatenate([kb.real, kb.imag]) * W, rcond=None)
    dm, dc, dk = coef / col
    return np.array([dm, dc, dk, wb.min(), wb.max()])
