"""The rotor engineer's toolkit: Campbell diagram with critical speeds, mode shapes and log decrement,
unbalance response (Bode/polar), orbits, against closed forms and against the independently written
rotor of ``tests/rotor_plain.py``."""
from __future__ import annotations

import functools
import math

import casadi as ca
import numpy as np
import pytest
import scipy.linalg as sla

from mutext.errors import ModelError
from mutext.examples.cracked_rotor import healthy_rotor as _healthy_rotor
from mutext.rotor import BearingElement, DiskElement, Element, Rotor
from mutext.rotor.campbell_diagram import campbell
from mutext.rotor.modal import mode_shapes
from mutext.rotor.orbits import ellipse, orbit
from mutext.rotor.unbalance import run_up, unbalance_response
from mutext.rotor.units import rpm_to_rad_s

from rotor_plain import plain_rotor as _plain_rotor


@functools.lru_cache(maxsize=None)
def healthy_rotor():
    """The thesis rotor (built once: the analyses below do not change it)."""
    return _healthy_rotor()


@functools.lru_cache(maxsize=None)
def plain_rotor():
    """The independently written thesis rotor (built once)."""
    return _plain_rotor()


# ----------------------------------------------------------------------------- small rotors with closed forms

class CantileverTip(Element):
    """Stiffness of a massless cantilever (clamped at z = 0) seen at its free tip, both planes.

    In the x-z plane (u, psi = du/dz): EI/L^3 [[12, -6L], [-6L, 4L^2]]; in the y-z plane
    (v, theta = -dv/dz) the coupling changes sign.  DOF order of the station: (u, v, theta, psi).
    """
    KIND = "tip"
    FIELDS = {"EI": ("N m^2", "bending stiffness"), "L": ("m", "overhang")}

    def __init__(self, station, EI, L):
        super().__init__((station,), None, EI=EI, L=L)

    def stiffness_matrix(self, p, layout):
        c = self.sym(p, "EI") / self.sym(p, "L") ** 3
        L = self.sym(p, "L")
        K = ca.SX(4, 4)
        K[0, 0] = K[1, 1] = 12 * c
        K[2, 2] = K[3, 3] = 4 * L * L * c
        K[0, 3] = K[3, 0] = -6 * L * c
        K[1, 2] = K[2, 1] = 6 * L * c
        return K


OVERHUNG = dict(m=5.0, Ip=0.05, Id=0.03, EI=2000.0, L=0.4)


def overhung():
    o = OVERHUNG
    return Rotor([DiskElement(1, o["m"], o["Ip"], o["Id"]), CantileverTip(1, o["EI"], o["L"])], name="overhung")


def overhung_closed_form(speed):
    """Forward and backward whirl frequencies [rad/s] of the overhung disk (Stodola-Green rotor):
    (k11 - m w^2)(k22 - Id w^2 +- Ip Omega w) - k12^2 = 0, + forward (gyroscopic stiffening), - backward."""
    o = OVERHUNG
    c = o["EI"] / o["L"] ** 3
    k11, k12, k22 = 12 * c, -6 * o["L"] * c, 4 * o["L"] ** 2 * c
    out = {}
    for name, sgn in (("forward", 1.0), ("backward", -1.0)):
        # (k11 - m w^2)(k22 + sgn Ip W w - Id w^2) - k12^2 as a polynomial in w
        p = np.polymul([-o["m"], 0.0, k11], [-o["Id"], sgn * o["Ip"] * speed, k22])
        p = np.polysub(p, [k12 ** 2])
        r = np.roots(p)
        out[name] = np.sort(r[(np.abs(r.imag) < 1e-9 * np.abs(r).max()) & (r.real > 0)].real)
    return out


def jeffcott(m=2.0, k=8.0e4, c=0.0, ky=None, cy=None):
    """A disk of mass m on a shaft of stiffness k (x) and ky (y) to ground; no rotational stiffness
    (the tilting DOFs are rigid-body and decouple from the translations)."""
    return Rotor([DiskElement(1, m, 0.0, 1e-3), BearingElement(1, k, c, kyy=ky, cyy=cy)], name="Jeffcott")


# ----------------------------------------------------------------------------- Campbell

def test_campbell_overhung_disk_against_closed_form():
    speeds = np.array([0.0, 50.0, 150.0, 400.0])
    cd = campbell(overhung(), speeds, 4)
    for i, W in enumerate(speeds):
        ref = overhung_closed_form(W)
        got = 2 * np.pi * cd.frequencies_hz[i]
        for name in ("forward", "backward"):
            want = ref[name]
            mine = np.sort(got[[r for r, d in enumerate(cd.direction[i]) if d == name]]) if W > 0 else None
            if W > 0:
                np.testing.assert_allclose(mine, want, rtol=1e-9)
        np.testing.assert_allclose(np.sort(got), np.sort(np.concatenate([ref["forward"], ref["backward"]])),
                                   rtol=1e-9)
    assert cd.direction[0] == ["degenerate"] * 4          # at standstill the pairs coincide
    np.testing.assert_allclose(cd.log_dec, 0.0, atol=1e-9)  # no damping


def test_campbell_crossings_and_log_dec_jeffcott():
    # gyroscopic-free, damped: the 1x line crosses the constant natural frequency at w_d; log dec closed form
    m, k, zeta = 2.0, 8.0e4, 0.03
    wn = math.sqrt(k / m)
    c = 2 * zeta * wn * m
    wd = wn * math.sqrt(1 - zeta ** 2)
    cd = campbell(jeffcott(m, k, c), np.linspace(0.0, 4 * wn, 9), 2)
    np.testing.assert_allclose(cd.frequencies_hz, wd / (2 * np.pi), rtol=1e-10)
    np.testing.assert_allclose(cd.log_dec, 2 * np.pi * zeta / math.sqrt(1 - zeta ** 2), rtol=1e-9)
    np.testing.assert_allclose(cd.damping_ratio, zeta, rtol=1e-9)
    for order in (1, 2, 3):
        cr = [x for x in cd.crossings if x.order == order]
        assert len(cr) == 2                                   # both members of the pair
        for x in cr:
            assert x.speed == pytest.approx(wd / order, rel=1e-12)   # g is linear in speed here: exact
            assert x.frequency_hz == pytest.approx(wd / (2 * np.pi), rel=1e-12)


def _plain_modes(rot, speed, n):
    """Eigenvalues (Im > 0, lowest n) and displacement shapes of the plain model, first-order form."""
    N = rot.ndof
    A = np.block([[np.zeros((N, N)), np.eye(N)],
                  [-np.linalg.solve(rot.M, rot.K), -np.linalg.solve(rot.M, rot.C + speed * rot.G)]])
    lam, X = sla.eig(A)
    keep = np.flatnonzero(lam.imag > 0)
    keep = keep[np.argsort(lam[keep].imag)][:n]
    return lam[keep], X[:N, keep]


def _plain_whirl(rot, shape):
    u = np.array([shape[rot.dof(s, "u")] for s in rot.node_of])
    v = np.array([shape[rot.dof(s, "v")] for s in rot.node_of])
    return -2 * np.sum(np.imag(np.conj(u) * v)) / np.sum(np.abs(u) ** 2 + np.abs(v) ** 2), u, v


def test_campbell_thesis_rotor_against_plain_rotor():
    model, rot = healthy_rotor(), plain_rotor()
    speeds = rpm_to_rad_s(np.array([900.0, 1100.0, 3000.0]))
    cd = campbell(model, speeds, 4)
    for i, W in enumerate(speeds):
        lam, X = _plain_modes(rot, W, 4)
        np.testing.assert_allclose(cd.frequencies_hz[i], lam.imag / (2 * np.pi), rtol=1e-8)
        np.testing.assert_allclose(cd.log_dec[i], -2 * np.pi * lam.real / lam.imag, rtol=1e-6)
        labels = ["forward" if _plain_whirl(rot, X[:, r])[0] > 0.5 else "backward" for r in range(4)]
        assert cd.direction[i] == labels == ["backward", "forward"] * 2
    # the 2x line crosses the first forward mode near 1020 rpm (half the 1x critical speed)
    two = cd.critical_speeds(order=2, whirl="forward")
    assert len(two) == 1 and two[0].mode == 1
    assert 1010.0 < two[0].speed_rpm < 1025.0, two[0].speed_rpm
    # at that speed, the plain rotor's forward frequency is twice the running frequency
    lam, _ = _plain_modes(rot, two[0].speed, 2)
    assert lam[1].imag == pytest.approx(2 * two[0].speed, rel=1e-6)


def test_campbell_bad_input_is_named():
    with pytest.raises(ModelError, match="increasing"):
        campbell(overhung(), [100.0, 50.0], 2)
    with pytest.raises(ModelError, match="n_modes"):
        campbell(overhung(), [0.0, 50.0], 0)
    with pytest.raises(ModelError, match="orders"):
        campbell(overhung(), [0.0, 50.0], 2, orders=[0.5])
    with pytest.raises(ModelError, match="two bending"):
        campbell(Rotor([DiskElement(1, 1.0, 0.0, 1.0), BearingElement(1, 1e4)], planes=1), [0.0], 1)


# ----------------------------------------------------------------------------- mode shapes

def test_mode_shapes_against_plain_rotor():
    model, rot = healthy_rotor(), plain_rotor()
    W = rpm_to_rad_s(1500.0)
    ms = mode_shapes(model, W, 4)
    lam, X = _plain_modes(rot, W, 4)
    np.testing.assert_allclose(ms.frequencies_hz, lam.imag / (2 * np.pi), rtol=1e-8)
    for r in range(4):
        w, u, v = _plain_whirl(rot, X[:, r])
        a = np.concatenate([ms.u[:, r], ms.v[:, r]])
        b = np.concatenate([u, v])
        mac = abs(np.vdot(a, b)) ** 2 / (np.vdot(a, a).real * np.vdot(b, b).real)
        assert mac > 1 - 1e-8, (r, mac)
        assert ms.whirl[r] == pytest.approx(w, abs=1e-6)
    assert ms.semi_major.max(axis=0) == pytest.approx(1.0)
    # the first pair bends the shaft between the bearings, largest near the disk (station 16)
    assert abs(int(np.argmax(ms.semi_major[:, 0])) + 1 - 16) <= 2
    assert np.all(ms.log_dec > 0)
    # the planar snapshot: first pair without a node between the bearings, second pair with one
    inside = slice(2, 28)
    assert np.all(np.abs(ms.shape[inside, :2]) > 0) and np.all(np.sign(ms.shape[inside, 0]) == 1)
    assert np.sum(np.diff(np.sign(ms.shape[inside, 2])) != 0) == 1
    assert np.max(np.abs(ms.shape), axis=0) == pytest.approx(1.0)


# ----------------------------------------------------------------------------- unbalance response

def test_unbalance_response_jeffcott_closed_form():
    m, k, zeta, U = 2.0, 8.0e4, 0.02, 1e-4
    wn = math.sqrt(k / m)
    c = 2 * zeta * wn * m
    W = np.linspace(0.2, 2.0, 901) * wn
    r = unbalance_response(jeffcott(m, k, c), 1, U, W, [1, (1, np.pi / 2)], phase=0.3)
    X = U * W ** 2 * np.exp(0.3j) / (k - m * W ** 2 + 1j * c * W)
    np.testing.assert_allclose(r.response[:, 0], X, rtol=1e-10)
    np.testing.assert_allclose(r.response[:, 1], -1j * X, rtol=1e-10)     # y lags x by 90 deg: forward
    # the displacement peak of the unbalance response: W = wn / sqrt(1 - 2 zeta^2), amplitude U/(2 m zeta sqrt(1-zeta^2))
    Wp, A = r.peak(0)
    assert Wp == pytest.approx(wn / math.sqrt(1 - 2 * zeta ** 2), abs=W[1] - W[0])
    assert A == pytest.approx(np.max(np.abs(X)), rel=1e-10)
    assert A == pytest.approx(U / (2 * m * zeta * math.sqrt(1 - zeta ** 2)), rel=2e-3)   # grid step 0.002 wn
    # phase: -90 deg (plus the mark's angle) at the natural frequency, towards -180 above it
    i = int(np.argmin(abs(W - wn)))
    assert np.degrees(r.phase[i, 0] - 0.3) == pytest.approx(-90.0, abs=0.5)
    assert np.degrees(r.phase[-1, 0] - 0.3) < -170.0
    cd = run_up(jeffcott(m, k, c), 1, U, W[::-1], 1, phase=0.3, coast_down=True)
    assert cd.speeds[0] > cd.speeds[-1]
    np.testing.assert_allclose(cd.response[::-1, 0], X, rtol=1e-10)


def test_unbalance_response_thesis_rotor_against_plain_rotor():
    model, rot = healthy_rotor(), plain_rotor()
    W = rpm_to_rad_s(np.linspace(1900.0, 2200.0, 61))
    U, st = 1e-5, 16
    r = unbalance_response(model, st, U, W, [13, (15, np.pi / 4)])
    # the direct solve with the plain rotor's matrices
    F = np.zeros((W.size, rot.ndof), complex)
    F[:, rot.dof(st, "u")] = U * W ** 2
    F[:, rot.dof(st, "v")] = -1j * U * W ** 2
    Z = rot.K[None] - (W ** 2)[:, None, None] * rot.M[None] + 1j * W[:, None, None] * (rot.C + W[:, None, None] * rot.G)
    Q = np.linalg.solve(Z, F[:, :, None])[:, :, 0]
    ref13 = Q[:, rot.dof(13, "u")]
    ref15 = (Q[:, rot.dof(15, "u")] + Q[:, rot.dof(15, "v")]) / math.sqrt(2)
    np.testing.assert_allclose(r.response[:, 0], ref13, rtol=1e-7)
    np.testing.assert_allclose(r.response[:, 1], ref15, rtol=1e-7)
    # the peak sits at the forward critical speed of the Campbell diagram (1 % damping: within 0.2 %)
    crit = campbell(model, rpm_to_rad_s([1900.0, 2200.0]), 2).critical_speeds(1)[0]
    assert r.peak(0)[0] == pytest.approx(crit.speed, rel=2e-3)


def test_unbalance_bad_input_is_named():
    j = jeffcott(c=1.0)
    with pytest.raises(ModelError, match="positive"):
        unbalance_response(j, 1, 1e-4, [0.0, 10.0], 1)
    with pytest.raises(ModelError, match="unbalance station"):
        unbalance_response(j, 2, 1e-4, [10.0], 1)
    with pytest.raises(ModelError, match="probe"):
        unbalance_response(j, 1, 1e-4, [10.0], [(5, 0.0)])
    with pytest.raises(ModelError, match="non-negative"):
        unbalance_response(j, 1, -1e-4, [10.0], 1)


# ----------------------------------------------------------------------------- orbits

def test_orbit_isotropic_jeffcott_is_a_forward_circle():
    m, k, c, U = 2.0, 8.0e4, 10.0, 1e-4
    W = 150.0
    r = unbalance_response(jeffcott(m, k, c), 1, U, [W], 1)
    o = r.orbit(0)
    radius = U * W ** 2 / abs(k - m * W ** 2 + 1j * c * W)
    e = o.ellipse(1)
    assert e.direction == "forward"
    assert e.semi_major == pytest.approx(radius, rel=1e-10) and e.semi_minor == pytest.approx(radius, rel=1e-10)
    np.testing.assert_allclose(np.hypot(o.x, o.y), radius, rtol=1e-10)
    assert o.loops() == 0


@pytest.mark.parametrize("W, direction", [(150.0, "forward"), (210.0, "backward"), (300.0, "forward")])
def test_orbit_anisotropic_bearing_ellipse_closed_form(W, direction):
    # undamped, kx < ky: x = F/(kx - m W^2) cos, y = F/(ky - m W^2) sin -- an ellipse on the axes,
    # backward between the two critical speeds sqrt(kx/m) = 200 and sqrt(ky/m) = 223.6 rad/s
    m, kx, ky, U = 2.0, 8.0e4, 1.0e5, 1e-4
    r = unbalance_response(jeffcott(m, kx, 0.0, ky=ky), 1, U, [W], 1)
    o = r.orbit(0)
    ax, ay = abs(U * W ** 2 / (kx - m * W ** 2)), abs(U * W ** 2 / (ky - m * W ** 2))
    e = o.ellipse(1)
    assert e.semi_major == pytest.approx(max(ax, ay), rel=1e-10)
    assert e.semi_minor == pytest.approx(min(ax, ay), rel=1e-10)
    assert e.direction == direction
    major_on_x = ax > ay
    assert abs(math.cos(e.angle)) == pytest.approx(1.0 if major_on_x else 0.0, abs=1e-9)
    assert np.max(np.abs(o.x)) == pytest.approx(ax, rel=1e-4) and np.max(np.abs(o.y)) == pytest.approx(ay, rel=1e-4)


def test_orbit_with_2x_has_an_inner_loop():
    one = {1: (1e-5, -1e-5j)}
    assert orbit(one, 100.0).loops() == 0
    assert orbit({**one, 2: (0.8e-5, -0.8e-5j)}, 100.0).loops() >= 1
    e = ellipse(1.0, 0.0)                   # a straight line along x
    assert e.direction == "straight" and e.semi_minor == pytest.approx(0.0, abs=1e-15)
    with pytest.raises(ModelError, match="speed"):
        orbit(one, 0.0)
    with pytest.raises(ModelError, match="orders"):
        orbit({-1: (1.0, 1.0)}, 1.0)


# ----------------------------------------------------------------------------- breathing crack: all orders

def test_periodic_response_without_crack_is_sag_plus_unbalance_of_plain_rotor():
    from mutext.rotor.periodic_orbit import GRAVITY, periodic_unbalance_response
    model, rot = healthy_rotor(), plain_rotor()
    W, U = rpm_to_rad_s(1000.0), 2e-6
    r = periodic_unbalance_response(model, W, [15], unbalance=(16, U), harmonics=3)
    ev = np.zeros(rot.ndof)
    ev[[rot.dof(s, "v") for s in rot.node_of]] = 1.0
    sag = np.linalg.solve(rot.K, -GRAVITY * rot.M @ ev)
    F = np.zeros(rot.ndof, complex)
    F[rot.dof(16, "u")], F[rot.dof(16, "v")] = U * W ** 2, -1j * U * W ** 2
    Q = np.linalg.solve(rot.K - W ** 2 * rot.M + 1j * W * (rot.C + W * rot.G), F)
    assert r.Y[0, 0].real == pytest.approx(sag[rot.dof(15, "v")], rel=1e-8)
    assert abs(r.X[0, 0]) < 1e-9 * abs(r.Y[0, 0])
    assert r.X[1, 0] == pytest.approx(Q[rot.dof(15, "u")], rel=1e-7)
    assert r.Y[1, 0] == pytest.approx(Q[rot.dof(15, "v")], rel=1e-7)
    assert np.all(np.abs(r.X[2:]) < 1e-12 * abs(r.X[1, 0]))        # time-invariant: no higher orders


@pytest.mark.slow
def test_breathing_crack_harmonic_balance_against_time_integration():
    """The harmonic balance on a Ritz basis against a time integration of the same reduced model with the
    breathing law evaluated directly (not through its Fourier series), started on the periodic solution."""
    from scipy.integrate import solve_ivp

    from mutext.examples.cracked_rotor import cracked_rotor
    from mutext.rotor.periodic import periodic_rotor
    from mutext.rotor.periodic_orbit import periodic_steady_state, weight_force
    from mutext.rotor.unbalance import unbalance_force
    model = cracked_rotor()
    W = rpm_to_rad_s(1000.0)
    pr = periodic_rotor(model, speed=W)
    P = pr.ritz_basis(400.0)
    red = pr.project(P)
    f0 = P.T @ weight_force(model, pr.M)
    F1 = P.T @ unbalance_force(model, [(16, 1e-5, 0.0)], W)
    N = 8
    Q = periodic_steady_state(red, {0: f0, 1: F1}, N)
    ks = np.arange(-N, N + 1)
    t = np.linspace(0.0, 2 * np.pi / W, 41)
    hb = (np.exp(1j * W * np.outer(t, ks)) @ Q).real                        # (t, r)
    z0 = (Q.sum(axis=0)).real
    dz0 = (1j * W * ks @ Q).real
    Minv = np.linalg.inv(red.M)

    def rhs(tt, s):
        r = red.n
        z, dz = s[:r], s[r:]
        K = red.stiffness_at(W * tt)[0]
        f = f0 + (F1 * np.exp(1j * W * tt)).real
        return np.concatenate([dz, Minv @ (f - red.D @ dz - K @ z)])

    sol = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([z0, dz0]), t_eval=t, method="DOP853", rtol=1e-10,
                    atol=1e-14)
    z = sol.y[:red.n].T
    x_hb = hb @ P.T
    x_ti = z @ P.T
    dof = [model.layout.dof(15, "u"), model.layout.dof(15, "v")]
    dyn = x_hb[:, dof] - x_hb[:, dof].mean(axis=0)
    err = np.max(np.abs(x_hb[:, dof] - x_ti[:, dof])) / np.max(np.abs(dyn))
    print(f"harmonic balance vs time integration: {err:.2e}")
    assert err < 1e-3, err
    # and the 2x order is what dominates near half the critical speed
    assert np.abs(2 * Q[N + 2] @ P.T[:, dof[0]]) > np.abs(2 * Q[N + 1] @ P.T[:, dof[0]])


# ----------------------------------------------------------------------------- figures draw the results

def test_rotor_figures_draw_the_results():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mutext import plots
    cd = campbell(overhung(), np.linspace(0.0, 400.0, 9), 4)
    fig = plots.campbell_figure(cd)
    lines = [ln for ln in fig.axes[0].lines if ln.get_label() == "1x"]
    np.testing.assert_allclose(lines[0].get_ydata(), cd.speeds_rpm / 60.0)
    ms = mode_shapes(healthy_rotor(), 100.0, 2)
    fig2 = plots.mode_shapes_figure(ms, marks={2: "bearing", 29: "bearing"})
    np.testing.assert_allclose(fig2.axes[0].lines[0].get_ydata(), ms.shape[:, 0])
    r = unbalance_response(jeffcott(c=20.0), 1, 1e-4, np.linspace(50.0, 400.0, 30), [1, (1, 0.5)])
    fig3 = plots.unbalance_bode_figure(r, critical=campbell(jeffcott(c=20.0), [0.0, 400.0], 1).crossings[:1])
    np.testing.assert_allclose(fig3.axes[0].lines[0].get_ydata(), 1e6 * r.amplitude[:, 0])
    fig4 = plots.unbalance_polar_figure(r, probe=1)
    np.testing.assert_allclose(fig4.axes[0].lines[0].get_xdata(), 1e6 * r.response[:, 1].real)
    fig5 = plots.orbit_figure([r.orbit(5), r.orbit(20, 1)])
    np.testing.assert_allclose(fig5.axes[1].lines[0].get_ydata(), 1e6 * r.orbit(20, 1).y)
    plt.close("all")


# ----------------------------------------------------------------------------- command line

def test_cli_rotor_campbell(capsys, tmp_path):
    import json

    from mutext.cli import main
    from mutext.rotor import data_path
    png = tmp_path / "campbell.png"
    assert main(["rotor", "campbell", data_path("rotor.toml"), "--speeds", "900:1100:2", "--modes", "2",
                 "--plot", str(png), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["speeds_rpm"] == pytest.approx([900.0, 1100.0]) and png.stat().st_size > 10000
    two = [c for c in out["crossings"] if c["order"] == 2 and c["whirl"] == "forward"]
    assert len(two) == 1 and 1010 < two[0]["speed_rpm"] < 1025
    lam, _ = _plain_modes(plain_rotor(), two[0]["speed_rad_s"], 2)       # the independent rotor there
    assert lam[1].imag / (2 * np.pi) == pytest.approx(two[0]["frequency_hz"], rel=1e-6)
    assert main(["rotor", "campbell", data_path("rotor.toml"), "--speeds", "900,1100", "--modes", "2"]) == 0
    text = capsys.readouterr().out
    assert "2x  mode 2  forward" in text and "rpm" in text
    assert main(["rotor", "campbell", data_path("rotor.toml"), "--speeds", "3000:0:4"]) == 2
    assert "--speeds" in capsys.readouterr().err
    assert main(["rotor", "campbell", str(tmp_path / "none.toml")]) == 1
    assert "no such model file" in capsys.readouterr().err
    assert main(["rotor", "campbell", data_path("three_mass.toml"), "--speeds", "0,10"]) == 1
    assert "two bending planes" in capsys.readouterr().err


# ----------------------------------------------------------------------------- sparse modal solve

def test_sparse_modes_against_plain_rotor():
    from mutext.rotor.sparse_modal import sparse_modes
    model, rot = healthy_rotor(), plain_rotor()
    W = rpm_to_rad_s(2500.0)
    md = sparse_modes(model, W, 6)
    lam, _ = _plain_modes(rot, W, 6)
    np.testing.assert_allclose(md.eigenvalues, lam, rtol=1e-8)
    assert md.whirl_direction() == ["backward", "forward"] * 3
    # a shift near the second pair finds it first
    md2 = sparse_modes(model, W, 2, shift_hz=190.0)
    np.testing.assert_allclose(md2.eigenvalues, lam[2:4], rtol=1e-8)
    with pytest.raises(ModelError, match="shift_hz"):
        sparse_modes(model, W, 2, shift_hz="x")
    # the Campbell diagram on the sparse solve: the same critical speeds as the plain rotor's frequencies
    cd = campbell(model, rpm_to_rad_s([900.0, 1100.0]), 2, method="sparse", refine=True)
    two = cd.critical_speeds(order=2)[0]
    lam, _ = _plain_modes(rot, two.speed, 2)
    assert lam[1].imag == pytest.approx(2 * two.speed, rel=1e-8)


def _fine_shaft(n_el, free=False):
    """A 1.5 m, 50 mm steel shaft of ``n_el`` Timoshenko elements with a disk, on two bearings
    (none when ``free``), spring-supported and lightly damped there."""
    from mutext.rotor import BearingElement, DiskElement, Rotor, ShaftElement
    els = [ShaftElement(i, 1.5 / n_el, 0.05, 0.0, E=211e9, rho=7810.0, nu=0.3) for i in range(1, n_el + 1)]
    els.append(DiskElement.from_geometry(n_el // 3 + 1, 0.07, 0.28, 0.05, 7810.0))
    if not free:
        els += [BearingElement(1, 1e6, 100.0), BearingElement(n_el + 1, 1e6, 100.0)]
    return Rotor(els)


def test_modes_take_the_sparse_route_on_a_fine_mesh_with_the_dense_modes():
    # 40 elements, 164 DOFs: a few modes come from the shift-invert solve; the same frequencies as the
    # dense eigen-decomposition, and each shape in the span of the dense shapes of its frequency
    model = _fine_shaft(40)
    W = rpm_to_rad_s(4000.0)
    dense = model.modes(speed=W, n=4, method="dense")
    auto = model.modes(speed=W, n=4)
    np.testing.assert_allclose(auto.eigenvalues, dense.eigenvalues, rtol=1e-8)
    for r in range(4):
        Q = dense.shapes[:, np.abs(dense.omega - auto.omega[r]) < 1e-6 * auto.omega[r]]
        x, *_ = np.linalg.lstsq(Q, auto.shapes[:, r], rcond=None)
        assert np.linalg.norm(Q @ x - auto.shapes[:, r]) < 1e-6 * np.linalg.norm(auto.shapes[:, r])
    sparse = model.modes(speed=W, n=4, method="sparse")
    np.testing.assert_array_equal(sparse.eigenvalues, auto.eigenvalues)      # a fixed start vector
    # a free-free shaft (rigid-body modes): "auto" falls back to the dense route, which leaves them out
    assert _fine_shaft(40, free=True).modes(n=2).frequencies_hz[0] > 1.0


def test_sparse_route_of_modes_says_what_it_needs():
    free = _fine_shaft(40, free=True)
    with pytest.raises(ModelError, match="rigid-body"):
        free.modes(n=2, method="sparse")
    with pytest.raises(ModelError, match="give n"):
        free.modes(method="sparse")
    with pytest.raises(ModelError, match="method must be"):
        free.modes(n=2, method="arpack")


def test_periodic_response_and_orbit_bad_input_is_named():
    from mutext.rotor.periodic_orbit import periodic_unbalance_response
    j = jeffcott(c=1.0)
    with pytest.raises(ModelError, match="nothing loads"):
        periodic_unbalance_response(j, 100.0, [1], weight=False)
    with pytest.raises(ModelError, match="unbalance must be"):
        periodic_unbalance_response(j, 100.0, [1], unbalance=(1,))
    with pytest.raises(ModelError, match="harmonics"):
        periodic_unbalance_response(j, 100.0, [1], harmonics=0)
    with pytest.raises(ModelError, match="running speed"):
        periodic_unbalance_response(j, -1.0, [1])
    with pytest.raises(ModelError, match="mapping"):
        orbit(5, 10.0)
    # a model without ports: the weight alone sags the overhung disk's tip by m g L^3 / (3 EI)
    r = periodic_unbalance_response(overhung(), 100.0, [1], harmonics=1)
    o = OVERHUNG
    assert r.Y[0, 0].real == pytest.approx(-o["m"] * 9.80665 * o["L"] ** 3 / (3 * o["EI"]), rel=1e-12)
    assert abs(r.X[0, 0]) < 1e-15 and np.all(np.abs(r.X[1:]) < 1e-15)


def test_cli_rotor_whirl(capsys, tmp_path):
    """``mutext rotor whirl``: the peaks of the forward and backward dFRFs of a two-plane sweep at 3000 rpm
    against the independently written rotor's damped frequencies and whirl senses (modes 3 and 4, 180-210 Hz)."""
    import json

    from mutext.cli import main
    from mutext.rotor import data_path
    assert main(["rotor", "whirl", data_path("rotor.toml"), "--input", "i12", "--output", "x13", "--speed", "3000",
                 "--freqs", "170:215:1801", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["speed_rpm"] == pytest.approx(3000.0)
    got = {p["direction"]: p["frequency_hz"] for p in out["peaks"]}
    assert len(out["peaks"]) == 2 and set(got) == {"forward", "backward"}
    rot = plain_rotor()
    lam, X = _plain_modes(rot, 3000 * 2 * np.pi / 60, 4)
    want = {("forward" if _plain_whirl(rot, X[:, k])[0] > 0.5 else "backward"): lam[k].imag / (2 * np.pi)
            for k in (2, 3)}
    assert set(want) == {"forward", "backward"}
    for s in ("forward", "backward"):
        # the peak of |H| lies O(zeta^2) below the damped frequency
        assert got[s] == pytest.approx(want[s], rel=1e-3)
    assert main(["rotor", "whirl", data_path("rotor.toml"), "--input", "12", "--output", "13",
                 "--freqs", "20:60:401"]) == 0
    text = capsys.readouterr().out
    assert "forward" in text and "backward" in text and "600 rpm" in text
    assert main(["rotor", "whirl", data_path("rotor.toml"), "--input", "i12", "--output", "x13",
                 "--freqs", "20:10:5"]) == 2
    assert "--freqs" in capsys.readouterr().err
    assert main(["rotor", "whirl", str(tmp_path / "none.toml"), "--input", "1", "--output", "2"]) == 1
    assert "no such model file" in capsys.readouterr().err
