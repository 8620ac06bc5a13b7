"""Model-based identification as convex worst-case model matching (mutext.mbi.identify_convex).

The references are independent of the package's LFT and mu code: the closed loop rebuilt with
python-control's ``feedback`` and evaluated on true systems drawn anew from the uncertainty box,
brute-force minimal enclosing circles, a one-coefficient program solved by a grid search, and
the known missing spring of a trial without uncertainty.
"""
from __future__ import annotations

import itertools

import control as ct
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.examples import three_mass as tm
from mutext.mbi import ConvexMBIResult, chebyshev_radius, identify, identify_convex, model_matching, wz_floor


#: a grid of 100 frequencies over the rig's modes (the default 300 and the certificate's 200 take
#: several seconds per mu sweep)
W = np.logspace(-0.3, 1.6, 100)


@pytest.fixture(scope="module")
def trial_1a():
    return identify_convex(**tm.mbi_arguments(tm.TRIALS["1a"]), omega=W, final_points=40)


def _response(sys, omega):
    """Frequency response of a SISO python-control system (no mutext code)."""
    return np.asarray(ct.frequency_response(sys, omega).complex).reshape(-1)


def _controlled_by_python_control(engineering, K):
    """x1/f1 of the engineering model with the force -K x3 at cart 3, by ``control.feedback``."""
    Kss = ct.ss(K.A, K.B, K.C, K.D)
    # from the outputs [x1, x3] to the inputs [f1, f3]: only f3 = -K x3 (feedback's sign -1)
    Kmat = ct.ss(Kss.A, np.hstack([np.zeros((Kss.nstates, 1)), Kss.B]),
                 np.vstack([np.zeros((1, Kss.nstates)), Kss.C]),
                 np.array([[0.0, 0.0], [0.0, float(Kss.D[0, 0])]]))
    G = ct.ss(engineering.A, engineering.B, engineering.C, engineering.D)
    CL = ct.feedback(G, Kmat, sign=-1)
    return CL[0, 0]


def test_certified_bound_holds_on_fresh_true_systems(trial_1a):
    r = trial_1a
    assert isinstance(r, ConvexMBIResult)
    assert r.mu_upper <= 1.0
    args = tm.mbi_arguments(tm.TRIALS["1a"])
    F = _controlled_by_python_control(args["engineering"], r.K)
    U = args["true"]
    w = np.logspace(np.log10(r.omega.min()), np.log10(r.omega.max()), 1500)
    Fw = _response(F, w)
    rng = np.random.default_rng(7)
    for d in np.concatenate([U.corners(), rng.uniform(-1, 1, size=(6, 1))]):
        T = U.close(d)
        xt = _response(ct.ss(T.A, T.B, T.C, T.D)[list(T.output_labels).index("x1"),
                                                  list(T.input_labels).index("f1")], w)
        assert np.max(np.abs(xt - Fw)) <= r.Wz * (1 + 1e-9)
    # the loop through python-control is the package's controlled model
    assert np.allclose(Fw, _response(ct.ss(r.controlled.A, r.controlled.B, r.controlled.C, r.controlled.D), w),
                       rtol=1e-6, atol=1e-9 * np.abs(Fw).max())


def test_bounds_are_ordered(trial_1a):
    r = trial_1a
    floor = wz_floor(tm.true_model(tm.TRIALS["1a"]), excitation="f1", measurement="x1", omega=r.omega)
    # the Chebyshev radius refines half the widest gap, the basis cannot beat a free response,
    # and the certificate cannot beat the samples
    assert r.lower >= floor.value * (1 - 1e-6)
    assert r.gamma >= r.lower * (1 - 1e-6)
    assert r.Wz >= r.gamma
    assert r.gamma <= 1.001 * r.lower          # the basis is rich enough on this trial
    assert r.Wz <= 1.03 * r.lower
    assert r.fit.dk == pytest.approx(186.0, rel=0.01)


def test_youla_recovers_the_missing_spring_without_uncertainty():
    """A certain true system: the optimum is 0 and K is the missing spring dk = 186 N/m."""
    tr = tm.TRIALS["1a"]
    args = tm.mbi_arguments(tr)
    args["true"] = tm.mechanical_model(tr.true)
    r = identify_convex(**args, omega=W, final_points=40)
    T, E = (ct.ss(S.A, S.B, S.C, S.D) for S in (args["true"], args["engineering"]))   # x1/f1 is [0, 0]
    open_loop = np.max(np.abs(_response(T[0, 0], r.omega) - _response(E[0, 0], r.omega)))
    assert r.lower == 0.0
    assert r.mu_upper <= 1.0 and r.Wz < 1e-6 * open_loop
    w = np.logspace(0, np.log10(20.0), 25)
    Kw = _response(ct.ss(r.K.A, r.K.B, r.K.C, r.K.D), w)
    assert np.max(np.abs(Kw - tr.Du["dk"])) < 1e-4 * tr.Du["dk"]


def _enclosing_radius(points) -> float:
    """Smallest enclosing circle by brute force over pairs and triples."""
    pts = np.asarray(points, complex)
    best = np.inf
    for a, b in itertools.combinations(pts, 2):
        c, rad = (a + b) / 2, abs(a - b) / 2
        if np.all(np.abs(pts - c) <= rad * (1 + 1e-12)):
            best = min(best, rad)
    for a, b, c3 in itertools.combinations(pts, 3):
        # circumcentre
        ax, ay, bx, by, cx, cy = a.real, a.imag, b.real, b.imag, c3.real, c3.imag
        d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
        if abs(d) < 1e-14:
            continue
        ux = ((ax ** 2 + ay ** 2) * (by - cy) + (bx ** 2 + by ** 2) * (cy - ay) + (cx ** 2 + cy ** 2) * (ay - by)) / d
        uy = ((ax ** 2 + ay ** 2) * (cx - bx) + (bx ** 2 + by ** 2) * (ax - cx) + (cx ** 2 + cy ** 2) * (bx - ax)) / d
        centre = ux + 1j * uy
        rad = abs(a - centre)
        if np.all(np.abs(pts - centre) <= rad * (1 + 1e-12)):
            best = min(best, rad)
    return best


def test_chebyshev_radius_against_brute_force():
    rng = np.random.default_rng(3)
    X = rng.normal(size=(9, 5)) + 1j * rng.normal(size=(9, 5))
    X[:, 4] = X[:, 4] * 1e-4 + 2.0                   # a tiny cluster far from 0
    r, c = chebyshev_radius(X)
    for k in range(X.shape[1]):
        ref = _enclosing_radius(X[:, k])
        assert r[k] == pytest.approx(ref, rel=1e-5)
        assert np.max(np.abs(X[:, k] - c[k])) <= r[k] * (1 + 1e-5)


def test_model_matching_against_a_grid_search():
    """One real coefficient: min_q max_ik |X_ik - F0_k - a_k q| by brute force over q."""
    rng = np.random.default_rng(5)
    nw = 12
    a = rng.normal(size=nw) + 1j * rng.normal(size=nw)
    X = 0.7 * a[None, :] + 0.05 * (rng.normal(size=(4, nw)) + 1j * rng.normal(size=(4, nw)))
    F0 = np.zeros(nw)
    g, q, _ = model_matching(X, F0, a[:, None])
    qs = np.linspace(0.0, 1.4, 140001)
    worst = np.array([np.max(np.abs(X - qq * a[None, :])) for qq in qs[::100]])
    q0 = qs[::100][np.argmin(worst)]
    fine = np.linspace(q0 - 2e-3, q0 + 2e-3, 4001)
    worst = np.array([np.max(np.abs(X - qq * a[None, :])) for qq in fine])
    assert g == pytest.approx(worst.min(), rel=1e-5)
    assert q[0] == pytest.approx(fine[np.argmin(worst)], abs=2e-5)


def test_free_free_engineering_model_is_refused():
    tr = tm.TRIALS["1a"]
    args = tm.mbi_arguments(tr)
    free = tr.engineering.with_(k3=0.0, c1=0.0, c2=0.0, c3=0.0)
    args["engineering"] = tm.mechanical_model(free)
    with pytest.raises(ModelError, match="engineering model is not stable"):
        identify_convex(**args)


def test_identify_chooses_the_convex_route_by_default(trial_1a):
    """method='auto': the convex route without D-K options (same result as identify_convex), the
    D-K search with them, and D-K for an engineering model the Youla parameterisation cannot take."""
    from mutext.mbi._identify import _convex_applies
    args = tm.mbi_arguments(tm.TRIALS["1a"])
    r = identify(**args, omega=W)
    assert isinstance(r, ConvexMBIResult) and r.dk is None
    assert r.mu_upper <= 1.0 and r.Wz == pytest.approx(trial_1a.Wz, rel=0.01)   # (a finer certificate grid)
    assert not _convex_applies(args["engineering"], None, 1e-4, {"max_iter": 1}, False, False)
    assert not _convex_applies(args["engineering"], 4e-4, 1e-4, None, False, False)
    free = tm.mechanical_model(tm.TRIALS["1a"].engineering.with_(k3=0.0, c1=0.0, c2=0.0, c3=0.0))
    assert not _convex_applies(free, None, 1e-4, None, False, False)
    assert _convex_applies(args["engineering"], None, 1e-4, None, False, False)


def test_identify_method_switch():
    args = tm.mbi_arguments(tm.TRIALS["1a"])
    with pytest.raises(ModelError, match="method must be"):
        identify(**args, method="lmi")
    with pytest.raises(ModelError, match="belong"):
        identify(**args, method="convex", dk_options={"max_iter": 1})
    with pytest.raises(ModelError, match="margin"):
        identify_convex(**args, margin=-1.0)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["4", "5"])
def test_three_parameter_trials_certified(name):
    r = identify(**tm.mbi_arguments(tm.TRIALS[name]), method="convex", tol=0.05)
    assert isinstance(r, ConvexMBIResult)
    assert r.mu_upper <= 1.0
    assert r.gamma <= 1.001 * r.lower
    assert r.Wz <= 1.2 * r.lower


def test_polish_stays_within_its_slack_and_moves_toward_the_target():
    """The second stage keeps the bound within (1 + polish) of the optimum and is closer to the target."""
    rng = np.random.default_rng(11)
    nw, m = 30, 4
    A = rng.normal(size=(nw, m)) + 1j * rng.normal(size=(nw, m))
    base = A @ np.array([0.5, -0.2, 0.1, 0.3])
    X = base[None, :] + 0.05 * (rng.normal(size=(5, nw)) + 1j * rng.normal(size=(5, nw)))
    target = base + 0.01
    g, q1, _ = model_matching(X, np.zeros(nw), A)
    g2, q2, _ = model_matching(X, np.zeros(nw), A, polish=0.05, target=target)
    assert g2 == pytest.approx(g)
    assert np.max(np.abs(X - (A @ q2)[None, :])) <= g * 1.05 * (1 + 1e-5)
    assert np.sum(np.abs(target - A @ q2)) <= np.sum(np.abs(target - A @ q1)) * (1 + 1e-6)


def test_a_measured_frf_has_no_spread_to_shape_by():
    from mutext.rig import measure
    tr = tm.TRIALS["1a"]
    args = tm.mbi_arguments(tr)
    args["true"] = measure(tm.mechanical_model(tr.true), "f1", "x1", np.arange(0.2, 10.0, 0.05), noise=0.0,
                           rng=0, input_station=1, output_station=1)
    with pytest.raises(ModelError, match="measured FRF has none"):
        identify_convex(**args, weight="spread")


# slow (about 50 CPU-s): the shaped bound on trial 5, three solves of the program and branch and bound
@pytest.mark.slow
def test_bound_shaped_by_the_spread_on_trial_5():
    r = identify_convex(**tm.mbi_arguments(tm.TRIALS["5"]), weight="spread")
    assert r.mu_upper <= 1.0
    assert r.plant.Wz_shape is not None
    assert r.Wz >= r.lower >= r.floor.value * (1 - 1e-6)
    assert r.Wz <= 1.1 * r.lower               # the D-K search stops at 1.39 times its floor here
    # the shaped bound holds K over the band: the spring read to within the box's spread
    assert r.fit.dk == pytest.approx(186.0, rel=0.1)
