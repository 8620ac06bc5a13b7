"""Crack models: fracture-mechanics compliance, cracked beam elements, breathing Jeffcott rotor.

The physical checks are independent of the code under test: an adaptive
double integral (scipy) of the compliance integral, published dimensionless
compliances, the characteristic equation of a simply supported
Euler-Bernoulli beam with a rotational spring solved by root finding, a small
finite-element beam written here, and a harmonic-balance solution of the
linear time-periodic Jeffcott rotor.
"""
import casadi as ca
import numpy as np
import pytest
from scipy import integrate, linalg, optimize

from mutext.errors import ModelError
from mutext.rotor import crack as cr
from mutext.rotor.simulate import simulate_breathing_jeffcott

E = cr.RIG_YOUNGS_MODULUS          # 30 Mpsi [Pa]
D = cr.RIG_SHAFT_DIAMETER          # 0.625 in [m]
NU = 0.3
I_SHAFT = np.pi * D**4 / 64


# ----------------------------------------------------------------------------
# compliance
# ----------------------------------------------------------------------------

def _cbar_reference(depth_ratio):
    """The compliance integral of Papadopoulos & Dimarogonas by adaptive quadrature."""
    abar = 2 * depth_ratio

    def F2(lam):
        return np.sqrt(np.tan(lam) / lam) * (0.923 + 0.199 * (1 - np.sin(lam))**4) / np.cos(lam)

    def f(y, x):
        lam = np.pi * y / (4 * np.sqrt(1 - x**2))
        return 0.0 if lam == 0 else 32 / np.pi * (1 - x**2) * y * F2(lam)**2

    b = np.sqrt(1 - (1 - abar)**2)
    val, _ = integrate.dblquad(f, -b, b, 0, lambda x: np.sqrt(1 - x**2) - (1 - abar),
                               epsabs=1e-13, epsrel=1e-11)
    return val


def test_compliance_is_zero_without_crack():
    assert cr.crack_compliance_dimensionless(0.0) == 0.0
    assert cr.crack_compliance(0.0, E, D, NU) == 0.0
    assert cr.crack_rotational_stiffness(0.0, E, D, NU) == np.inf
    a = ca.SX.sym("a")
    f = ca.Function("f", [a], [cr.crack_compliance(a, E, D, NU), ca.gradient(cr.crack_compliance(a, E, D, NU), a)])
    v, g = (float(x) for x in f(0.0))
    assert v == 0.0 and g == 0.0


def test_compliance_positive_and_increasing():
    d = np.linspace(0.005, 0.5, 100)
    c = cr.crack_compliance(d, E, D, NU)
    assert np.all(c > 0)
    assert np.all(np.diff(c) > 0)
    # small cracks: c ~ (a/D)^(5/2) (crack area ~ a^(3/2), energy ~ a)
    c1, c2 = cr.crack_compliance_dimensionless([1e-4, 2e-4])
    assert np.log(c2 / c1) / np.log(2) == pytest.approx(2.5, abs=0.01)


@pytest.mark.parametrize("depth_ratio, cbar", [
    # dimensionless compliance c55 = c E R^3 / (1 - nu^2) of Papadopoulos (2004), as tabulated
    # against a/R in the ROSS rotordynamics package (petrobras/ross, file
    # ross/faults/data/PAPADOPOULOS.csv, rows a/R = 0.1, 0.4, 0.8; six significant digits)
    (0.05, 0.0277722),
    (0.20, 0.724880),
    (0.40, 3.97355),
])
def test_compliance_matches_published_values(depth_ratio, cbar):
    assert cr.crack_compliance_dimensionless(depth_ratio) == pytest.approx(cbar, rel=2e-6)


@pytest.mark.parametrize("depth_ratio", [0.03, 0.27, 0.5])
def test_gauss_rule_matches_adaptive_quadrature(depth_ratio):
    assert cr.crack_compliance_dimensionless(depth_ratio) == pytest.approx(
        _cbar_reference(depth_ratio), rel=1e-9)


def test_dimensional_compliance_of_the_rig_crack():
    c = cr.crack_compliance(cr.RIG_CRACK_DEPTH_RATIO, E, D, NU)
    R = D / 2
    assert c == pytest.approx((1 - NU**2) * 3.97355 / (E * R**3), rel=2e-6)
    # the 40 % crack is as flexible as about 1.42 diameters of extra shaft
    assert c * E * I_SHAFT / D == pytest.approx(np.pi / 8 * (1 - NU**2) * 3.97355, rel=2e-6)
    assert cr.crack_rotational_stiffness(0.4, E, D, NU) == pytest.approx(1 / c)


@pytest.mark.parametrize("sym", [ca.SX, ca.MX])
def test_casadi_derivative_equals_finite_difference(sym):
    a = sym.sym("a")
    c = cr.crack_compliance(a, E, D, NU)
    f = ca.Function("f", [a], [c, ca.gradient(c, a)])
    h = 1e-6
    for d in (0.02, 0.1, 0.25, 0.4, 0.49):
        val, grad = (float(x) for x in f(d))
        assert val == pytest.approx(cr.crack_compliance(d, E, D, NU), rel=1e-14)
        fd = (cr.crack_compliance(d + h, E, D, NU) - cr.crack_compliance(d - h, E, D, NU)) / (2 * h)
        assert grad == pytest.approx(fd, rel=1e-6)
        assert grad > 0


def test_symbolic_material_and_diameter():
    Es, Ds = ca.SX.sym("E"), ca.SX.sym("D")
    c = cr.crack_compliance(0.3, Es, Ds, NU)
    f = ca.Function("f", [Es, Ds], [c])
    assert float(f(E, D)) == pytest.approx(cr.crack_compliance(0.3, E, D, NU), rel=1e-14)


@pytest.mark.parametrize("kwargs, match", [
    (dict(depth_ratio=-0.1), "depth_ratio"),
    (dict(depth_ratio=0.6), "half the diameter"),
    (dict(depth_ratio=np.nan), "finite"),
    (dict(E=-1.0), "Young"),
    (dict(D=0.0), "diameter"),
    (dict(nu=0.7), "Poisson"),
])
def test_compliance_input_errors(kwargs, match):
    args = dict(depth_ratio=0.2, E=E, D=D, nu=NU)
    args.update(kwargs)
    with pytest.raises(ModelError, match=match):
        cr.crack_compliance(**args)


# ----------------------------------------------------------------------------
# beam elements
# ----------------------------------------------------------------------------

def _eb_stiffness(EI, h):
    return EI / h**3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                                 [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])


def _eb_mass(rhoA, h):
    return rhoA * h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                                      [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])


def test_cracked_element_reduces_to_standard_elements():
    h = 0.03
    K = cr.cracked_element_stiffness(h, E, I_SHAFT, 0.0)
    Kref = _eb_stiffness(E * I_SHAFT, h)
    assert np.allclose(K, Kref, rtol=1e-12, atol=1e-12 * np.abs(Kref).max())
    phi = 0.2   # Timoshenko element (Przemieniecki)
    Kt = cr.cracked_element_stiffness(h, E, I_SHAFT, 0.0, phi=phi)
    Kt_ref = E * I_SHAFT / ((1 + phi) * h**3) * np.array([
        [12, 6 * h, -12, 6 * h], [6 * h, (4 + phi) * h * h, -6 * h, (2 - phi) * h * h],
        [-12, -6 * h, 12, -6 * h], [6 * h, (2 - phi) * h * h, -6 * h, (4 + phi) * h * h]])
    assert np.allclose(Kt, Kt_ref, rtol=1e-12, atol=1e-12 * np.abs(Kt_ref).max())


@pytest.mark.parametrize("position", [0.0, 0.37, 1.0])
def test_cracked_element_rigid_body_modes_and_softening(position):
    h = 0.05
    c = cr.crack_compliance(0.4, E, D, NU)
    K = cr.cracked_element_stiffness(h, E, I_SHAFT, c, position=position)
    K0 = cr.cracked_element_stiffness(h, E, I_SHAFT, 0.0)
    assert np.allclose(K, K.T, rtol=0, atol=1e-10 * np.abs(K).max())
    for mode in (np.array([1.0, 0, 1, 0]), np.array([0, 1.0, h, 1])):   # translation, rotation
        assert np.linalg.norm(K @ mode) < 1e-9 * np.abs(K).max()
    ev = np.linalg.eigvalsh(K0 - K)     # the crack only removes stiffness
    assert ev.min() > -1e-9 * np.abs(K).max()
    # cantilever (node 1 clamped), tip moment M: tip rotation gains exactly c*M
    M = 3.0
    Kff = K[2:, 2:]
    u = np.linalg.solve(Kff, [0.0, M])
    u0 = np.linalg.solve(K0[2:, 2:], [0.0, M])
    assert u[1] - u0[1] == pytest.approx(c * M, rel=1e-9)


def test_open_crack_element_structure():
    k = cr.crack_rotational_stiffness(0.4, E, D, NU)
    Kc = cr.open_crack_element(0.4, E, D, NU)
    assert np.allclose(Kc, k * np.array([[0, 0, 0, 0], [0, 1, 0, -1], [0, 0, 0, 0], [0, -1, 0, 1]]))
    with pytest.raises(ModelError, match="infinite"):
        cr.open_crack_element(0.0, E, D, NU)
    a = ca.SX.sym("a")
    f = ca.Function("f", [a], [cr.open_crack_element(a, E, D, NU)])
    assert np.allclose(np.array(f(0.4)), Kc, rtol=1e-14)


def test_two_plane_element_is_a_rotated_pair():
    h = 0.04
    c = cr.crack_compliance(0.35, E, D, NU)
    Kxi = cr.cracked_element_stiffness(h, E, I_SHAFT, c)
    Kh = cr.cracked_element_stiffness(h, E, I_SHAFT, 0.0)
    K0 = cr.cracked_element_stiffness_two_plane(h, E, I_SHAFT, c, 0.0)
    assert np.allclose(K0, linalg.block_diag(Kxi, Kh))
    K90 = cr.cracked_element_stiffness_two_plane(h, E, I_SHAFT, c, np.pi / 2)
    assert np.allclose(K90, linalg.block_diag(Kh, Kxi), atol=1e-9 * np.abs(Kh).max())
    beta = 0.7
    K = cr.cracked_element_stiffness_two_plane(h, E, I_SHAFT, c, beta)
    # independent construction: rotate the crack-frame DOFs, q_xi = cos q_x + sin q_y
    Rm = np.block([[np.cos(beta) * np.eye(4), np.sin(beta) * np.eye(4)],
                   [-np.sin(beta) * np.eye(4), np.cos(beta) * np.eye(4)]])
    assert np.allclose(K, Rm.T @ linalg.block_diag(Kxi, Kh) @ Rm, atol=1e-9 * np.abs(Kh).max())
    b = ca.SX.sym("b")
    f = ca.Function("f", [b], [cr.cracked_element_stiffness_two_plane(h, E, I_SHAFT, c, b)])
    assert np.allclose(np.array(f(beta)), K, atol=1e-9 * np.abs(Kh).max())


# ----------------------------------------------------------------------------
# independent physical check: simply supported beam with a rotational spring
# ----------------------------------------------------------------------------

L_BEAM = 26 * 0.0254           # rig length 26 in
RHO_A = 7800.0 * np.pi * D**2 / 4


def _spring_beam_det(beta, a, L, cEI):
    """Characteristic determinant of a simply supported beam with a rotational spring at x=a.

    Segment 1: W = A sin(bx) + B sinh(bx); segment 2: W = C sin(b(L-x)) + D sinh(b(L-x)).
    At x=a: equal deflection, moment and shear; slope jump W2' - W1' = c EI W''.
    Rows are scaled by powers of beta so the determinant is O(1).
    """
    s1, c1, sh1, ch1 = np.sin(beta * a), np.cos(beta * a), np.sinh(beta * a), np.cosh(beta * a)
    u = beta * (L - a)
    s2, c2, sh2, ch2 = np.sin(u), np.cos(u), np.sinh(u), np.cosh(u)
    M = np.array([
        [s1, sh1, -s2, -sh2],                                           # W1 = W2
        [-s1, sh1, s2, -sh2],                                           # W1'' = W2''  (/beta^2)
        [-c1, ch1, -c2, ch2],                                           # W1''' = W2''' (/beta^3)
        # W2' - W1' - cEI W1'' = 0  (/beta)
        [-c1 - cEI * beta * (-s1), -ch1 - cEI * beta * sh1, -c2, -ch2],
    ])
    return np.linalg.det(M) / np.cosh(beta * a) / np.cosh(u)


def _analytic_first_frequency(a, L, cEI):
    b0 = np.pi / L
    if cEI == 0:
        beta = b0
    else:
        beta = optimize.brentq(_spring_beam_det, 0.6 * b0, b0, args=(a, L, cEI), xtol=1e-14)
    return beta**2 * np.sqrt(E * I_SHAFT / RHO_A)


def _fe_simply_supported(n_el, L, crack=None):
    """First bending frequency [rad/s] of a simply supported Euler-Bernoulli beam.

    crack: None, ("hinge", node, depth) -- zero-length hinge at a node with one
    translation and two rotations -- or ("element", element, position, depth).
    """
    h = L / n_el
    EI = E * I_SHAFT
    hinge_node = crack[1] if crack and crack[0] == "hinge" else None
    # DOF numbering: node i -> w_i, theta_i ; the hinge node gets an extra rotation at the end
    ndof = 2 * (n_el + 1) + (1 if hinge_node is not None else 0)
    extra = ndof - 1
    K = np.zeros((ndof, ndof))
    M = np.zeros((ndof, ndof))
    for e in range(n_el):
        dofs = [2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3]
        if hinge_node is not None and e == hinge_node:     # element right of the hinge
            dofs[1] = extra
        if crack and crack[0] == "element" and e == crack[1]:
            c = cr.crack_compliance(crack[3], E, D, NU)
            Ke = cr.cracked_element_stiffness(h, E, I_SHAFT, c, position=crack[2])
        else:
            Ke = _eb_stiffness(EI, h)
        K[np.ix_(dofs, dofs)] += Ke
        M[np.ix_(dofs, dofs)] += _eb_mass(RHO_A, h)
    if hinge_node is not None:
        hd = [2 * hinge_node, 2 * hinge_node + 1, 2 * hinge_node, extra]   # shared translation
        Kc = cr.open_crack_element(crack[2], E, D, NU)
        for i in range(4):
            for j in range(4):
                K[hd[i], hd[j]] += Kc[i, j]
    free = [i for i in range(ndof) if i not in (0, 2 * n_el)]         # w = 0 at both ends
    w2 = linalg.eigh(K[np.ix_(free, free)], M[np.ix_(free, free)], eigvals_only=True,
                     subset_by_index=[0, 0])
    return float(np.sqrt(w2[0]))


def test_analytic_spring_beam_reduces_to_healthy():
    w = _analytic_first_frequency(0.3 * L_BEAM, L_BEAM, 1e-12 * L_BEAM)
    assert w == pytest.approx((np.pi / L_BEAM)**2 * np.sqrt(E * I_SHAFT / RHO_A), rel=1e-9)


@pytest.mark.parametrize("depth", [0.2, 0.4])
def test_fe_hinge_frequency_drop_matches_characteristic_equation(depth):
    n_el = 40
    node = 12                                   # a = 0.3 L
    a = node * L_BEAM / n_el
    cEI = cr.crack_compliance(depth, E, D, NU) * E * I_SHAFT
    w_healthy = _analytic_first_frequency(a, L_BEAM, 0.0)
    w_crack = _analytic_first_frequency(a, L_BEAM, cEI)
    drop = 1 - w_crack / w_healthy
    fe_healthy = _fe_simply_supported(n_el, L_BEAM)
    fe_crack = _fe_simply_supported(n_el, L_BEAM, ("hinge", node, depth))
    fe_drop = 1 - fe_crack / fe_healthy
    assert drop > 1e-3                          # a visible effect
    assert fe_drop == pytest.approx(drop, rel=5e-3)
    # the cracked element with the crack at its end node: same stiffness, but its consistent
    # mass uses the rotation beyond the crack, so it agrees only to discretisation accuracy
    fe_el = _fe_simply_supported(n_el, L_BEAM, ("element", node - 1, 1.0, depth))
    assert 1 - fe_el / fe_healthy == pytest.approx(drop, rel=5e-3)
    assert fe_el == pytest.approx(fe_crack, rel=1e-4)


def test_fe_crack_inside_an_element_matches_characteristic_equation():
    n_el, depth = 40, 0.4
    e, pos = 12, 0.4                             # a = (12 + 0.4) L / 40 = 0.31 L
    a = (e + pos) * L_BEAM / n_el
    cEI = cr.crack_compliance(depth, E, D, NU) * E * I_SHAFT
    drop = 1 - _analytic_first_frequency(a, L_BEAM, cEI) / _analytic_first_frequency(a, L_BEAM, 0.0)
    fe_drop = 1 - (_fe_simply_supported(n_el, L_BEAM, ("element", e, pos, depth))
                   / _fe_simply_supported(n_el, L_BEAM))
    assert fe_drop == pytest.approx(drop, rel=5e-3)


def test_reduced_inertia_segment_approximates_the_hinge():
    # crack at mid-span replaced by a segment of length D with reduced I
    n_el, depth = 60, 0.4
    L = L_BEAM
    c = cr.crack_compliance(depth, E, D, NU)
    a = 0.5 * L
    w_h = _analytic_first_frequency(a, L, 0.0)
    drop = 1 - _analytic_first_frequency(a, L, c * E * I_SHAFT) / w_h
    # mesh: uniform elements except one of length D centred at mid-span
    xs = np.unique(np.concatenate([np.linspace(0, a - D / 2, n_el // 2 + 1),
                                   np.linspace(a + D / 2, L, n_el // 2 + 1)]))
    Ic = cr.equivalent_reduced_inertia(I_SHAFT, E, c, D)
    assert Ic < I_SHAFT
    n = len(xs) - 1
    K = np.zeros((2 * n + 2,) * 2)
    M = np.zeros_like(K)
    for e in range(n):
        h = xs[e + 1] - xs[e]
        I_e = Ic if abs(xs[e] + h / 2 - a) < 1e-12 else I_SHAFT
        dofs = slice(2 * e, 2 * e + 4)
        K[dofs, dofs] += _eb_stiffness(E * I_e, h)
        M[dofs, dofs] += _eb_mass(RHO_A, h)
    free = list(range(1, 2 * n)) + [2 * n + 1]
    w = np.sqrt(linalg.eigh(K[np.ix_(free, free)], M[np.ix_(free, free)], eigvals_only=True,
                            subset_by_index=[0, 0])[0])
    assert 1 - w / w_h == pytest.approx(drop, rel=0.01)


# ----------------------------------------------------------------------------
# breathing laws
# ----------------------------------------------------------------------------

def test_open_fraction_laws():
    psi = np.array([0.0, np.pi / 3, np.pi / 2 - 1e-9, np.pi / 2 + 1e-9, np.pi, 1.5 * np.pi + 1e-9])
    assert np.allclose(cr.open_fraction(psi, "mayes"), 0.5 * (1 + np.cos(psi)))
    assert np.array_equal(cr.open_fraction(psi, "gasch"), [1, 1, 1, 0, 0, 1])
    assert np.array_equal(cr.open_fraction(psi, "open"), np.ones(6))
    assert np.array_equal(cr.open_fraction(psi, "closed"), np.zeros(6))
    p = ca.SX.sym("p")
    for model in ("mayes", "gasch"):
        f = ca.Function("f", [p], [cr.open_fraction(p, model)])
        assert [float(f(v)) for v in psi] == pytest.approx(list(cr.open_fraction(psi, model)))
    with pytest.raises(ModelError, match="crack model"):
        cr.open_fraction(0.0, "hinge")


def test_fixed_frame_stiffness_is_rotated_crack_frame():
    k0, dxi, deta = 1e4, 900.0, 150.0
    rng = np.random.default_rng(1)
    for th, psi in rng.uniform(0, 2 * np.pi, (5, 2)):
        kxi, keta = cr.rotating_frame_stiffness(k0, dxi, deta, psi, "mayes")
        R = np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
        assert np.allclose(cr.fixed_frame_stiffness(k0, dxi, deta, th, psi, "mayes"),
                           R.T @ np.diag([kxi, keta]) @ R)
    # fully open crack normal along x: x loses dk_xi, y loses dk_eta
    assert np.allclose(cr.fixed_frame_stiffness(k0, dxi, deta, 0.0, 0.0, "gasch"),
                       np.diag([k0 - dxi, k0 - deta]))


# ----------------------------------------------------------------------------
# breathing Jeffcott rotor
# ----------------------------------------------------------------------------

M_DISK, K0, W0 = 1.0, 1e4, 100.0     # natural frequency 100 rad/s
DK = 0.1 * K0


def _harmonic_balance_mayes(speed, zeta, gravity, dk, n_harm=24):
    """Steady state of the Mayes-crack Jeffcott rotor by harmonic balance (gravity only).

    With theta = W t and psi = theta + pi/2, K(t) = k0 I - (1 - sin th)/2 * dk/2 * (I + Q(2 th))
    has Fourier terms up to 3X; r = sum_n R_n exp(j n W t) for |n| <= n_harm.
    """
    s = zeta * 2 * np.sqrt(K0 * M_DISK)
    I2 = np.eye(2)
    Qc = np.array([[1.0, 0], [0, -1]])            # coefficient of cos 2th
    Qs = np.array([[0.0, 1], [1, 0]])             # coefficient of sin 2th
    # f(psi) = (1 + cos(th + pi/2))/2 = (1 - sin th)/2
    # dK = -f * dk/2 * (I + cos2th Qc + sin2th Qs); expand products into exponentials
    terms = {}

    def add(p, A):
        terms[p] = terms.get(p, 0) + A

    def cos_(p, A):
        add(p, A / 2); add(-p, A / 2)

    def sin_(p, A):
        add(p, A / 2j); add(-p, -A / 2j)

    h = -dk / 4                                     # -(1/2) * dk/2
    add(0, K0 * I2 + h * I2)
    cos_(2, h * Qc); sin_(2, h * Qs)
    # -sin th * (I + cos2th Qc + sin2th Qs) * h
    sin_(1, -h * I2)
    # sin th cos 2th = (sin 3th - sin th)/2 ; sin th sin 2th = (cos th - cos 3th)/2
    sin_(3, -h * Qc / 2); sin_(1, h * Qc / 2)
    cos_(1, -h * Qs / 2); cos_(3, h * Qs / 2)
    N = 2 * n_harm + 1
    A = np.zeros((2 * N, 2 * N), complex)
    F = np.zeros(2 * N, complex)
    idx = {n: 2 * (n + n_harm) for n in range(-n_harm, n_harm + 1)}
    for n in range(-n_harm, n_harm + 1):
        i = idx[n]
        A[i:i + 2, i:i + 2] += (-M_DISK * (n * speed)**2 + 1j * n * speed * s) * I2
        for p, Kp in terms.items():
            if -n_harm <= n - p <= n_harm:
                A[i:i + 2, idx[n - p]:idx[n - p] + 2] += Kp
    F[idx[0] + 1] = -M_DISK * gravity
    R = np.linalg.solve(A, F)
    return {n: 2 * R[idx[n]:idx[n] + 2] for n in range(1, 4)}


def test_jeffcott_mayes_matches_harmonic_balance():
    speed = 0.5 * W0
    res = simulate_breathing_jeffcott(M_DISK, K0, DK, speed, model="mayes", damping_ratio=0.02)
    hb = _harmonic_balance_mayes(speed, 0.02, 9.81, DK)
    for n in (1, 2, 3):
        assert np.allclose(res.harmonic(n), hb[n], rtol=0, atol=1e-5 * np.abs(hb[2]).max()), n


def test_breathing_crack_2x_peaks_at_half_critical_speed():
    """Gasch (1993): the weight-dominated breathing crack excites 2X, resonant at w0/2."""
    amp = {r: simulate_breathing_jeffcott(M_DISK, K0, DK, r * W0, model="mayes").amplitude(2)
           for r in (0.4, 0.5, 0.6)}
    assert amp[0.5] > 3 * amp[0.4] and amp[0.5] > 3 * amp[0.6]
    healthy = simulate_breathing_jeffcott(M_DISK, K0, DK, 0.5 * W0, model="closed")
    assert healthy.amplitude(2) < 1e-9 * amp[0.5]


def test_open_crack_without_gravity_has_no_2x():
    """An always-open crack is a shaft with constant asymmetric stiffness in the rotating
    frame; unbalance is a constant load in that frame, so the steady response is pure 1X."""
    res = simulate_breathing_jeffcott(M_DISK, K0, DK, 0.5 * W0, model="open", gravity=0.0,
                                         eccentricity=1e-4, unbalance_angle=0.4)
    assert res.amplitude(1) > 1e-6
    # what is left is the decayed start transient (exp(-12)), not a 2X response
    assert res.amplitude(2) < 1e-5 * res.amplitude(1)
    assert res.amplitude(3) < 1e-5 * res.amplitude(1)


def test_breathing_and_open_cracks_differ_in_odd_harmonics():
    """Under gravity an asymmetric (open) shaft responds only at even orders (static sag + 2X);
    a breathing crack also produces 1X and 3X, which is what distinguishes it."""
    kw = dict(speed=0.45 * W0, gravity=9.81)
    opened = simulate_breathing_jeffcott(M_DISK, K0, DK, model="open", **kw)
    breath = simulate_breathing_jeffcott(M_DISK, K0, DK, model="mayes", **kw)
    ref = opened.amplitude(2)
    assert ref > 1e-5
    assert opened.amplitude(1) < 1e-6 * ref and opened.amplitude(3) < 1e-6 * ref
    assert breath.amplitude(1) > 0.05 * breath.amplitude(2)
    assert breath.amplitude(3) > 0.01 * breath.amplitude(2)


@pytest.mark.slow
def test_gasch_hinge_2x_peak_at_half_critical_speed():
    amp = {r: simulate_breathing_jeffcott(M_DISK, K0, DK, r * W0, model="gasch").amplitude(2)
           for r in (0.4, 0.5, 0.6)}
    assert amp[0.5] > 3 * amp[0.4] and amp[0.5] > 3 * amp[0.6]


def test_jeffcott_input_errors():
    with pytest.raises(ModelError, match="dk < k0"):
        simulate_breathing_jeffcott(1.0, 1e4, 2e4, 50.0)
    with pytest.raises(ModelError, match="crack model"):
        simulate_breathing_jeffcott(1.0, 1e4, 1e3, 50.0, model="hinge")
    with pytest.raises(ModelError, match="speed"):
        simulate_breathing_jeffcott(1.0, 1e4, 1e3, 0.0)


def test_ipopt_recovers_depth_from_compliance():
    """The depth ratio is an optimisation variable with exact derivatives."""
    target = cr.crack_compliance(0.33, E, D, NU)
    x = ca.MX.sym("x")
    c = cr.crack_compliance(x, E, D, NU)
    solver = ca.nlpsol("s", "ipopt", {"x": x, "f": ((c - target) / target)**2},
                       {"ipopt.print_level": 0, "print_time": 0, "ipopt.sb": "yes"})
    sol = solver(x0=0.1, lbx=0.0, ubx=cr.MAX_DEPTH_RATIO)
    assert solver.stats()["success"]
    assert float(sol["x"]) == pytest.approx(0.33, rel=1e-6)


# ----------------------------------------------------------------------------
# crack element in an assembled rotor
# ----------------------------------------------------------------------------

def _shafts(L=0.05, di=0.0):
    from mutext.rotor import ShaftElement
    return [ShaftElement(s, L, D, di, E=E, rho=7800.0, nu=NU, shear=False, rotary_inertia=False)
            for s in range(1, 6)]


@pytest.mark.parametrize("perpendicular", [True, False])
@pytest.mark.parametrize("planes, orientation", [(1, 0.0), (1, 0.6), (1, "mean"), (2, 0.6), (2, "mean")])
def test_crack_element_in_rotor_matches_cracked_element(planes, orientation, perpendicular):
    from mutext.rotor import Rotor
    from mutext.rotor.elements import T_XZ, T_YZ
    L, xi, depth = 0.05, 0.3, 0.4
    healthy = Rotor(_shafts(L), planes=planes)
    cracked = Rotor(_shafts(L) + [cr.Crack(3, depth, xi=xi, orientation=orientation,
                                           perpendicular=perpendicular)], planes=planes)
    dK = cracked.matrices().K - healthy.matrices().K
    n = 2 * planes
    host = slice(2 * n, 4 * n)                   # stations 3 and 4
    c = cr.crack_compliance(depth, E, D, NU)
    c44 = cr.crack_compliance(depth, E, D, NU, component=44) if perpendicular else 0.0
    delta = (cr.cracked_element_stiffness(L, E, I_SHAFT, c, position=xi)
             - cr.cracked_element_stiffness(L, E, I_SHAFT, 0.0))
    delta44 = (cr.cracked_element_stiffness(L, E, I_SHAFT, c44, position=xi)
               - cr.cracked_element_stiffness(L, E, I_SHAFT, 0.0))
    if orientation == "mean":
        mean = (delta + delta44) / 2
        ref = mean if planes == 1 else linalg.block_diag(mean, mean)
    else:
        ref = np.cos(orientation)**2 * delta + np.sin(orientation)**2 * delta44 if planes == 1 else (
            cr.cracked_element_stiffness_two_plane(L, E, I_SHAFT, c, orientation, position=xi,
                                                   compliance_eta=c44)
            - cr.cracked_element_stiffness_two_plane(L, E, I_SHAFT, 0.0, orientation, position=xi))
    if planes == 2:                              # plane-blocked (w, slope) -> station DOFs
        T = np.vstack([np.array(T_XZ), np.array(T_YZ)])
        ref = T.T @ ref @ T
    assert np.allclose(dK[host, host], ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    dK[host, host] = 0
    assert not dK.any()                          # nothing outside the host element
    assert np.array_equal(cracked.matrices().M, healthy.matrices().M)
    # the depth is a parameter: zero depth is the healthy rotor, and K has exact derivatives
    assert "crack3.depth_ratio" in cracked.parameter_names
    K0 = cracked.matrices({"crack3.depth_ratio": 0.0}).K
    assert np.allclose(K0, healthy.matrices().K, rtol=0, atol=1e-12 * np.abs(K0).max())
    p = cracked.p
    k = cracked.parameter_names.index("crack3.depth_ratio")
    J = ca.Function("J", [p], [ca.jacobian(ca.vec(cracked.symbolic["K"]), p[k])])
    h = 1e-6
    v = cracked.values()
    fd = (cracked.matrices({"crack3.depth_ratio": depth + h}).K
          - cracked.matrices({"crack3.depth_ratio": depth - h}).K) / (2 * h)
    jac = np.array(J(v)).reshape(dK.shape, order="F")
    assert np.allclose(jac, fd, rtol=0, atol=1e-5 * np.abs(fd).max())


def test_crack_element_errors():
    from mutext.rotor import Rotor
    with pytest.raises(ModelError, match="depth_ratio must lie"):
        cr.Crack(3, 0.7)
    with pytest.raises(ModelError, match="xi"):
        cr.Crack(3, 0.2, xi=1.5)
    with pytest.raises(ModelError, match="orientation"):
        cr.Crack(3, 0.2, orientation="vertical")
    with pytest.raises(ModelError, match="solid shaft"):
        Rotor(_shafts(di=0.005) + [cr.Crack(3, 0.2)], planes=1)


# ----------------------------------------------------------------------------
# gaping notch or breathing crack, from the slot width (breathing = "auto")
# ----------------------------------------------------------------------------

def _auto_rotor(extra):
    from mutext.rotor import data_path, loads_model
    text = open(data_path("rotor.toml")).read() + "[[crack]]\nstation = 15\ndepth_ratio = 0.4\n" + extra
    return loads_model(text, base_dir=data_path(""))


def _hand_moment_at_15(table):
    """Weight moment at station 15 of the shaft simply supported at stations 2 and 29, by statics
    on the station table (each element's mass split between its ends, plus the added masses)."""
    z = np.concatenate([[0.0], np.cumsum([s.length for s in table.stations])])[:len(table.stations)]
    m = np.array([s.added_mass for s in table.stations], float)
    for i, s in enumerate(table.stations[:-1]):
        me = s.density * np.pi / 4 * (s.outer_diameter ** 2 - s.inner_diameter ** 2) * s.length
        m[i] += me / 2
        m[i + 1] += me / 2
    W = 9.80665 * m
    za, zb = z[1], z[28]                        # stations 2 and 29
    Rb = np.sum(W * (z - za)) / (zb - za)       # moments about the left bearing
    Ra = W.sum() - Rb
    zc = z[14]                                  # station 15
    left = z < zc
    return Ra * (zc - za) - np.sum(W[left] * (zc - z[left]))


def test_auto_breathing_thesis_slot_is_gaping_with_micrometre_faces():
    r = _auto_rotor("breathing = 'auto'\nslot_width = 115e-6\n")
    ch = r.breathing_choices["crack15"]
    cr_el = next(e for e in r.elements if e.name == "crack15")
    assert ch.law == "gaping" and cr_el.breathing == "gaping" and cr_el.breathing_choice is ch
    assert "never touch" in ch.reason
    # hand beam formula: M c / (E I) times a gauge length of one diameter (the crack's local
    # flexibility spreads over about a diameter: l_eq = E I c55 is 0.3-1 D for a/D = 0.4)
    st = r.table.stations[14]
    D, E = st.outer_diameter, st.youngs_modulus
    I = np.pi * D ** 4 / 64
    M_hand = _hand_moment_at_15(r.table)
    assert abs(ch.moment) == pytest.approx(abs(M_hand), rel=0.03)     # statically determinate shaft
    delta_hand = abs(M_hand) * (D / 2) / (E * I) * D
    assert 0.3e-6 < ch.face_displacement < 3e-6
    assert 1 / 3 < ch.face_displacement / delta_hand < 3
    assert ch.face_displacement < 115e-6 / 30


def test_auto_breathing_fatigue_crack_breathes():
    r = _auto_rotor("breathing = 'auto'\nslot_width = 0\nclosing_law = 'gasch'\n")
    assert r.breathing_choices["crack15"].law == "gasch"
    r = _auto_rotor("breathing = 'auto'\nslot_width = 0.0\n")
    assert r.breathing_choices["crack15"].law == "mayes"
    assert next(e for e in r.elements if e.name == "crack15").breathing == "mayes"


@pytest.mark.parametrize("extra, words", [
    ("breathing = 'auto'\n", "needs slot_width"),
    ("breathing = 'auto'\nslot_width = -1e-6\n", "slot_width"),
    ("breathing = 'auto'\nslot_width = 'wide'\n", "slot_width"),
    ("breathing = 'mayes'\nslot_width = 1e-4\n", "only with breathing = 'auto'"),
    ("breathing = 'auto'\nslot_width = 0\nclosing_law = 'gaping'\n", "closing_law"),
])
def test_auto_breathing_named_errors(extra, words):
    with pytest.raises(ModelError) as exc:
        _auto_rotor(extra)
    assert "[[crack]] #1" in str(exc.value) and words in str(exc.value)


def test_gaping_names():
    assert cr.breathing_law("open") == cr.breathing_law("notch") == cr.breathing_law("gaping") == "gaping"
    assert np.array_equal(cr.breathing_fourier("open", 3), cr.breathing_fourier("gaping", 3))
    # the gaping notch varies at 0 and 2x only
    c = cr.breathing_fourier("gaping", 4)
    assert np.all(np.abs(c[[4 - 4, 4 - 3, 4 - 1, 4 + 1, 4 + 3, 4 + 4]]) < 1e-14)
    assert np.max(np.abs(c[4 + 2])) > 0.1
    with pytest.raises(ModelError, match="breathing law"):
        cr.breathing_law("ajar")
