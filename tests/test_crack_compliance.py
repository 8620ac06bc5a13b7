"""Both bending compliances of an open crack (c55 and c44) and the crack element that uses them.

Independent checks: the strip integrals of Papadopoulos and Dimarogonas
evaluated by mpmath in the other order of integration (outer over the depth
coordinate, inner over the strips whose local depth exceeds it), a table of
the compliances from another implementation (c55, c44 and the coupling c45 at
a/D = 0.1 ... 0.5, with the difference in c44 and c45 explained), the limits
for a shallow crack, the ratio c44/c55 quoted in the book, the crack element
in its own frame (no coupling), the one-compliance element written out here,
and the thesis rotor's stiffness loss with the crack facing x (first mode pair
at standstill).
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
# the rig's depth in the default run, the others with the slow tests
@pytest.mark.parametrize("depth_ratio", [d if d == 0.4 else pytest.param(d, marks=pytest.mark.slow)
                                         for d in (0.05, 0.2, 0.4, 0.5)])
def test_compliances_match_integration_in_the_other_order(depth_ratio, component):
    got = cr.crack_compliance_dimensionless(depth_ratio, component=component)
    assert got == pytest.approx(_cbar_mpmath(depth_ratio, component), rel=1e-6)


def test_reference_values_of_c44():
    assert cr.crack_compliance_dimensionless(0.2, component=44) == pytest.approx(0.109043, rel=5e-6)
    assert cr.crack_compliance_dimensionless(0.4, component=44) == pytest.approx(1.65513, rel=5e-6)
    # c55 is unchanged by the new keyword
    assert cr.crack_compliance_dimensionless(0.4, component="c55") == cr.crack_compliance_dimensionless(0.4)


# Tabulated compliances of Papadopoulos and Dimarogonas's strip model against abar = a/R, from the
# table PAPADOPOULOS.csv of the ROSS rotordynamics package (github.com/petrobras/ross, file
# ross/faults/data/PAPADOPOULOS.csv, commit e22c2ad31c1b15ea967e2bab3318d79c6e997137; rows abar = 0.2,
# 0.4, 0.6, 0.8, 1.0, i.e. a/D = 0.1 ... 0.5; columns c55, c44, c45, same normalisation as here:
# c = (1 - nu^2) cbar / (E R^3)).  It is an implementation independent of this package (ROSS
# reads the table for its Crack fault).  No table of the papers themselves was at hand; their
# formulas are checked in addition by the mpmath quadrature above.
ROSS_TABLE = {   # a/D: (c55, c44, c45)
    0.1: (0.144614, 0.00474954, 0.0302734),
    0.2: (0.72488, 0.0545213, 0.225899),
    0.3: (1.8922, 0.247011, 0.761595),
    0.4: (3.97355, 0.827564, 1.97266),
    0.5: (7.79039, 2.63318, 4.75993),
}


def _strip_integral_mpmath(depth_ratio, integrand, half=True):
    """int int integrand(xi, alpha) d(alpha) d(xi) over the crack (xi in (0, b) if half, else (-b, b))."""
    with mp.workdps(15):
        ab = mp.mpf(2 * depth_ratio)
        b = mp.sqrt(1 - (1 - ab)**2)

        def inner(xi):
            depth = mp.sqrt(1 - xi**2) - (1 - ab)
            return mp.quad(lambda al: integrand(xi, al), [0, depth])

        return float(mp.quad(inner, [0, b] if half else [-b, 0, b]))


def _F(which, xi, al):
    h = 2 * mp.sqrt(1 - xi**2)
    lam = mp.pi * al / (2 * h)
    g = mp.sqrt(mp.tan(lam) / lam) / mp.cos(lam)
    if which == 2:
        return g * (mp.mpf("0.923") + mp.mpf("0.199") * (1 - mp.sin(lam))**4)
    return g * (mp.mpf("0.752") + mp.mpf("2.02") * al / h + mp.mpf("0.37") * (1 - mp.sin(lam))**3)


# a shallow crack and the rig's depth in the default run (2-3 CPU-s each: mpmath quadrature), the rest slow
@pytest.mark.parametrize("depth_ratio", [d if d in (0.1, 0.4) else pytest.param(d, marks=pytest.mark.slow)
                                         for d in sorted(ROSS_TABLE)])
def test_compliances_against_the_tabulated_values(depth_ratio):
    c55_tab, c44_tab, c45_tab = ROSS_TABLE[depth_ratio]
    c55 = cr.crack_compliance_dimensionless(depth_ratio)
    c44 = cr.crack_compliance_dimensionless(depth_ratio, component=44)
    # c55 (the moment that opens the crack): the table, to its six digits
    assert c55 == pytest.approx(c55_tab, rel=5e-6)
    # c44: the table integrates over one half of the crack front, 0 <= xi <= b, the half in tension
    # under M4 (a crack whose other half closes): exactly half the package's value, at every depth.
    # The package's crack is open and linear (the rig's slot never closes), so both halves count: a
    # gaping notch has the same energy for +M4 and -M4, quadratic in M4, K_I^2 integrated over the front.
    assert c44 == pytest.approx(2 * c44_tab, rel=5e-6)
    # the tabulated c45 is 64/pi times the cross term's integral over that half front (checked here by
    # an independent quadrature); over the whole front the integrand, odd in xi (K_I under M4 ~ xi,
    # under M5 even in xi), cancels: c45 = 0 for a straight front, the package's element has no
    # coupling between the two bending planes of the crack frame
    cross = lambda xi, al: xi * mp.sqrt(1 - xi**2) * al * _F(1, xi, al) * _F(2, xi, al)
    assert 64 / np.pi * _strip_integral_mpmath(depth_ratio, cross) == pytest.approx(c45_tab, rel=1e-5)
    full = 64 / np.pi * _strip_integral_mpmath(depth_ratio, cross, half=False)
    assert abs(full) < 1e-12 * c45_tab


def test_axial_bending_coupling_is_left_out_for_a_reason():
    """c15 (axial force and the moment that opens the crack) is even along the front and does not vanish.

    From K_I = (P1 / (pi R^2) F1 + 4 M5 sqrt(1 - xi^2) / (pi R^3) F2) sqrt(pi alpha), the cross term is
    c15 = (1 - nu^2) / (E R^2) * 8/pi int int sqrt(1 - xi^2) alpha F1 F2 over the front: the table's
    value (column c15, a/D = 0.2: 0.225987) agrees.  The lateral beam model carries no axial force
    (one bearing locates the shaft axially, the other floats), so M5 sees c55 only: the rotation is
    c55 M5 + c15 P1 with P1 = 0."""
    cross = lambda xi, al: mp.sqrt(1 - xi**2) * al * _F(1, xi, al) * _F(2, xi, al)
    c15 = 8 / np.pi * _strip_integral_mpmath(0.2, cross, half=False)
    assert c15 == pytest.approx(0.225987, rel=1e-5)
    assert c15 > 0.1 * cr.crack_compliance_dimensionless(0.2)


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


def test_assembled_crack_has_no_coupling_in_the_crack_frame():
    """The default crack at an angle, seen in its own frame: symmetric, the plane of the normal with c55,
    the plane of the edge with c44 (the one-plane rotor's crack facing x and facing y), no coupling."""
    from mutext.rotor import Rotor
    from mutext.rotor.shaft_element import T_XZ, T_YZ

    def delta(planes, beta):
        rotor = Rotor(_shafts() + [cr.Crack(3, 0.4, xi=0.3, orientation=beta)], planes=planes)
        el = rotor.elements[-1]
        fn = ca.Function("k", [rotor.p], [el.stiffness_matrix(rotor._ps.symbols, rotor.layout)])
        return np.asarray(fn(rotor.values()).full())

    beta = 0.9
    K = delta(2, beta)
    Txz, Tyz = np.asarray(ca.DM(T_XZ).full()), np.asarray(ca.DM(T_YZ).full())
    P_xi = np.cos(beta) * Txz + np.sin(beta) * Tyz       # deflection and rotation along the normal
    P_eta = -np.sin(beta) * Txz + np.cos(beta) * Tyz     # ... and along the edge
    scale = np.abs(K).max()
    assert np.allclose(K, K.T, rtol=0, atol=1e-12 * scale)
    assert np.allclose(P_xi @ K @ P_eta.T, 0.0, rtol=0, atol=1e-12 * scale)
    k_xi, k_eta = delta(1, 0.0), delta(1, np.pi / 2)     # plane x-z: facing x sees c55, facing y c44
    assert np.allclose(P_xi @ K @ P_xi.T, k_xi, rtol=0, atol=1e-10 * scale)
    assert np.allclose(P_eta @ K @ P_eta.T, k_eta, rtol=0, atol=1e-10 * scale)
    assert np.abs(k_eta).max() > 0.1 * np.abs(k_xi).max()


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
    m = loads_model(text + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\nperpendicular = false\n",
                    source="rotor.toml + crack", base_dir=data_path(""))
    assert m.elements[-1].perpendicular is False
    # the default is the full model, both bending compliances, in a file as in the class
    m = loads_model(text + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\n",
                    source="rotor.toml + crack", base_dir=data_path(""))
    assert m.elements[-1].perpendicular is True
    assert cr.Crack(3, 0.2).perpendicular is True


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


def test_diagnosis_crack_hypothesis_is_the_default_crack_of_a_model_file():
    """The screen's crack at station 15 changes K exactly as the [[crack]] entry it writes (the
    default crack: both compliances, facing x) changes the assembled rotor."""
    from mutext.diagnose.faults.crack import candidates
    healthy = _thesis_rotor()
    (hyp,) = candidates(healthy, stations=[15])
    dk = hyp.crack(0.4)
    cracked = _thesis_rotor("\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\n")
    full = cracked.matrices(cracked.values())[2] - healthy.matrices(healthy.values())[2]
    idx = np.asarray(hyp.dofs)
    assert np.allclose(full[np.ix_(idx, idx)], dk, rtol=0, atol=1e-9 * np.abs(dk).max())
    # ... including the plane along the crack edge (c44): not the one-compliance change
    one = _thesis_rotor(_crack(False))
    k_one = one.matrices(one.values())[2] - healthy.matrices(healthy.values())[2]
    assert not np.allclose(k_one[np.ix_(idx, idx)], dk, rtol=0, atol=1e-3 * np.abs(dk).max())
