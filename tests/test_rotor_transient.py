"""Transient run-up and coast-down (:mod:`mutext.rotor.transient`) against independent references:
the steady unbalance response at a constant speed (the package's, and a plain solve with the matrices of
the independently written rotor of ``tests/rotor_plain.py``), a Jeffcott rotor written here and
integrated by ``scipy.integrate.solve_ivp``, the known physics of a finite acceleration (Lewis 1932:
the peak is lower than the steady one, later in a run-up, earlier in a coast-down), bad input, the
figure and the command line."""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mutext.errors import ModelError
from mutext.examples.cracked_rotor import healthy_rotor as _healthy_rotor
from mutext.rotor import BearingElement, DiskElement, Rotor
from mutext.rotor.transient import transient_run_up
from mutext.rotor.unbalance import unbalance_response

from rotor_plain import plain_rotor as _plain_rotor


@functools.lru_cache(maxsize=None)
def healthy_rotor():
    return _healthy_rotor()


def jeffcott(m, k, c):
    """A disk of mass m on a massless shaft of stiffness k and damping c (tilting DOFs free, uncoupled)."""
    return Rotor([DiskElement(1, m, 0.0, 1e-3), BearingElement(1, k, c)], name="Jeffcott")


# ----------------------------------------------------------------------------- constant speed: the steady response

def test_constant_speed_settles_to_the_steady_unbalance_response():
    model, rot = healthy_rotor(), _plain_rotor()
    W, st, mass, e, ph = 180.0, 16, 1e-3, 0.01, 0.4               # 1719 rpm, below the first critical (2037)
    r = transient_run_up(model, (W, W), (st, mass, e, ph), [16, 13], duration=6.0, initial="rest")
    assert r.acceleration == 0.0 and r.speed == pytest.approx(W)
    # the package's steady response
    s = unbalance_response(model, st, mass * e, [W], [16, 13], phase=ph)
    np.testing.assert_allclose(r.X1[-1], s.X[0], rtol=1e-3)
    np.testing.assert_allclose(r.Y1[-1], s.Y[0], rtol=1e-3)
    # a plain solve of (K - W^2 M + jW(C + W G)) Q = F with the plain rotor's matrices
    U = mass * e * W ** 2 * np.exp(1j * ph)
    F = np.zeros(rot.ndof, complex)
    F[rot.dof(st, "u")], F[rot.dof(st, "v")] = U, -1j * U
    Q = np.linalg.solve(rot.K - W ** 2 * rot.M + 1j * W * (rot.C + W * rot.G), F)
    for j, s_ in enumerate((16, 13)):
        X, Y = Q[rot.dof(s_, "u")], Q[rot.dof(s_, "v")]
        assert abs(r.X1[-1, j] / X - 1) < 1e-3 and abs(r.Y1[-1, j] / Y - 1) < 1e-3
        # amplitude and phase of the last revolution's x signal itself
        k = np.floor(r.angle / (2 * np.pi)).astype(int) == int(r.angle[-1] // (2 * np.pi)) - 1
        assert np.max(np.abs(r.x[k, j])) == pytest.approx(abs(X), rel=2e-3)
        assert r.envelope[-1, j] == pytest.approx(np.hypot(abs(X), abs(Y)) / math.sqrt(2), rel=2e-3)
        assert np.angle(r.X1[-1, j] / X) == pytest.approx(0.0, abs=1e-3)


# ----------------------------------------------------------------------------- Jeffcott rotor through its critical

def _jeffcott_reference(m, k, c, U, w0, w1, T):
    """Peak orbit radius and the speed there, by solve_ivp on the two equations written out."""
    a = (w1 - w0) / T

    def rhs(t, z):
        x, y, vx, vy = z
        om, th = w0 + a * t, w0 * t + 0.5 * a * t * t
        fx = U * (om * om * math.cos(th) + a * math.sin(th))
        fy = U * (om * om * math.sin(th) - a * math.cos(th))
        return [vx, vy, (fx - c * vx - k * x) / m, (fy - c * vy - k * y) / m]

    sol = solve_ivp(rhs, (0.0, T), [0.0, 0.0, 0.0, 0.0], method="DOP853", rtol=1e-10, atol=1e-14,
                    dense_output=True)
    t = np.linspace(0.0, T, 200001)
    z = sol.sol(t)
    r = np.hypot(z[0], z[1])
    i = int(np.argmax(r))
    return w0 + a * t[i], r[i]


@pytest.mark.parametrize("w0, w1", [(100.0, 300.0), (300.0, 100.0)], ids=["run-up", "coast-down"])
def test_jeffcott_through_its_critical_against_solve_ivp(w0, w1):
    m, k, zeta, U = 2.0, 8.0e4, 0.01, 1e-4                            # wn = 200 rad/s
    wn = math.sqrt(k / m)
    c = 2 * zeta * wn * m
    T = 2.0                                                           # 100 rad/s^2: alpha / wn^2 = 2.5e-3
    r = transient_run_up(jeffcott(m, k, c), (w0, w1), (1, U, 1.0), 1, duration=T, initial="rest")
    w_ref, a_ref = _jeffcott_reference(m, k, c, U, w0, w1, T)
    w_pk, a_pk = r.peak(0)
    assert a_pk == pytest.approx(a_ref, rel=1e-2)
    assert w_pk == pytest.approx(w_ref, rel=1e-2)
    # the steady peak: U / (2 m zeta sqrt(1 - zeta^2)) at wn / sqrt(1 - 2 zeta^2)
    w_st, a_st = r.steady_peak(0)
    assert a_st == pytest.approx(U / (2 * m * zeta * math.sqrt(1 - zeta ** 2)), rel=1e-3)
    assert a_pk < 0.8 * a_st                                          # lower ...
    if w1 > w0:
        assert w_pk > 1.02 * w_st                                     # ... and later in a run-up
    else:
        assert w_pk < 0.98 * w_st                                     # ... earlier in a coast-down


def test_gyroscopic_overhung_disk_against_solve_ivp():
    """An overhung disk (Ip > Id: strong gyroscopic coupling of tilt and bending) run through its forward
    critical from rest: the history and the peak against solve_ivp on the model's own four DOFs, with
    the speed-dependent velocity matrix C + Omega(t) G and the unbalance forces written out here."""
    from test_rotor_toolkit import OVERHUNG as o, CantileverTip
    rot = Rotor([DiskElement(1, o["m"], o["Ip"], o["Id"]), CantileverTip(1, o["EI"], o["L"]),
                 BearingElement(1, 0.0, 30.0)], name="overhung")
    w0, w1, T, U = 100.0, 400.0, 1.5, 1e-4                          # forward critical near 141 rad/s
    r = transient_run_up(rot, (w0, w1), (1, U, 1.0), 1, duration=T, initial="rest")
    M, C, K, G = rot.matrices()
    n, a = M.shape[0], (w1 - w0) / T
    iu, iv = rot.layout.dof(1, "u"), rot.layout.dof(1, "v")
    Minv = np.linalg.inv(M)

    def rhs(t, z):
        om, th = w0 + a * t, w0 * t + 0.5 * a * t * t
        f = np.zeros(n)
        f[iu] = U * (om * om * math.cos(th) + a * math.sin(th))
        f[iv] = U * (om * om * math.sin(th) - a * math.cos(th))
        return np.concatenate([z[n:], Minv @ (f - (C + om * G) @ z[n:] - K @ z[:n])])

    sol = solve_ivp(rhs, (0.0, T), np.zeros(2 * n), method="DOP853", rtol=1e-10, atol=1e-14,
                    dense_output=True)
    z = sol.sol(r.t)
    scale = np.max(np.abs(z[iu]))
    assert np.max(np.abs(r.x[:, 0] - z[iu])) < 2e-3 * scale
    assert np.max(np.abs(r.y[:, 0] - z[iv])) < 2e-3 * scale
    t = np.linspace(0.0, T, 300001)
    zz = sol.sol(t)
    i = int(np.argmax(np.hypot(zz[iu], zz[iv])))
    w_pk, a_pk = r.peak(0)
    assert a_pk == pytest.approx(np.hypot(zz[iu, i], zz[iv, i]), rel=1e-3)
    assert w_pk == pytest.approx(w0 + a * t[i], rel=1e-3)
    assert w_pk > r.steady_peak(0)[0] * 1.05


def test_slower_run_up_comes_closer_to_the_steady_peak():
    m, k, zeta, U = 2.0, 8.0e4, 0.05, 1e-4
    c = 2 * zeta * math.sqrt(k * m)
    peaks = [transient_run_up(jeffcott(m, k, c), (100.0, 300.0), (1, U, 1.0), 1, acceleration=a).peak(0)
             for a in (400.0, 100.0, 25.0)]
    w_st, a_st = transient_run_up(jeffcott(m, k, c), (100.0, 300.0), (1, U, 1.0), 1,
                                  acceleration=400.0).steady_peak(0)
    amps = [a for _, a in peaks]
    speeds = [w for w, _ in peaks]
    assert amps[0] < amps[1] < amps[2] < a_st
    assert speeds[0] > speeds[1] > speeds[2] > w_st


def test_steady_initial_state_starts_on_the_steady_response():
    m, k, zeta, U = 2.0, 8.0e4, 0.02, 1e-4
    c = 2 * zeta * math.sqrt(k * m)
    calls = []
    r = transient_run_up(jeffcott(m, k, c), (150.0, 150.0), (1, U, 1.0, 0.3), 1, duration=0.2,
                         progress=lambda stage, fraction: calls.append((stage, fraction)))
    assert [c_ for c_ in calls if c_[0] != "integrate"] == [("reduce", 0.0), ("reduce", 1.0), ("steady", 0.0),
                                                           ("steady", 1.0)]
    done = [f for s_, f in calls if s_ == "integrate"]
    assert done == sorted(done) and done[-1] == 1.0
    X = U * 150.0 ** 2 * np.exp(0.3j) / (k - m * 150.0 ** 2 + 1j * c * 150.0)
    np.testing.assert_allclose(r.X1[:, 0], X, rtol=2e-3)                 # from the first revolution on
    np.testing.assert_allclose(r.Y1[:, 0], -1j * X, rtol=2e-3)


# ----------------------------------------------------------------------------- the thesis rotor, bad input

def test_thesis_rotor_run_up_and_coast_down_move_the_peak():
    model = healthy_rotor()
    w = np.array([1000.0, 3000.0]) * np.pi / 30
    up = transient_run_up(model, w, (16, 1e-3, 0.01), 16, duration=2.0)
    down = transient_run_up(model, w[::-1], (16, 1e-3, 0.01), 16, duration=2.0)
    w_st, a_st = up.steady_peak(0)
    assert 2000 < w_st * 30 / np.pi < 2080                               # the first forward critical, 2037 rpm
    assert up.peak(0)[0] > 1.03 * w_st and down.peak(0)[0] < 0.97 * w_st
    assert up.peak(0)[1] < 0.7 * a_st and down.peak(0)[1] < 0.7 * a_st
    assert up.rev_speed[0] < up.rev_speed[-1] and down.rev_speed[0] > down.rev_speed[-1]
    d = up.to_dict()
    assert d["outputs"][0]["station"] == 16 and len(d["outputs"][0]["envelope_m"]) == up.rev_speed.size


def test_bad_input_is_named():
    j = jeffcott(2.0, 8.0e4, 10.0)
    ub = (1, 1e-4, 1.0)
    with pytest.raises(ModelError, match="duration must be positive"):
        transient_run_up(j, (100.0, 300.0), ub, 1, duration=-1.0)
    with pytest.raises(ModelError, match="unbalance station"):
        transient_run_up(j, (100.0, 300.0), (5, 1e-4, 1.0), 1, duration=1.0)
    with pytest.raises(ModelError, match="output station"):
        transient_run_up(j, (100.0, 300.0), ub, 7, duration=1.0)
    with pytest.raises(ModelError, match="steps"):
        transient_run_up(j, (100.0, 300.0), ub, 1, duration=1.0, steps=0)
    with pytest.raises(ModelError, match="duration .* or acceleration"):
        transient_run_up(j, (100.0, 300.0), ub, 1)
    with pytest.raises(ModelError, match="acceleration must be positive"):
        transient_run_up(j, (100.0, 300.0), ub, 1, acceleration=-5.0)
    with pytest.raises(ModelError, match="non-negative"):
        transient_run_up(j, (-100.0, 300.0), ub, 1, duration=1.0)
    with pytest.raises(ModelError, match="the mass"):
        transient_run_up(j, (100.0, 300.0), (1, "heavy", 1.0), 1, duration=1.0)
    with pytest.raises(ModelError, match="initial"):
        transient_run_up(j, (100.0, 300.0), ub, 1, duration=1.0, initial="moving")
    with pytest.raises(ModelError, match="two bending planes"):
        transient_run_up(Rotor([DiskElement(1, 1.0, 0.0, 1.0), BearingElement(1, 1e4)], planes=1),
                         (100.0, 300.0), ub, 1, duration=1.0)


# ----------------------------------------------------------------------------- figure and command line

def test_run_up_figure_draws_the_envelope_and_the_steady_response():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mutext import plots
    m, k, c, U = 2.0, 8.0e4, 16.0, 1e-4
    up = transient_run_up(jeffcott(m, k, c), (100.0, 300.0), (1, U, 1.0), 1, duration=0.5)
    down = transient_run_up(jeffcott(m, k, c), (300.0, 100.0), (1, U, 1.0), 1, duration=0.5)
    fig = plots.run_up_figure(up, others=[down], trace=False)
    lines = fig.axes[0].lines
    np.testing.assert_allclose(lines[0].get_ydata(), 1e6 * up.envelope[:, 0])
    np.testing.assert_allclose(lines[0].get_xdata(), up.rev_speed * 30 / np.pi)
    np.testing.assert_allclose(lines[2].get_ydata(), 1e6 * down.envelope[:, 0])
    np.testing.assert_allclose(lines[-1].get_ydata(), 1e6 * up.steady.semi_major[:, 0])
    assert lines[-1].get_linestyle() == "--"
    plt.close("all")


def test_cli_rotor_runup(capsys, tmp_path):
    import json

    from mutext.cli import main
    from mutext.rotor import data_path
    png = tmp_path / "runup.png"
    args = ["rotor", "runup", data_path("rotor.toml"), "--unbalance", "16:0.001:0.01", "--speeds", "1500:2500",
            "--duration", "0.5", "--output", "16"]
    assert main(args + ["--plot", str(png), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    o = out["outputs"][0]
    assert o["station"] == 16 and png.stat().st_size > 10000
    assert 2000 < o["steady_peak_speed_rpm"] < 2080 < o["peak_speed_rpm"]
    assert o["peak_radius_m"] < 0.7 * o["steady_peak_m"]
    assert out["unbalances"] == [{"station": 16, "kg_m": pytest.approx(1e-5), "phase_rad": 0.0}]
    assert main(args[:-1] + ["13,16"]) == 0
    text = capsys.readouterr().out
    assert "run-up" in text and "steady peak [rpm]" in text and "\n     13 " in text
    assert main(args[:4] + ["16:0.001", "--speeds", "1500:2500", "--duration", "1", "--output", "16"]) == 2
    assert "--unbalance" in capsys.readouterr().err
    assert main(args[:6] + ["2500", "--duration", "1", "--output", "16"]) == 2
    assert "--speeds" in capsys.readouterr().err
    assert main(args[:8] + ["-1", "--output", "16"]) == 2
    assert "--duration" in capsys.readouterr().err
    assert main(args[:10] + ["99"]) == 1
    assert "output station" in capsys.readouterr().err
