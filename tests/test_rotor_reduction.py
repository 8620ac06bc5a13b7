"""Model reduction of rotor models: modal truncation with static correction, balanced truncation."""
import control as ct
import numpy as np
import pytest

from mutext.errors import IllPosedError, ModelError
from mutext.lti import balance_states, freqresp, mck_to_ss
from mutext.rotor import data_path, load_model, loads_model
from mutext.rotor.reduction import (balanced_truncation, hankel_singular_values, modal_truncation,
                                    reduction_error)

try:
    import slycot
except ImportError:          # the comparisons with SLICOT are skipped, the rest still runs
    slycot = None
needs_slycot = pytest.mark.skipif(slycot is None, reason="slycot (SLICOT) is not installed")

BEAM = """
name = "test beam"
planes = 1
[shaft]
poisson_ratio = 0.3
{stations}
[[bearing]]
station = 1
stiffness = 2.0e6
[[bearing]]
station = {n}
stiffness = 2.0e6
[[force]]
station = 3
[[sensor]]
station = {s}
[[sensor]]
station = 3
[damping]
modal = 0.02
"""


FREE = """
planes = 1
[shaft]
poisson_ratio = 0.3
[[station]]
length = 0.1
outer_diameter = 0.03
youngs_modulus = 2.1e11
density = 7800
[[station]]
outer_diameter = 0.03
youngs_modulus = 2.1e11
density = 7800
[[force]]
station = 1
[[sensor]]
station = 2
"""


def beam(n=9, sensor=7):
    rows = []
    for k in range(1, n + 1):
        rows.append("[[station]]")
        if k < n:
            rows.append("length = 0.1\nouter_diameter = 0.03\nyoungs_modulus = 2.1e11\ndensity = 7800")
        else:
            rows.append("outer_diameter = 0.03\nyoungs_modulus = 2.1e11\ndensity = 7800")
    return loads_model(BEAM.format(stations="\n".join(rows), n=n, s=sensor), source="beam")


@pytest.fixture(scope="module")
def bm():
    return beam()


def static_gain(model, inp, out):
    M, C, K, G = model.matrices()
    B = model.input_matrix()[:, model.input_names.index(inp)]
    return np.linalg.solve(K, B)[model.output_dofs[model.output_names.index(out)]]


def dc(sys):
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    return D - C @ np.linalg.solve(A, B)


# ----------------------------------------------------------------------------
# modal truncation
# ----------------------------------------------------------------------------

def test_modal_error_decreases_with_kept_modes(bm):
    # Driving-point FRF (force and sensor at station 3): every deleted mode adds a residual of the
    # same sign, phi_r(3)^2 w^2 / (w_r^2 (w_r^2 - w^2)), so keeping more modes must reduce the
    # error.  (For a transfer FRF the residuals of successive modes can cancel, and the band error
    # need not decrease at every step.)
    f = bm.natural_frequencies()
    band = (0.3 * f[0], 1.2 * f[1])
    errs, hinfs, orders = [], [], []
    for r in (2, 3, 4, 6):
        cut = 0.5 * (f[r - 1] + f[r])
        red = modal_truncation(bm, cut, outputs=["x3"], band_hz=band)
        assert red.order == 2 * r
        assert np.allclose(red.kept_frequencies_hz, f[:r] / np.sqrt(1 - 0.02**2), rtol=1e-9)  # undamped
        errs.append(red.max_relative_error)
        hinfs.append(red.hinf_error)
        orders.append(red.order)
    assert all(a > b for a, b in zip(errs, errs[1:])), errs
    assert all(a > b for a, b in zip(hinfs, hinfs[1:])), hinfs
    assert errs[-1] < 1e-3
    # the reported H-infinity error is the peak of the sampled error (certified lower bound)
    red = modal_truncation(bm, 0.5 * (f[2] + f[3]), outputs=["x3"], band_hz=band)
    w = np.linspace(0, 2 * np.pi * 1.5 * f[-1], 20000)
    E = freqresp(red.full, w) - freqresp(red.system, w)
    assert np.max(np.abs(E)) <= red.hinf_error * (1 + 1e-6)


def test_static_correction_makes_dc_gain_exact(bm):
    f = bm.natural_frequencies()
    exact = static_gain(bm, "F3", "x7")
    with_sc = modal_truncation(bm, 0.5 * (f[1] + f[2]), outputs=["x7"], hinf=False)
    without = modal_truncation(bm, 0.5 * (f[1] + f[2]), outputs=["x7"], static_correction=False, hinf=False)
    assert dc(with_sc.system)[0, 0] == pytest.approx(exact, rel=1e-10)
    assert abs(dc(without.system)[0, 0] / exact - 1) > 1e-3      # truncation alone misses the residual
    assert with_sc.max_relative_error < 0.2 * without.max_relative_error
    assert np.asarray(with_sc.system.D)[0, 0] != 0 and np.asarray(without.system.D)[0, 0] == 0


def test_modal_keeps_port_names_and_state_space_path_agrees(bm):
    f = bm.natural_frequencies()
    cut = 0.5 * (f[2] + f[3])
    red = modal_truncation(bm, cut, hinf=False)
    assert list(red.system.input_labels) == ["F3"] and list(red.system.output_labels) == ["x7", "x3"]
    assert red.system.state_labels[0] == "eta1"
    # the same truncation done on the eigenvalues of A (proportional damping: |lambda_r| = omega_r)
    red_ss = modal_truncation(bm.state_space(), cut, hinf=False)
    assert red_ss.order == red.order
    assert list(red_ss.system.input_labels) == ["F3"]
    w = 2 * np.pi * np.linspace(1.0, 2 * f[3], 300)
    H1, H2 = freqresp(red.system, w), freqresp(red_ss.system, w)
    assert np.max(np.abs(H1 - H2) / np.abs(H1)) < 1e-7
    assert dc(red_ss.system)[0, 0] == pytest.approx(static_gain(bm, "F3", "x7"), rel=1e-8)
    assert dc(red_ss.system)[1, 0] == pytest.approx(static_gain(bm, "F3", "x3"), rel=1e-8)


def test_modal_rotor_at_speed_keeps_gyroscopic_coupling():
    rotor = load_model(data_path("rotor.toml"))
    red = modal_truncation(rotor, 400.0, inputs=["i12"], outputs=["x13", "y13"], band_hz=(20, 225), hinf=False)
    # the x-y cross response exists only through the gyroscopic terms, which the projection keeps
    w = 2 * np.pi * np.array([30.0, 100.0, 190.0])
    H, Hr = freqresp(red.full, w), freqresp(red.system, w)
    assert np.all(np.abs(Hr[1, 0]) > 0)
    assert np.max(np.abs(Hr - H) / np.abs(H).max(axis=(0, 1))) < 0.1
    assert red.max_relative_error < 0.1


def test_modal_errors(bm):
    f = bm.natural_frequencies()
    with pytest.raises(ModelError, match="positive"):
        modal_truncation(bm, -1.0)
    with pytest.raises(ModelError, match="no mode below"):
        modal_truncation(bm, 0.5 * f[0])
    free = loads_model(FREE, source="free beam")
    with pytest.raises(ModelError, match="rigid-body"):
        modal_truncation(free, 1e5, hinf=False)
    with pytest.raises(ModelError, match="structural model"):
        modal_truncation(bm.state_space(), 100.0, inputs=["F3"])


# ----------------------------------------------------------------------------
# balanced truncation
# ----------------------------------------------------------------------------

def slycot_hsv(sys):
    """Hankel singular values from SLICOT AB09AD (square-root method, Hammarling factors)."""
    A, B, C = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C))
    *_, hsv = slycot.ab09ad("C", "B", "N", A.shape[0], B.shape[1], C.shape[0], A, B, C, nr=1, tol=0.0)
    return hsv


@needs_slycot
def test_hankel_singular_values_agree_with_slycot(bm):
    G = bm.state_space()
    Gs, _ = balance_states(G)            # same Hankel singular values, better scaled for SLICOT too
    ref = slycot_hsv(Gs)
    ours = hankel_singular_values(G)
    assert ours.shape == ref.shape
    sig = ref > 1e-6 * ref[0]
    assert np.sum(sig) >= 10
    assert np.max(np.abs(ours[sig] - ref[sig]) / ref[sig]) < 1e-6
    # and with python-control's hsvd (Gramians by SLICOT SB03MD, eigenvalues of P Q)
    hs = ct.hsvd(Gs)
    assert np.max(np.abs(ours[:6] - hs[:6]) / hs[:6]) < 1e-6


@needs_slycot
def test_balanced_bound_and_slycot_error(bm):
    G = bm.state_space()
    Gs, _ = balance_states(G)
    prev = np.inf
    for r in (2, 4, 6, 8, 10):
        red = balanced_truncation(G, r)
        hsv = red.hankel_singular_values
        assert red.bound == pytest.approx(2 * np.sum(hsv[r:]), rel=1e-12)
        assert red.hinf_error <= red.bound * (1 + 1e-8)
        # the error cannot be smaller than the first discarded Hankel singular value
        assert red.hinf_error >= hsv[r] * (1 - 1e-6)
        ref = reduction_error(G, ct.balred(Gs, r), hinf=True)["hinf"]
        assert red.hinf_error == pytest.approx(ref, rel=0.05), (r, red.hinf_error, ref)
        assert red.hinf_error < prev
        prev = red.hinf_error
        assert list(red.system.output_labels) == ["x7", "x3"] and red.system.nstates == r
        assert np.all(np.linalg.eigvals(np.asarray(red.system.A)).real < 0)


def test_balanced_order_from_max_error(bm):
    G = bm.state_space()
    red = balanced_truncation(G, max_error=1e-3 * hankel_singular_values(G)[0])
    assert red.bound <= 1e-3 * red.hankel_singular_values[0]
    smaller = balanced_truncation(G, red.order - 1, hinf=False)
    assert smaller.bound > 1e-3 * red.hankel_singular_values[0]


def test_balanced_accepts_structural_model(bm):
    a = balanced_truncation(bm, 6, hinf=False)
    b = balanced_truncation(bm.state_space(), 6, hinf=False)
    w = 2 * np.pi * np.linspace(10, 500, 50)
    assert np.allclose(freqresp(a.system, w), freqresp(b.system, w), rtol=1e-10, atol=0)


def test_balanced_errors(bm):
    G = bm.state_space()
    with pytest.raises(ModelError, match="order must be"):
        balanced_truncation(G, 0)
    with pytest.raises(ModelError, match="order must be"):
        balanced_truncation(G, G.nstates + 1)
    with pytest.raises(ModelError, match="exactly one"):
        balanced_truncation(G)
    unstable = mck_to_ss(np.eye(1), [[-0.1]], [[1.0]], inputs={"f": 0}, outputs={"x": 0})
    with pytest.raises(IllPosedError, match="stable"):
        balanced_truncation(unstable, 1)
    # two identical channels: the model has order 2 although it has 4 states
    M, K = np.eye(2), np.diag([1.0, 1.0])
    twin = mck_to_ss(M, 0.1 * K, K, inputs={"f": np.array([1.0, 1.0])}, outputs={"x": np.array([1.0, 1.0])})
    with pytest.raises(ModelError, match="minimal order"):
        balanced_truncation(twin, 3)


@pytest.mark.slow
@needs_slycot
def test_thesis_rotor_reduction_against_slycot():
    rotor = load_model(data_path("rotor.toml"))
    G = rotor.state_space(inputs=["i12"], outputs=["x13"])
    Gs, _ = balance_states(G)
    ref = slycot_hsv(Gs)
    ours = hankel_singular_values(G)
    sig = ref > 1e-4 * ref[0]
    assert np.max(np.abs(ours[sig] - ref[sig]) / ref[sig]) < 1e-6
    for r in (12,):
        red = balanced_truncation(G, r, band_hz=(20, 225))
        assert red.hinf_error <= red.bound
        ref_err = reduction_error(G, ct.balred(Gs, r), hinf=True)["hinf"]
        assert red.hinf_error == pytest.approx(ref_err, rel=0.05)
    red = modal_truncation(rotor, 1000.0, inputs=["i12"], outputs=["x13"], band_hz=(20, 225), hinf=False)
    assert red.max_relative_error < 5e-3
