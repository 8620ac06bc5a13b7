"""Two-plane measurement and directional FRFs (forward/backward whirl, Lee 1993).

References are independent of the package: a rigid rotor on two bearings
written here in plain numpy (analytic whirl frequencies; a plain eigen-solve),
an anisotropic Jeffcott rotor solved in complex coordinates by hand, a
time signal sampled and correlated, and the package's own eigen-solve
(Campbell whirl labels) against peaks picked from FRFs.
"""
from __future__ import annotations

import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.response import FRF
from mutext.rotor import DirectionalFRF, PlanarFRF, data_path, directional_frf, load_model, loads_model, whirl_peaks

# rigid rotor: mass, transverse and polar inertia, bearing stiffness and damping
M_KG, ID, IP, K_B, C_B = 10.0, 0.1, 0.15, 1.0e6, 20.0


def rigid_rotor(za, zb, speed, kyy=None):
    """M, C + speed G, K of a rigid rotor, q = [x, y, ax, ay] (ax = dx/dz, ay = dy/dz at the centre
    of mass), bearings at z = za and z = zb.  Spin about +z: the tilt equations are
    Id ax'' + Ip W ay' = My and Id ay'' - Ip W ax' = -Mx (angular momentum Ip W along the axis)."""
    kyy = K_B if kyy is None else kyy
    M = np.diag([M_KG, M_KG, ID, ID])
    K = np.zeros((4, 4))
    C = np.zeros((4, 4))
    for z in (za, zb):
        for plane, k in ((0, K_B), (1, kyy)):
            t = np.zeros(4)
            t[plane], t[plane + 2] = 1.0, z          # displacement of the shaft at the bearing
            K += k * np.outer(t, t)
            C += C_B * np.outer(t, t)
    G = np.zeros((4, 4))
    G[2, 3], G[3, 2] = IP, -IP
    return M, C + speed * G, K


def planar_at(matrices, z, freq_hz):
    """H[i, j, k] between force and displacement at axial position z, x/y planes (plain solves)."""
    M, D, K = matrices
    T = np.array([[1.0, 0.0, z, 0.0], [0.0, 1.0, 0.0, z]])
    H = np.empty((2, 2, freq_hz.size), complex)
    for i, w in enumerate(2 * np.pi * freq_hz):
        H[:, :, i] = T @ np.linalg.solve(K - w * w * M + 1j * w * D, T.T)
    return H


def eigen_whirl(matrices):
    """Damped natural frequencies [Hz] and whirl sense from a plain eigen-solve of the first-order form."""
    M, D, K = matrices
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])
    lam, V = np.linalg.eig(A)
    keep = lam.imag > 0
    out = []
    for lk, v in zip(lam[keep], V[:n, keep].T):
        u, w = v[[0, 2]], v[[1, 3]]                 # x plane (x, ax) and y plane (y, ay)
        sense = -2 * np.sum(np.imag(np.conj(u) * w)) / np.sum(np.abs(u) ** 2 + np.abs(w) ** 2)
        out.append((lk.imag / (2 * np.pi), "forward" if sense > 0 else "backward"))
    return sorted(out)


def senses(peaks):
    return {s: sorted(p.frequency_hz for p in peaks if p.direction == s) for s in ("forward", "backward")}


F = np.arange(20.0, 250.0, 0.1)


def test_formulas_against_a_sampled_circular_force():
    """H_pp is the e^{jwt} part of p = x + jy under the forward circular force f_x = cos wt, f_y = sin wt;
    H_bp (p-bar p) the e^{jwt} part of conj(p) -- from time samples of the real responses."""
    rng = np.random.default_rng(3)
    H = rng.standard_normal((2, 2, 1)) + 1j * rng.standard_normal((2, 2, 1))
    d = directional_frf(H, [7.0])
    w = 2 * np.pi * 7.0
    t = np.linspace(0.0, 1.0 / 7.0, 64, endpoint=False)      # one period
    X = H[0, 0, 0] * 1.0 + H[0, 1, 0] * (-1j)                 # complex amplitudes of f_x = 1, f_y = -j
    Y = H[1, 0, 0] * 1.0 + H[1, 1, 0] * (-1j)
    x, y = np.real(X * np.exp(1j * w * t)), np.real(Y * np.exp(1j * w * t))
    p = x + 1j * y
    assert np.mean(p * np.exp(-1j * w * t)) == pytest.approx(d.pp[0], abs=1e-12)
    assert np.mean(np.conj(p) * np.exp(-1j * w * t)) == pytest.approx(d.bp[0], abs=1e-12)
    # the inverse recovers the planar matrix
    assert np.allclose(d.planar(), H, rtol=0, atol=1e-14)


def test_rigid_rotor_whirl_frequencies_analytic():
    """Bearings symmetric about the centre of mass: the cylindrical mode sqrt(2k/m) whirls both ways at one
    frequency; the conical mode splits into Id w^2 -+ Ip W w - k_t = 0 (k_t = 2 k a^2)."""
    a, speed = 0.2, 300.0
    mats = rigid_rotor(-a, a, speed)
    d = directional_frf(planar_at(mats, a, F), F)
    kt = 2 * K_B * a * a
    root = np.sqrt((IP * speed) ** 2 + 4 * ID * kt)
    wt = np.sqrt(2 * K_B / M_KG) / (2 * np.pi)
    wf, wb = (IP * speed + root) / (2 * ID) / (2 * np.pi), (-IP * speed + root) / (2 * ID) / (2 * np.pi)
    got = senses(whirl_peaks(d))
    assert got["forward"] == pytest.approx(sorted([wt, wf]), rel=1e-3)
    assert got["backward"] == pytest.approx(sorted([wt, wb]), rel=1e-3)
    # isotropic: no reverse dFRF, to round-off
    assert np.max(np.abs(d.pb)) <= 1e-12 * np.max(np.abs(d.pp))
    assert np.max(np.abs(d.bp)) <= 1e-12 * np.max(np.abs(d.pp))


def test_rigid_rotor_peaks_match_a_plain_eigen_solve():
    """Bearings not symmetric: translation and tilt couple; every mode in the band is one dFRF peak of its
    own sense (the forward ones in H_pp, the backward in H_bb)."""
    mats = rigid_rotor(-0.15, 0.3, 400.0)
    modes = [(f, s) for f, s in eigen_whirl(mats) if F[0] < f < F[-1]]
    assert {s for _, s in modes} == {"forward", "backward"}
    d = directional_frf(planar_at(mats, 0.3, F), F)
    got = senses(whirl_peaks(d))
    for s in ("forward", "backward"):
        assert got[s] == pytest.approx(sorted(f for f, t in modes if t == s), rel=1e-3)
    assert np.max(np.abs(d.pb)) <= 1e-12 * np.max(np.abs(d.pp))


def test_at_standstill_forward_and_backward_dfrfs_agree():
    d = directional_frf(planar_at(rigid_rotor(-0.15, 0.3, 0.0), 0.3, F), F)
    assert np.max(np.abs(d.pp - d.bb)) <= 1e-12 * np.max(np.abs(d.pp))
    d = directional_frf(planar_at(rigid_rotor(-0.15, 0.3, 400.0), 0.3, F), F)
    assert np.max(np.abs(d.pp - d.bb)) > 0.1 * np.max(np.abs(d.pp))      # at speed they differ


def test_anisotropic_jeffcott_in_complex_coordinates():
    """m p'' + c p' + k p + dk conj(p) = f_p (k = (kx + ky)/2, dk = (kx - ky)/2), solved by hand for
    f_p = e^{jwt}: p = P e^{jwt} + Q e^{-jwt} gives H_pp = P = a/(a^2 - dk^2), H_bp = conj(Q) = -dk/(a^2 - dk^2),
    a = k - m w^2 + j c w."""
    m, c, kx, ky = 2.0, 8.0, 4.0e5, 2.5e5
    w = 2 * np.pi * F
    H = np.zeros((2, 2, F.size), complex)
    H[0, 0] = 1 / (kx - m * w ** 2 + 1j * c * w)
    H[1, 1] = 1 / (ky - m * w ** 2 + 1j * c * w)
    d = directional_frf(H, F)
    k, dk = (kx + ky) / 2, (kx - ky) / 2
    a = k - m * w ** 2 + 1j * c * w
    assert np.allclose(d.pp, a / (a * a - dk * dk), rtol=1e-10, atol=0)
    assert np.allclose(d.bp, -dk / (a * a - dk * dk), rtol=1e-10, atol=0)
    assert np.max(np.abs(d.pb)) > 0.1 * np.max(np.abs(d.pp))
    # a straight-line (planar) mode is half forward, half backward: both dFRFs peak, the index is ~0
    idx = [p.index for p in whirl_peaks(d)]
    assert idx and max(abs(i) for i in idx) < 0.05


def test_anisotropic_bearing_of_the_rigid_rotor_gives_a_reverse_dfrf():
    iso = directional_frf(planar_at(rigid_rotor(-0.15, 0.3, 400.0), 0.3, F), F)
    ani = directional_frf(planar_at(rigid_rotor(-0.15, 0.3, 400.0, kyy=0.6 * K_B), 0.3, F), F)
    ratio = np.max(np.abs(ani.pb)) / np.max(np.abs(ani.pp))
    assert ratio > 0.05 and np.max(np.abs(iso.pb)) <= 1e-12 * np.max(np.abs(iso.pp))


# ----------------------------------------------------------------------------- the package's rotor

@pytest.fixture(scope="module")
def thesis():
    return load_model(data_path("rotor.toml"))


def test_rig_planar_matrix_keeps_the_one_plane_channels(thesis, tmp_path):
    from mutext.rig import measure_rotor
    f = np.arange(20.0, 225.0, 0.5)
    P = measure_rotor(thesis, "i12", "x13", f, planes="xy")
    assert isinstance(P, PlanarFRF)
    assert np.array_equal(P["xx"].response, measure_rotor(thesis, "i12", "x13", f).response)
    assert np.array_equal(P["yx"].response, measure_rotor(thesis, "i12", "y13", f).response)
    assert [[c.label for c in r] for r in P.channels] == [["i12->x13", "i12y->x13"], ["i12->y13", "i12y->y13"]]
    assert P["xy"].input_direction == "y" and P["xy"].output_direction == "x" and P.speed_hz == 10.0
    # y excitation: the file's rotor with a y force port at the exciter, times its 40 N/A
    text = open(data_path("rotor.toml")).read() + '\n[[force]]\nstation = 12\ndirection = "y"\n'
    H = loads_model(text, base_dir=data_path("")).frf(f, inputs=["F12y"], outputs=["x13", "y13"])
    scale = np.max(np.abs(P["yy"].response))
    assert np.max(np.abs(P["xy"].response - 40.0 * H("x13", "F12y"))) <= 1e-9 * scale
    assert np.max(np.abs(P["yy"].response - 40.0 * H("y13", "F12y"))) <= 1e-9 * scale
    # the four channels as FRFs (as read from four files) give the same dFRFs
    from mutext.rig import read_frf, write_frf
    path = tmp_path / "xy.csv"
    write_frf(path, P["xy"])
    back = read_frf(path)
    assert (back.input_direction, back.output_direction) == ("y", "x")
    d = directional_frf([[P["xx"], back], [P["yx"], P["yy"]]])
    assert np.allclose(d.pp, P.directional().pp, rtol=1e-12, atol=0)
    # an isotropic rotor: H_yy = H_xx, H_xy = -H_yx
    assert np.max(np.abs(P["yy"].response - P["xx"].response)) <= 1e-8 * scale
    assert np.max(np.abs(P["xy"].response + P["yx"].response)) <= 1e-8 * scale


def test_thesis_rotor_dfrf_peaks_agree_with_the_campbell_whirl_labels(thesis):
    """Modes and whirl labels of the package's eigen-solve at 50 Hz running speed against the peaks of the
    forward and backward dFRFs measured in two planes (station 12 exciter, station 13 sensor)."""
    from mutext.rig import measure_rotor
    speed_hz = 50.0
    f = np.arange(20.0, 225.0, 0.05)
    d = measure_rotor(thesis, "i12", "x13", f, planes="xy", speed_hz=speed_hz).directional()
    assert d.speed_hz == speed_hz
    m = thesis.modes(speed=2 * np.pi * speed_hz, n=8)
    modes = [(fr, s) for fr, s in zip(m.frequencies_hz, m.whirl_direction()) if f[0] < fr < f[-1]]
    assert {s for _, s in modes} == {"forward", "backward"} and len(modes) == 4
    got = senses(whirl_peaks(d))
    for s in ("forward", "backward"):
        # the peak of |H| lies O(zeta^2) below the damped frequency (1 % modal damping)
        assert got[s] == pytest.approx(sorted(fr for fr, t in modes if t == s), rel=3e-4)
    assert np.max(np.abs(d.pb)) <= 1e-8 * np.max(np.abs(d.pp))     # isotropic bearings


def test_thesis_rotor_anisotropic_bearing_gives_a_reverse_dfrf(thesis):
    from mutext.rig import measure_rotor
    bearing = "station = 29\nstiffness = 1.0e7       # N/m"
    text = open(data_path("rotor.toml")).read().replace(bearing, bearing + "\nstiffness_y = 0.5e7")
    assert "stiffness_y" in text
    ani = loads_model(text, base_dir=data_path(""))
    f = np.arange(20.0, 225.0, 0.5)
    d = measure_rotor(ani, "i12", "x13", f, planes="xy").directional()
    assert np.max(np.abs(d.pb)) > 0.05 * np.max(np.abs(d.pp))


def test_planar_measurement_with_noise_and_station_numbers(thesis):
    from mutext.rig import measure_rotor
    f = np.arange(100.0, 110.0, 1.0)
    P = measure_rotor(thesis, 15, 24, f, planes="xy", noise=0.01, rng=1)
    exact = measure_rotor(thesis, "F15", "x24", f, planes="xy")
    assert P["xx"].input_name == "F15" and P["yy"].output_name == "y24" and P["xx"].metadata["noise_relative"]
    err = np.abs(P.H - exact.H) / np.abs(exact.H)
    assert 0 < err.max() < 0.1


def test_breathing_crack_planar_measurement_uses_the_analyzer():
    """A rotor with a breathing crack at speed: the planar matrix comes from the same analyzer as the one
    channel (H_xx agrees to the reduction's error), and the crack, an anisotropy turning with the shaft,
    couples p and conj(p)."""
    from mutext.examples.cracked_rotor import cracked_rotor
    from mutext.rig import measure_rotor
    r = cracked_rotor()
    f = np.arange(30.0, 40.0, 0.5)
    P = measure_rotor(r, "i12", "x13", f, planes="xy")
    one = measure_rotor(r, "i12", "x13", f)
    assert "harmonic balance" in P["yy"].metadata["analyzer"]
    tol = 20 * float(P["xx"].metadata["reduction_error"])
    assert np.max(np.abs(P["xx"].response - one.response)) <= tol * np.max(np.abs(one.response))
    d = P.directional()
    assert np.max(np.abs(d.pb)) > 0.01 * np.max(np.abs(d.pp))


# ----------------------------------------------------------------------------- bad input

def test_bad_input_is_named(thesis):
    from mutext.rig import measure_rotor
    with pytest.raises(ModelError, match="planes"):
        measure_rotor(thesis, "i12", "x13", [50.0], planes="z")
    with pytest.raises(ModelError, match="combination"):
        measure_rotor(thesis, "i12", "x13", [50.0], planes="xy", combination=(1,))
    with pytest.raises(ModelError, match="unknown input"):
        measure_rotor(thesis, "i99", "x13", [50.0], planes="xy")
    with pytest.raises(ModelError, match="outside"):
        measure_rotor(thesis, "i12", 31, [50.0], planes="xy")
    with pytest.raises(ModelError, match="shape"):
        directional_frf(np.zeros((2, 3, 4)), np.arange(1.0, 5.0))
    with pytest.raises(ModelError, match="freq_hz"):
        directional_frf(np.zeros((2, 2, 4)))
    with pytest.raises(ModelError, match="DirectionalFRF"):
        whirl_peaks(np.zeros(3))
    f = np.array([1.0, 2.0])
    one = FRF(f, [1, 1], 1, 1)
    with pytest.raises(ModelError, match="H_xy"):
        PlanarFRF(((one, one), (one, one)))
    assert isinstance(DirectionalFRF(f, f, f, f, f).two_sided()[0], np.ndarray)


def test_two_sided_puts_backward_modes_at_negative_frequency():
    f = np.linspace(5.0, 15.0, 201)
    h = lambda fn: 1 / (fn ** 2 - f ** 2 + 0.02j * fn * f)  # noqa: E731
    fs, hs = DirectionalFRF(f, h(10.0), h(12.0), 0 * f, 0 * f).two_sided()
    assert np.all(np.diff(fs) > 0) and fs.size == 2 * f.size
    neg = fs < 0
    assert fs[neg][np.argmax(np.abs(hs[neg]))] == pytest.approx(-12.0, abs=0.05)
    assert fs[~neg][np.argmax(np.abs(hs[~neg]))] == pytest.approx(10.0, abs=0.05)
