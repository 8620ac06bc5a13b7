"""Both bending compliances of an open crack (c55 and c44) and the crack element that uses them.

Independent checks: the strip integrals of Papadopoulos and Dimarogonas
evaluated by mpmath in the other order of integration (outer over the depth
coordinate, inner over the strips whose local depth exceeds it), the limits
for a shallow crack, the ratio c44/c55 quoted in the book, the one-compliance
element written out here, and the thesis rotor's stiffness loss with the crack
facing x (first mode pair at standstill).
"""
import casadi as ca
import mpmath as mp
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.rotor import crack as cr
from mutext.rotor import data_path, loads_model

E = cr.RIG_YOUNGS_MODULUS
D = cr.RIG_SHAFT_DIAMETER
NU = 0.3
I_SHAFT = np.pi * D**4 / 64


# ----------------------------------------------------------------------------
# the compliances
# ----------------------------------------------------------------------------

def _cbar_mpmath(depth_ratio, component):
    r"""\bar c_55 or \bar c_44 with the integration order swapped (tanh-sinh quadrature).

    For a local depth alpha in (0, a) the strips with alpha_xi >= alpha are
    |xi| <= sqrt(1 - (1 - a + alpha)^2) (all lengths over R)."""
    with mp.workdps(15):
        ab = mp.mpf(2 * depth_ratio)

        def F(alpha, xi):
            h = 2 * mp.sqrt(1 - xi**2)
            lam = mp.pi * alpha / (2 * h)
            g = mp.sqrt(mp.tan(lam) / lam) / mp.cos(lam)
            if component == 55:
                return g * (mp.mpf("0.923") + mp.mpf("0.199") * (1 - mp.sin(lam))**4)
            return g * (mp.mpf("0.752") + mp.mpf("2.02") * alpha / h + mp.mpf("0.37") * (1 - mp.sin(lam))**3)

        def weight(xi):
            return 1 - xi**2 if component == 55 else xi**2

        def inner(alpha):
            if alpha == 0:
                return mp.mpf(0)
            xm = mp.sqrt(1 - (1 - ab + alpha)**2)
            return alpha * mp.quad(lambda xi: weight(xi) * F(alpha, xi)**2, [0, xm])

        return float(64 / mp.pi * mp.quad(inner, [0, ab]))


@pytest.mark.parametrize("component", [55, 44])
@pytest.mark.parametrize("depth_ratio", [0.05, 0.2, 0.4, 0.5])
def test_compliances_match_integration_in_the_other_order(depth_ratio, component):
    got = cr.crack_compliance_dimensionless(depth_ratio, component=component)
    assert got == pytest.approx(_cbar_mpmath(depth_ratio, component), rel=1e-6)


def test_reference_values_of_c44():
    assert cr.crack_compliance_dimensionless(0.2, component=44) == pytest.approx(0.109043, rel=5e-6)
    assert cr.crack_compliance_dimensionless(0.4, component=44) == pytest.approx(1.65513, rel=5e-6)
    # c55 is unchanged by the new keyword
    assert cr.crack_compliance_dimensionless(0.4, component="c55") == cr.crack_compliance_dimensionless(0.4)


@pytest.mark.parametrize("depth_ratio, ratio", [(0.1, 0.07), (0.2, 0.15), (0.3, 0.26), (0.4, 0.42), (0.5, 0.68)])
def test_ratio_c44_over_c55(depth_ratio, ratio):
    r = (cr.crack_compliance(depth_ratio, E, D, NU, component=44)
         / cr.crack_compliance(depth_ratio, E, D, NU, component=55))
    assert round(r, 2) == ratio


def test_shallow_crack_limits_and_ordering():
    d = np.linspace(0.0, 0.5, 51)
    c55 = cr.crack_compliance_dimensionless(d)
    c44 = cr.crack_compliance_dimensionless(d, component=44)
    assert c55[0] == 0.0 and c44[0] == 0.0
    assert np.all(c44[1:] < c55[1:]) and np.all(np.diff(c44) > 0)
    # shallow crack: width ~ sqrt(a D), so c55 ~ (a/D)^(5/2) and c44 ~ (a/D)^(7/2) (one more xi^2 ~ a/D)
    lo, hi = 1e-3, 2e-3
    for comp, order in ((55, 2.5), (44, 3.5)):
        slope = np.log(cr.crack_compliance_dimensionless(hi, component=comp)
                       / cr.crack_compliance_dimensionless(lo, component=comp)) / np.log(hi / lo)
        assert slope == pytest.approx(order, abs=0.02)
    # so both vanish faster than (a/D)^2, and the ratio grows from 0 with the depth
    for comp in (55, 44):
        q = [cr.crack_compliance_dimensionless(x, component=comp) / x**2 for x in (1e-4, 1e-3, 1e-2)]
        assert q[0] < q[1] < q[2]
    r = c44[1:] / c55[1:]
    assert np.all(np.diff(r) > 0) and r[0] < 0.01


def test_c44_symbolic_derivative_and_errors():
    x = ca.SX.sym("d")
    f = ca.Function("f", [x], [cr.crack_compliance_dimensionless(x, component=44)])
    g = ca.Function("g", [x], [ca.jacobian(cr.crack_compliance_dimensionless(x, component=44), x)])
    h = 1e-6
    for d in (0.15, 0.35):
        fd = (float(f(d + h)) - float(f(d - h))) / (2 * h)
        assert float(g(d)) == pytest.approx(fd, rel=1e-6)
    for bad in (45, "c45", True, None):
        with pytest.raises(ModelError, match="component"):
            cr.crack_compliance(0.3, E, D, NU, component=bad)


# ----------------------------------------------------------------------------
# the cracked element
# ----------------------------------------------------------------------------

def _shafts(L=0.05):
    from mutext.rotor import ShaftElement
    return [ShaftElement(s, L, D, 0.0, E=E, rho=7800.0, nu=NU) for s in range(1, 6)]


def _one_compliance(el, p, layout):
    """The crack element before c44 was added, written out (only c55, bending across the edge)."""
    from mutext.rotor.shaft_element import T_XZ, T_YZ
    delta = el.plane_delta(p, el.compliance(p))
    if el.orientation == "mean":
        if layout.kind == "plane":
            return 0.5 * delta
        return ca.mtimes([T_XZ.T, 0.5 * delta, T_XZ]) + ca.mtimes([T_YZ.T, 0.5 * delta, T_YZ])
    co, si = float(np.cos(el.orientation)), float(np.sin(el.orientation))
    if layout.kind == "plane":
        return co**2 * delta
    return (co**2 * ca.mtimes([T_XZ.T, delta, T_XZ]) + si**2 * ca.mtimes([T_YZ.T, delta, T_YZ])
            + co * si * (ca.mtimes([T_XZ.T, delta, T_YZ]) + ca.mtimes([T_YZ.T, delta, T_XZ])))


@pytest.mark.parametrize("planes, orientation", [(1, 0.4), (1, "mean"), (2, 0.0), (2, 0.7), (2, "mean")])
def test_perpendicular_false_is_the_one_compliance_model(planes, orientation):
    from mutext.rotor import Rotor
    rotor = Rotor(_shafts() + [cr.Crack(3, 0.4, xi=0.3, orientation=orientation, perpendicular=False)],
                  planes=planes)
    el = rotor.elements[-1]
    p = rotor._ps.symbols
    fn = ca.Function("k", [rotor.p], [el.stiffness_matrix(p, rotor.layout), _one_compliance(el, p, rotor.layout)])
    new, old = (np.asarray(m.full()) for m in fn(rotor.values()))
    assert np.abs(new - old).max() <= 4 * np.finfo(float).eps * np.abs(old).max()
    # the full model differs, by the c44 compliance
    full = Rotor(_shafts() + [cr.Crack(3, 0.4, xi=0.3, orientation=orientation, perpendicular=True)],
                 planes=planes)
    fe = full.elements[-1]
    kf = np.asarray(ca.Function("k", [full.p], [fe.stiffness_matrix(full._ps.symbols, full.layout)])(
        full.values()).full())
    assert not np.allclose(kf, old)


def test_two_plane_element_default_is_the_one_compliance_element():
    c55 = cr.crack_compliance(0.4, E, D, NU)
    c44 = cr.crack_compliance(0.4, E, D, NU, component=44)
    L, ang = 0.05, 0.8
    K1 = cr.cracked_element_stiffness_two_plane(L, E, I_SHAFT, c55, ang, position=0.3)
    K0 = cr.cracked_element_stiffness_two_plane(L, E, I_SHAFT, c55, ang, position=0.3, compliance_eta=0.0)
    assert np.array_equal(K1, K0)
    # in the crack frame: K_xi with c55, K_eta with c44, uncoupled
    K = cr.cracked_element_stiffness_two_plane(L, E, I_SHAFT, c55, ang, position=0.3, compliance_eta=c44)
    R = np.kron(np.array([[np.cos(ang), np.sin(ang)], [-np.sin(ang), np.cos(ang)]]), np.eye(4))
    Kc = R @ K @ R.T
    Kxi = cr.cracked_element_stiffness(L, E, I_SHAFT, c55, position=0.3)
    Keta = cr.cracked_element_stiffness(L, E, I_SHAFT, c44, position=0.3)
    scale = np.abs(Kxi).max()
    assert np.allclose(Kc[:4, :4], Kxi, rtol=0, atol=1e-12 * scale)
    assert np.allclose(Kc[4:, 4:], Keta, rtol=0, atol=1e-12 * scale)
    assert np.allclose(Kc[:4, 4:], 0.0, rtol=0, atol=1e-12 * scale)
    # symbolic angle gives the same matrix
    a = ca.SX.sym("a")
    Ks = ca.Function("K", [a], [cr.cracked_element_stiffness_two_plane(L, E, I_SHAFT, c55, a, position=0.3,
                                                                        compliance_eta=c44)])
    assert np.allclose(np.asarray(Ks(ang)), K, rtol=0, atol=1e-12 * scale)


def test_directional_deltas_agree_with_the_open_crack_at_any_angle():
    from mutext.rotor import Rotor
    beta = 1.1
    rotor = Rotor(_shafts() + [cr.Crack(3, 0.35, xi=0.5, orientation=beta, perpendicular=True)], planes=2)
    el = rotor.elements[-1]
    p = rotor._ps.symbols
    Axx, Ayy, Axy = el.directional_deltas(p, rotor.layout)
    comb = np.cos(beta)**2 * Axx + np.sin(beta)**2 * Ayy + np.sin(beta) * np.cos(beta) * Axy
    fn = ca.Function("k", [rotor.p], [comb, el.stiffness_matrix(p, rotor.layout)])
    a, b = (np.asarray(m.full()) for m in fn(rotor.values()))
    assert np.allclose(a, b, rtol=0, atol=1e-12 * np.abs(b).max())


def test_perpendicular_flag_is_checked_and_read_from_a_model_file():
    with pytest.raises(ModelError, match="perpendicular"):
        cr.Crack(3, 0.2, perpendicular="no")
    text = open(data_path("rotor.toml")).read()
    m = loads_model(text + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\nperpendicular = true\n",
                    source="rotor.toml + crack", base_dir=data_path(""))
    assert m.elements[-1].perpendicular is True
    # the default is the one-compliance model the book and the exercises were computed with
    m = loads_model(text + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\n",
                    source="rotor.toml + crack", base_dir=data_path(""))
    assert m.elements[-1].perpendicular is False


# ----------------------------------------------------------------------------
# the thesis rotor's crack at a/D = 0.4
# ----------------------------------------------------------------------------

def _thesis_rotor(crack=""):
    text = open(data_path("rotor.toml")).read()
    return loads_model(text + crack, source="rotor.toml + crack", base_dir=data_path(""))


def _crack(perpendicular, orientation="0.0"):
    return (f"\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\norientation = {orientation}\n"
            f"perpendicular = {'true' if perpendicular else 'false'}\n")


def test_thesis_crack_mean_loss_grows_and_asymmetry_shrinks():
    """Crack facing x, open, at standstill: the first mode pair gives the modal stiffness losses.

    dk = k0 (1 - (f/f0)^2) with k0 = m_disk (2 pi f0)^2, as for the book's Jeffcott rotor;
    dk_xi from the mode bending across the crack edge, dk_eta from the other one."""
    healthy = _thesis_rotor()
    f0 = healthy.natural_frequencies(n=2, speed=0.0)
    k0 = healthy.parameter("disk16.m").value * (2 * np.pi * f0[0])**2
    loss = {}
    for perp in (False, True):
        f = _thesis_rotor(_crack(perp)).natural_frequencies(n=2, speed=0.0)
        dk_xi, dk_eta = k0 * (1 - (f[0] / f0[0])**2), k0 * (1 - (f[1] / f0[1])**2)
        loss[perp] = (dk_xi, dk_eta)
    (x_old, e_old), (x_new, e_new) = loss[False], loss[True]
    assert e_old == pytest.approx(0.0, abs=1e-9 * k0)            # one-compliance model: eta plane healthy
    assert x_new == pytest.approx(x_old, rel=1e-6)              # c55 plane unchanged
    ratio = cr.crack_compliance_dimensionless(0.4, component=44) / cr.crack_compliance_dimensionless(0.4)
    mean_growth = (x_new + e_new) / (x_old + e_old)
    asym_change = (x_new - e_new) / (x_old - e_old)
    assert mean_growth > 1 and asym_change < 1
    assert mean_growth == pytest.approx(1 + ratio, abs=0.05)      # measured 1.44 (ratio 0.417)
    assert asym_change == pytest.approx(1 - ratio, abs=0.05)      # measured 0.56
    assert x_old / k0 == pytest.approx(0.0957, abs=5e-4)
    assert e_new / k0 == pytest.approx(0.0422, abs=5e-4)


@pytest.mark.parametrize("orientation", ["0.6", '"mean"'])
def test_more_compliance_only_lowers_the_natural_frequencies(orientation):
    f0 = _thesis_rotor().natural_frequencies(n=4, speed=0.0)
    f_old = _thesis_rotor(_crack(False, orientation)).natural_frequencies(n=4, speed=0.0)
    f_new = _thesis_rotor(_crack(True, orientation)).natural_frequencies(n=4, speed=0.0)
    assert np.all(f_new <= f_old * (1 + 1e-9)) and np.all(f_old <= f0 * (1 + 1e-9))
    # the mode bending in the eta plane (second of each pair) sees c44; with the stiffness averaged
    # over a revolution both modes of a pair do
    assert f_new[1] < f_old[1] * (1 - 1e-3) and f_new[3] < f_old[3] * (1 - 1e-3)
    if orientation == '"mean"':
        assert np.all(f_new < f_old * (1 - 1e-3))
