"""Rotor finite elements: element matrices, beams against analytic solutions (with mesh
convergence), assembled-matrix properties, Friswell et al. example 5.9.1, the thesis rotor,
symbolic derivatives, FRF/state-space consistency, the local-flexibility (crack) hook, ROSS."""
import json
import math

import casadi as ca
import numpy as np
import pytest
import scipy.linalg as sla

from mutext.errors import ModelError
from mutext.examples.friswell import FREQUENCIES_0_RPM as FRISWELL_0
from mutext.examples.friswell import FREQUENCIES_4000_RPM as FRISWELL_4000
from mutext.examples.friswell import rotor as friswell_rotor
from mutext.lti import freqresp
from mutext.rotor import (BearingElement, DiskElement, ExciterElement, InputPort, OutputPort, Param,
                          ProportionalDamping, Rotor, ShaftElement, ShaftFlexibility, data_path, load_model,
                          loads_model, shaft_stiffness_with_compliance)
from mutext.rotor.elements import (Layout, cowper_shear_coefficient, section_properties,
                                   timoshenko_plane_matrices, timoshenko_shape_functions)
from mutext.rotor.analytic import beta_l, euler_bernoulli_frequency, timoshenko_pinned_frequency
from mutext.rotor.units import rpm_to_rad_s

STEEL = dict(E=2.1e11, rho=7800.0, nu=0.3)


def dm(x):
    return np.asarray(ca.DM(x).full())


# ----------------------------------------------------------------------------- element matrices

@pytest.mark.parametrize("do, di, L", [(0.05, 0.0, 0.25), (0.2, 0.12, 0.1), (0.01, 0.0, 1.0)])
def test_closed_form_matrices_equal_integrated_shape_functions(do, di, L):
    E, G, rho = 2.1e11, 8.1e10, 7800.0
    kappa = cowper_shear_coefficient(E / (2 * G) - 1, do, di)
    A, I = section_properties(do, di)
    phi = 12 * E * I / (kappa * G * A * L**2)
    Mt, Mr, K = (dm(X) for X in timoshenko_plane_matrices(E, G, rho, L, do, di, kappa))
    xi = ca.SX.sym("xi")
    N, P = timoshenko_shape_functions(xi, L, phi)
    N, P = ca.vertcat(*N), ca.vertcat(*P)
    f = ca.Function("f", [xi], [N, P, ca.jacobian(N, xi) / L, ca.jacobian(P, xi) / L])
    x, wq = np.polynomial.legendre.leggauss(8)
    x, wq = 0.5 * (x + 1), 0.5 * wq * L
    Mt_q, Mr_q, K_q = np.zeros((4, 4)), np.zeros((4, 4)), np.zeros((4, 4))
    for xk, wk in zip(x, wq):
        n, p, dn, dp = (dm(v).ravel() for v in f(xk))
        Mt_q += wk * rho * A * np.outer(n, n)
        Mr_q += wk * rho * I * np.outer(p, p)
        gam = dn - p                       # shear strain
        K_q += wk * (E * I * np.outer(dp, dp) + kappa * G * A * np.outer(gam, gam))
    for X, Y in ((Mt, Mt_q), (Mr, Mr_q), (K, K_q)):
        np.testing.assert_allclose(X, Y, rtol=1e-11, atol=1e-12 * np.abs(Y).max())
    # the shape functions interpolate the nodal values
    n0, p0, _, _ = (dm(v).ravel() for v in f(0.0))
    n1, p1, _, _ = (dm(v).ravel() for v in f(1.0))
    np.testing.assert_allclose(np.vstack([n0, p0, n1, p1]), np.eye(4), atol=1e-12)


def test_cowper_coefficient_solid_is_friswell():
    nu = 211 / (2 * 81.2) - 1
    assert math.isclose(cowper_shear_coefficient(nu), 6 * (1 + nu) / (7 + 6 * nu))
    assert math.isclose(cowper_shear_coefficient(nu, 0.05, 0.0), 6 * (1 + nu) / (7 + 6 * nu))
    assert cowper_shear_coefficient(nu, 0.05, 0.04) < cowper_shear_coefficient(nu, 0.05, 0.0)


def test_element_matrices_are_casadi_expressions_of_parameters():
    el = ShaftElement(1, 0.3, 0.04, 0.0, **STEEL)
    from mutext.rotor.elements import ParameterSet
    ps = ParameterSet()
    el.declare(ps)
    assert ps.names == ["shaft1.L", "shaft1.do", "shaft1.di", "shaft1.E", "shaft1.rho", "shaft1.nu"]
    K = el.stiffness_matrix(ps.symbols, Layout("rotor", 2))
    assert isinstance(K, ca.SX) and K.shape == (8, 8)
    dK = ca.jacobian(ca.vec(K), ps.symbols["shaft1.E"])
    assert not ca.DM(ca.Function("d", [ps.vector], [dK])(np.array([0.3, 0.04, 0, 2.1e11, 7800, 0.3]))).is_zero()


# ----------------------------------------------------------------------------- beams

def beam(n_el, L, d, planes=1, **kw):
    mat = {k: Param(k, v) for k, v in STEEL.items()}
    return Rotor([ShaftElement(i + 1, L / n_el, d, 0.0, **mat, **kw) for i in range(n_el)], planes=planes)


def eb_omega(mode, L, d, support="pinned"):
    """Exact Euler-Bernoulli frequency [rad/s] of a steel beam of solid section ``d``."""
    return euler_bernoulli_frequency(mode, L, STEEL["E"], STEEL["rho"], *section_properties(d, 0.0), support)


def timoshenko_pinned_omega(n, L, d):
    """Exact pinned-pinned Timoshenko frequency (lower branch) of mode n."""
    E, nu = STEEL["E"], STEEL["nu"]
    return timoshenko_pinned_frequency(n, L, E, E / (2 * (1 + nu)), STEEL["rho"], *section_properties(d, 0.0),
                                       kappa=cowper_shear_coefficient(nu))


def test_beam_references_against_published_values():
    # beta L to the digits of Blevins' tables; the Timoshenko beam tends to Euler-Bernoulli when slender
    np.testing.assert_allclose([beta_l("free", n) for n in (1, 2, 3)], [4.730040745, 7.853204624, 10.99560784],
                               rtol=1e-9)
    np.testing.assert_allclose([beta_l("cantilever", n) for n in (1, 2)], [1.875104069, 4.694091133], rtol=1e-9)
    assert timoshenko_pinned_omega(1, 10.0, 0.01) == pytest.approx(eb_omega(1, 10.0, 0.01), rel=3e-6)
    assert timoshenko_pinned_omega(1, 10.0, 0.01) < eb_omega(1, 10.0, 0.01)     # shear and rotary inertia lower it
    with pytest.raises(ModelError, match="support"):
        beta_l("clamped-clamped", 1)
    with pytest.raises(ModelError, match="positive integer"):
        beta_l("free", 0)


def pinned(r):
    M, _, K, _ = r.matrices()
    keep = np.setdiff1d(np.arange(r.ndof), [r.layout.dof(1, "u"), r.layout.dof(r.n_stations, "u")])
    lam = sla.eigvalsh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)])
    return np.sqrt(lam)


def test_free_free_euler_bernoulli_convergence():
    L, d = 1.0, 0.01                      # slender: L/d = 100
    exact = np.array([eb_omega(n, L, d, "free") for n in (1, 2, 3)])
    errs = []
    for n in (2, 4, 8, 16):
        w = 2 * np.pi * beam(n, L, d, shear=False, rotary_inertia=False).natural_frequencies()[:3]
        errs.append(np.abs(w / exact - 1))
    errs = np.array(errs)
    # error falls with every refinement, as h^4 (cubic elements: a factor ~16 per halving), each mode
    assert np.all(np.diff(errs, axis=0) < 0), errs
    assert np.all(errs[-2] / errs[-1] > 10), errs
    assert errs[-1].max() < 3e-4 and errs[-1, 0] < 1e-5
    # the Timoshenko element on the slender beam is within 0.2 % of Euler-Bernoulli
    w_t = 2 * np.pi * beam(16, L, d).natural_frequencies()[:3]
    np.testing.assert_allclose(w_t, exact, rtol=2e-3)
    assert np.all(w_t < exact * (1 + 1e-6))      # shear and rotary inertia only lower frequencies


@pytest.mark.parametrize("planes", [1, 2])
def test_free_free_has_exactly_two_rigid_modes_per_plane(planes):
    r = beam(6, 1.0, 0.05, planes=planes)
    M, C, K, G = r.matrices()
    lam = sla.eigvalsh(K, M)
    zero = np.abs(lam) < 1e-9 * lam.max()
    assert zero.sum() == 2 * planes
    assert np.all(lam[~zero] > 0)
    assert r.natural_frequencies().size == r.ndof - 2 * planes


def test_pinned_pinned_euler_bernoulli_and_thick_timoshenko_convergence():
    # slender, Euler-Bernoulli element: (n pi)^2
    L, d = 1.0, 0.01
    ex_eb = np.array([eb_omega(n, L, d) for n in (1, 2, 3)])
    err_eb = [np.abs(pinned(beam(n, L, d, shear=False, rotary_inertia=False))[:3] / ex_eb - 1) for n in (3, 6, 12)]
    assert np.all(np.diff(err_eb, axis=0) < 0) and err_eb[-1].max() < 5e-4 and err_eb[-1][0] < 1e-5
    # thick (L/d = 5), Timoshenko element: exact Timoshenko frequencies
    L, d = 1.0, 0.2
    ex_t = np.array([timoshenko_pinned_omega(n, L, d) for n in (1, 2, 3)])
    ex_eb = np.array([eb_omega(n, L, d) for n in (1, 2, 3)])
    assert np.all(ex_t[1:] < 0.95 * ex_eb[1:]) and ex_t[0] < 0.97 * ex_eb[0]   # shear matters here
    err_t = np.array([np.abs(pinned(beam(n, L, d))[:3] / ex_t - 1) for n in (4, 8, 16, 32)])
    assert np.all(np.diff(err_t, axis=0) < 0), err_t
    # second order (a factor ~4 per halving): the interdependent-interpolation element has a
    # constant shear strain per element, which limits the rate once shear energy matters
    assert np.all(err_t[:-1] / err_t[1:] > 3.5), err_t
    assert err_t[-1, 0] < 5e-5 and err_t[-1].max() < 2e-3
    # and the Euler-Bernoulli element is far off for the thick beam: the shear terms do the work
    assert np.abs(pinned(beam(32, L, d, shear=False, rotary_inertia=False))[:3] / ex_t - 1).min() > 0.03


# ----------------------------------------------------------------------------- Friswell example 5.9.1

FRISWELL_TOML = """
name = "Friswell et al. example 5.9.1"
[shaft]
shear_modulus = 81.2e9
""" + "".join("""
[[station]]
length = 0.25
outer_diameter = 0.05
youngs_modulus = 211e9
density = 7810
""" for _ in range(6)) + """
[[station]]
[[disk]]
station = 3
width = 0.07
outer_diameter = 0.28
inner_diameter = 0.05
density = 7810
[[disk]]
station = 5
width = 0.07
outer_diameter = 0.35
inner_diameter = 0.05
density = 7810
[[bearing]]
station = 1
stiffness = 1e6
[[bearing]]
station = 7
stiffness = 1e6
"""


def test_friswell_example_5_9_1():
    r = friswell_rotor()
    # disk data: m = rho pi (Do^2 - Di^2) h / 4, Ip = m (Do^2 + Di^2)/8, Id = Ip/2 + m h^2/12
    d1 = r.element_by_name["disk3"]
    assert math.isclose(d1.nominal("m"), 32.59, rel_tol=2e-4)
    assert math.isclose(d1.nominal("Ip"), 32.59 * (0.28**2 + 0.05**2) / 8, rel_tol=2e-4)
    for rpm, ref in ((0, FRISWELL_0), (4000, FRISWELL_4000)):
        md = r.modes(speed=rpm_to_rad_s(rpm), n=6)
        np.testing.assert_allclose(md.omega, ref, rtol=1e-3)
        if rpm:
            assert md.whirl_direction() == ["backward", "forward"] * 3
    # the same rotor from a TOML file with inline stations
    t = loads_model(FRISWELL_TOML)
    np.testing.assert_allclose(2 * np.pi * t.natural_frequencies(speed=rpm_to_rad_s(4000), n=6),
                               FRISWELL_4000, rtol=1e-3)


def test_campbell_forward_rises_backward_falls():
    r = friswell_rotor()
    cb = r.campbell(rpm_to_rad_s(np.array([0.0, 2000.0, 4000.0])), n_modes=4)
    fw = cb.frequencies_hz[:, 3]   # second forward mode
    bw = cb.frequencies_hz[:, 2]
    assert fw[0] < fw[1] < fw[2] and bw[0] > bw[1] > bw[2]
    assert np.all(cb.whirl[1:, 3] > 0.5) and np.all(cb.whirl[1:, 2] < -0.5)


# ----------------------------------------------------------------------------- assembled matrices

def test_assembled_matrix_properties_thesis_rotor():
    r = load_model(data_path("rotor.toml"))
    M, C, K, G = r.matrices()
    for X in (M, C, K):
        np.testing.assert_allclose(X, X.T, rtol=0, atol=1e-12 * np.abs(X).max())
    np.testing.assert_allclose(G, -G.T, rtol=0, atol=1e-14 * np.abs(G).max())
    np.linalg.cholesky(M)                                  # positive definite
    assert sla.eigvalsh(K, M).min() > 0                    # on bearings: positive definite
    assert np.all(sla.eigvalsh(C) > -1e-9 * np.abs(C).max())
    # without bearings (free-free) K has exactly 4 rigid-body modes (2 per plane)
    _, _, K0, _, _ = r.evaluate({"bearing2.k": 0.0, "bearing29.k": 0.0})
    lam = sla.eigvalsh(K0, M)
    assert (np.abs(lam) < 1e-9 * lam.max()).sum() == 4
    # modal damping: every mode of the non-rotating rotor gets the ratio of the file (1 %)
    md = r.modes(speed=0.0, n=8)
    np.testing.assert_allclose(md.damping_ratio, 0.01, rtol=1e-6)


def test_thesis_rotor_first_resonances_in_measured_band():
    r = load_model(data_path("rotor.toml"))
    f = r.natural_frequencies(n=4)             # two whirl pairs at 600 rpm
    assert np.all((20 < f) & (f < 225)), f
    f1 = load_model(data_path("rotor.toml")).natural_frequencies(speed=0.0, n=4)
    assert 30 < f1[0] < 40 and 185 < f1[2] < 200          # 33.9 Hz and 193 Hz
    fr = np.linspace(20, 225, 411)
    H = np.abs(r.frf(fr, inputs=["i12"], outputs=["x13"])("x13", "i12"))
    i = np.arange(1, fr.size - 1)
    peaks = fr[i[(H[i] > H[i - 1]) & (H[i] >= H[i + 1])]]
    assert len(peaks) >= 2 and peaks[0] < 40 and 185 < peaks[1] < 200


def test_symbolic_functions_and_exact_derivatives():
    r = load_model(data_path("rotor.toml"))
    p0 = r.values()
    M, C, K, G = r.matrices()
    np.testing.assert_array_equal(dm(r.functions["K"](p0)), K)
    np.testing.assert_array_equal(dm(r.functions["M"](p0)), M)
    # d K / d k_bearing is the unit pattern on the bearing's u and v DOFs
    j = r.parameter_names.index("bearing2.k")
    dK = dm(ca.Function("dK", [r.p], [ca.jacobian(ca.vec(r.symbolic["K"]), r.p[j])])(p0)).reshape(r.ndof, r.ndof)
    expect = np.zeros((r.ndof, r.ndof))
    for lab in ("u", "v"):
        d = r.layout.dof(2, lab)
        expect[d, d] = 1.0
    np.testing.assert_array_equal(dK, expect)
    # d M / d rho against a central difference
    j = r.parameter_names.index("rho")
    dM = dm(ca.Function("dM", [r.p], [ca.jacobian(ca.vec(r.symbolic["M"]), r.p[j])])(p0)).reshape(r.ndof, r.ndof)
    h = 1e-3 * p0[j]
    fd = (r.evaluate({"rho": p0[j] + h})[0] - r.evaluate({"rho": p0[j] - h})[0]) / (2 * h)
    np.testing.assert_allclose(dM, fd, rtol=1e-6, atol=1e-9 * np.abs(fd).max())
    # input matrix: the exciter current enters through ki at u12
    B = r.input_matrix({"exciter12.ki": 55.0})
    assert B[r.layout.dof(12, "u"), r.input_names.index("i12")] == 55.0


def test_frf_equals_state_space_response():
    r = load_model(data_path("rotor.toml"))
    sys = r.state_space(inputs=["i12", "F15"], outputs=["x13", "y13"])
    assert sys.input_labels == ["i12", "F15"] and sys.output_labels == ["x13", "y13"]
    f = np.array([25.0, 33.9, 120.0, 193.0, 220.0])
    H = r.frf(f, inputs=["i12", "F15"], outputs=["x13", "y13"]).H
    np.testing.assert_allclose(freqresp(sys, 2 * np.pi * f), H, rtol=1e-6, atol=1e-9 * np.abs(H).max())
    # gyroscopic cross-coupling: at speed the y sensor sees the x exciter, at standstill it does not
    H0 = r.frf(f, inputs=["i12"], outputs=["y13"], speed=0.0).H
    assert np.abs(H0).max() < 1e-12 * np.abs(H[0, 0]).max() and np.abs(H[1, 0]).max() > 1e-4 * np.abs(H[0, 0]).max()


def test_proportional_damping_ratio():
    base = friswell_rotor()
    r = Rotor(base.elements, damping=ProportionalDamping(alpha=2.0, beta=1e-5))
    md = r.modes(speed=0.0, n=6)
    wn = np.abs(md.eigenvalues)
    np.testing.assert_allclose(md.damping_ratio, 2.0 / (2 * wn) + 1e-5 * wn / 2, rtol=1e-8)
    assert "damping.alpha" in r.parameter_names


def test_exciter_negative_stiffness_and_ports():
    base = friswell_rotor()
    ex = ExciterElement(4, ki=100.0, kx=2e5, port="i4")
    r = Rotor(base.elements + [ex], outputs=[OutputPort("x4", 4, "u")], inputs=[InputPort("F4", 4, "x")])
    K0 = base.matrices().K
    K = r.matrices().K
    d = r.layout.dof(4, "u")
    assert K[d, d] == pytest.approx(K0[d, d] - 2e5)
    H = r.frf([0.0], inputs=["i4", "F4"], outputs=["x4"]).H[0, :, 0]
    assert H[0] == pytest.approx(100.0 * H[1])               # current in A = ki newtons


def test_model_construction_errors():
    with pytest.raises(ModelError, match="inner diameter"):
        ShaftElement(1, 0.1, 0.05, 0.05, **STEEL)
    with pytest.raises(ModelError, match="exactly one of nu"):
        ShaftElement(1, 0.1, 0.05, E=2e11, rho=7800)
    with pytest.raises(ModelError, match="must be positive"):
        ShaftElement(1, -0.1, 0.05, **STEEL)
    els = [ShaftElement(1, 0.1, 0.05, **STEEL), ShaftElement(2, 0.1, 0.05, **STEEL)]
    with pytest.raises(ModelError, match="two elements are named 'bearing1'"):
        Rotor(els + [BearingElement(1, 1e6), BearingElement(1, 2e6)])
    with pytest.raises(ModelError, match="outside 1..3"):
        Rotor(els, outputs=[OutputPort("x9", 9)])
    with pytest.raises(ModelError, match="outside 1..3"):
        Rotor(els + [BearingElement(5, 1e6)], n_stations=3)
    with pytest.raises(ModelError, match="direction 'v' does not exist in a 'plane'"):
        Rotor(els, planes=1, outputs=[OutputPort("y2", 2, "v")])
    with pytest.raises(ModelError, match="declared twice with different nominal values"):
        Rotor([ShaftElement(1, 0.1, 0.05, E=Param("E", 2e11), rho=7800, nu=0.3),
               ShaftElement(2, 0.1, 0.05, E=Param("E", 1e11), rho=7800, nu=0.3)])
    with pytest.raises(ModelError, match="two shaft elements start at station 1"):
        Rotor([ShaftElement(1, 0.1, 0.05, **STEEL), ShaftElement(1, 0.1, 0.05, name="other", **STEEL)])
    with pytest.raises(ModelError, match="nonzero speed needs a two-plane"):
        Rotor(els, planes=1).modes(speed=10.0)
    with pytest.raises(ModelError, match="unknown input 'i12'"):
        Rotor(els, outputs=[OutputPort("x2", 2)]).frf([1.0], inputs=["i12"])


# ----------------------------------------------------------------------------- crack hook

def test_local_flexibility_hook_static_hinge():
    """A rotational compliance c at the start of element 2 equals a hinge spring 1/c between the two
    elements (split rotation DOF): identical static deflections of a simply supported shaft."""
    L, d, c = 0.4, 0.03, 2e-5
    mat = {k: Param(k, v) for k, v in STEEL.items()}
    els = [ShaftElement(1, L / 2, d, **mat), ShaftElement(2, L / 2, d, **mat)]
    r0 = Rotor(els, planes=1)
    r = Rotor(els + [ShaftFlexibility(2, c_x=c, xi=0.0)], planes=1)
    K = r.matrices().K
    # reference: nodes 1, 2a, 2b, 3 with rotation DOFs split at node 2 and a spring 1/c between them
    Ke = [dm(timoshenko_plane_matrices(STEEL["E"], STEEL["E"] / 2.6, 7800, L / 2, d, 0.0,
                                       cowper_shear_coefficient(0.3))[2])] * 2
    # DOFs: u1 psi1 u2 psi2a psi2b u3 psi3
    Kr = np.zeros((7, 7))
    for e, idx in ((0, [0, 1, 2, 3]), (1, [2, 4, 5, 6])):
        Kr[np.ix_(idx, idx)] += Ke[e]
    Kr[np.ix_([3, 4], [3, 4])] += np.array([[1, -1], [-1, 1]]) / c
    F = np.zeros(6)
    F[2] = 1000.0                           # N at mid-span
    free = [1, 2, 3, 5]                     # pinned: u1 = u3 = 0 (plane layout u1 psi1 u2 psi2 u3 psi3)
    x = np.linalg.solve(K[np.ix_(free, free)], F[free])
    Fr = np.zeros(7)
    Fr[2] = 1000.0
    fr = [1, 2, 3, 4, 6]
    xr = np.linalg.solve(Kr[np.ix_(fr, fr)], Fr[fr])
    assert x[1] == pytest.approx(xr[1], rel=1e-10)          # mid-span deflection
    assert x[1] > np.linalg.solve(r0.matrices().K[np.ix_(free, free)], F[free])[1] * 1.01
    # zero compliance changes nothing; any compliance lowers the first frequency; symmetric
    np.testing.assert_allclose(Rotor(els + [ShaftFlexibility(2, c_x=0.0)], planes=1).matrices().K,
                               r0.matrices().K, rtol=1e-12, atol=1e-6)
    np.testing.assert_allclose(K, K.T, atol=1e-9 * np.abs(K).max())


def test_local_flexibility_hook_in_two_planes_is_symbolic():
    r = load_model(data_path("rotor.toml"))
    flex = ShaftFlexibility(15, c_x=Param("crack.c", 1e-4, "rad/(N m)"), xi=0.5)
    rc = Rotor(r.elements + [flex], inputs=r.inputs[:-1], outputs=r.outputs, speed=r.speed,
               damping=r.damping)
    assert "crack.c" in rc.parameter_names
    f0 = r.natural_frequencies(n=4)
    f1 = rc.natural_frequencies(n=4)
    assert np.all(f1 < f0)
    np.testing.assert_allclose(rc.natural_frequencies(n=4, values={"crack.c": 0.0}), f0, rtol=1e-9)
    # d f / d c is available symbolically: K depends on crack.c
    j = rc.parameter_names.index("crack.c")
    assert ca.depends_on(rc.symbolic["K"], rc.p[j])
    host = rc.shaft_element(15)
    Kc = shaft_stiffness_with_compliance(host, {n: ca.SX(v) for n, v in
                                                zip(rc.parameter_names, rc.nominal)} | {}, 0.0)
    Kh = host.plane_matrices({n: ca.SX(v) for n, v in zip(rc.parameter_names, rc.nominal)})[2]
    np.testing.assert_allclose(dm(ca.evalf(Kc)), dm(ca.evalf(Kh)), rtol=1e-10, atol=1e-3)


# ----------------------------------------------------------------------------- demo

def test_demo_rotor_json(capsys):
    from mutext.cli import main
    assert main(["demo", "rotor", "--json", "--points", "60"]) == 0
    out = json.loads(capsys.readouterr().out)
    nf = out["natural_frequencies_hz"]
    assert set(nf) == {"healthy", "cracked"} and len(nf["healthy"]) == 6
    assert 20 < nf["healthy"][0] < 225 and 20 < nf["healthy"][2] < 225
    assert nf["cracked"][0] < nf["healthy"][0]             # heavier disk
    assert "no crack element" in out["note"]


# ----------------------------------------------------------------------------- ROSS

@pytest.mark.slow
def test_against_ross():
    """A hollow shaft with an overhung disk on anisotropic bearings, at 3000 rpm, against ROSS."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rs = pytest.importorskip("ross")
    E, G, rho = 2.05e11, 7.9e10, 7850.0
    steel = rs.Material(name="mutext_test_steel", rho=rho, E=E, G_s=G)
    Ls = [0.1, 0.15, 0.15, 0.15, 0.12]
    sh = [rs.ShaftElement(L=L, idl=0.01, odl=0.04, material=steel, shear_effects=True, rotary_inertia=True,
                          gyroscopic=True) for L in Ls]
    dk = [rs.DiskElement.from_geometry(n=5, material=steel, width=0.04, i_d=0.04, o_d=0.25)]
    br = [rs.BearingElement(n=1, kxx=5e6, kyy=8e6, cxx=0), rs.BearingElement(n=4, kxx=5e6, kyy=8e6, cxx=0)]
    ross_rotor = rs.Rotor(sh, dk, br)
    speed = rpm_to_rad_s(3000)
    ross_w = np.sort(ross_rotor.run_modal(speed=speed, num_modes=30).wd)
    mat = dict(E=Param("E", E), G=Param("G", G), rho=Param("rho", rho))
    els = [ShaftElement(i + 1, L, 0.04, 0.01, **mat) for i, L in enumerate(Ls)]
    els += [DiskElement.from_geometry(6, 0.04, 0.25, 0.04, rho),
            BearingElement(2, 5e6, kyy=8e6), BearingElement(5, 5e6, kyy=8e6)]
    ours = Rotor(els).modes(speed=speed, n=8).omega
    # ROSS also has axial and torsional modes: every lateral mode of ours must appear in ROSS
    for w in ours:
        assert np.min(np.abs(ross_w / w - 1)) < 1e-4, (w, ross_w)
