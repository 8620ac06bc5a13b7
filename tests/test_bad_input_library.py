"""Bad input to the library's entry points gets an error that names the problem, never a traceback from
deep inside numpy/scipy and never a silently wrong number (shapes, non-numbers, NaN and infinite values,
absurd scales)."""
import warnings

import control as ct
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.lti import freqresp, hinf_norm, ss, stability

G1 = ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])


@pytest.mark.parametrize("mats, words", [
    ((np.zeros((2, 3)), np.zeros((2, 1)), np.zeros((1, 2)), np.zeros((1, 1))), "A has shape (2, 3)"),
    ((np.eye(2), np.zeros((3, 1)), np.zeros((1, 2)), np.zeros((1, 1))), "B has shape (3, 1)"),
    ((np.eye(2), np.zeros((2, 1)), np.zeros((1, 3)), np.zeros((1, 1))), "C has shape (1, 3)"),
    ((np.eye(2), np.zeros((2, 1)), np.zeros((1, 2)), np.zeros((2, 2))), "D has shape (2, 2)"),
    ((np.ones(2), np.zeros((2, 1)), np.zeros((1, 2)), np.zeros((1, 1))), "1-D array"),
    (("a", "b", "c", "d"), "not a number"),
    (([[None]], [[1.0]], [[1.0]], [[0.0]]), "not a number (None)"),
])
def test_ss_names_the_malformed_matrix(mats, words):
    with pytest.raises(ModelError, match=None) as exc:
        ss(*mats)
    assert words in str(exc.value)


def test_ss_still_accepts_the_usual_forms():
    G = ss([[-1, 0], [0, -2]], [1, 1], [1, 1], 0)       # 1-D B and C, scalar D
    assert G.B.shape == (2, 1) and G.C.shape == (1, 2) and G.D.shape == (1, 1)
    S = ss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((3, 0)), np.ones((3, 2)))   # static gain
    assert S.nstates == 0 and S.D.shape == (3, 2)


@pytest.mark.parametrize("scale", [1e-160, 1e-80, 1e80, 5e299])
def test_hinf_norm_of_extreme_scales_is_the_analytic_value(scale):
    # ||b c / (s + 1)||_inf = |b c| exactly (peak at 0 rad/s); split the scale between B and C unevenly
    b, c = scale ** 0.75, scale ** 0.25
    r = hinf_norm(ss([[-1.0]], [[b]], [[c]], [[0.0]]))
    assert r.value == pytest.approx(b * c, rel=1e-8)
    assert r.lower <= r.value <= r.upper * (1 + 1e-12)


def test_hinf_norm_beyond_the_largest_double_is_inf_not_an_error():
    r = hinf_norm(ss([[-1e-10]], [[1e200]], [[1e200]], [[0.0]]))
    assert r.value == np.inf


@pytest.mark.parametrize("rtol", [float("nan"), 0.0, -1e-3, 1.0, "1e-9", True])
def test_hinf_norm_rejects_a_bad_tolerance(rtol):
    with pytest.raises(ModelError, match="rtol"):
        hinf_norm(G1, rtol=rtol)


def test_hinf_norm_of_an_improper_transfer_function_is_named():
    with pytest.raises(ModelError, match="improper"):
        hinf_norm(ct.tf([1, 0, 0], [1, 1]))


def test_freqresp_names_a_pole_on_the_grid_and_bad_frequencies():
    osc = ss([[0, 1], [-1, 0]], [[0], [1]], [[1, 0]], [[0]])
    with pytest.raises(ModelError, match="pole on the imaginary axis at 1 rad/s"):
        freqresp(osc, [0.5, 1.0, 2.0])
    with pytest.raises(ModelError, match="1-D"):
        freqresp(G1, np.ones((2, 2)))
    for bad in (np.inf, np.nan):
        with pytest.raises(ModelError, match="finite"):
            freqresp(G1, [1.0, bad])
    with pytest.raises(ModelError, match=r"C contains a non-finite entry \(nan\)"):
        freqresp(ss([[-1.0]], [[1.0]], [[np.nan]], [[0.0]]), [1.0])


@pytest.mark.parametrize("margin", [float("nan"), -1.0, float("inf"), "0"])
def test_stability_rejects_a_bad_margin(margin):
    with pytest.raises(ModelError, match="margin"):
        stability(G1, margin=margin)


@pytest.mark.parametrize("spec, words", [([[1]], "pair"), ([[1.7, 0]], "integers"), ([[0, 0]], "not a block"),
                                         ([[-2, 3]], "not a block"), (5, "list of")])
def test_block_structure_spec_is_checked(spec, words):
    from mutext.mu import BlockStructure
    with pytest.raises(ModelError, match=words):
        BlockStructure.from_spec(spec)


def test_block_structure_spec_still_reads_matlab_blk():
    from mutext.mu import BlockStructure
    b = BlockStructure.from_spec([[2, 3], [-1, 0], [2.0, 0]])
    assert [x.kind for x in b] == ["full", "real", "scalar"]


def test_read_frfs_names_a_non_path_entry():
    from mutext.rig import read_frfs
    with pytest.raises(ModelError, match="entry 0 of the list is NoneType"):
        read_frfs([None])


def test_relative_error_checks_lengths():
    from mutext.mbi import relative_error
    w = np.linspace(1, 5, 5)
    with pytest.raises(ModelError, match="weight has shape"):
        relative_error(G1, np.ones(5, complex), w, weight=np.ones(3))


def _chain(m, k):
    from mutext.rotor import loads_model
    return loads_model(f'[[mass]]\nname="m1"\nmass={m}\n[[mass]]\nname="m2"\nmass=1.0\n'
                       f'[[spring]]\nname="k1"\nstiffness={k}\nbetween=["m1","m2"]\n'
                       '[[spring]]\nname="k2"\nstiffness=1.0\nbetween=["m2","ground"]\n')


@pytest.mark.parametrize("m, k", [(1.0, 1e308), (1e-300, 1e300)])
def test_natural_frequencies_that_overflow_are_named(m, k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ModelError, match="overflow"):
            _chain(m, k).natural_frequencies()


def test_mbi_plant_weights_and_regularization_are_checked():
    from mutext.mbi import mbi_plant
    for kw, words in (({"Ww": "abc"}, "Ww must be positive"), ({"Wz": float("nan")}, "Wz must be positive"),
                      ({"regularization": -1.0}, "regularization"), ({"regularization": float("nan")},
                                                                      "regularization")):
        with pytest.raises(ModelError, match=words):
            mbi_plant(G1, G1, excitation="u", measurement="y", control_input="u", control_output="y", **kw)


def test_write_frf_refuses_a_fractional_station(tmp_path):
    from mutext.response import FRF
    from mutext.rig import read_frf, write_frf
    f = np.array([1.0, 2.0])
    h = np.array([1e-3 + 0j, 2e-3 + 1e-4j])
    with pytest.raises(ModelError, match="whole station number, got 12.7"):
        write_frf(tmp_path / "a.csv", FRF(f, h, input_station=1, output_station=12.7))
    write_frf(tmp_path / "b.csv", FRF(f, h, input_station=1, output_station=12.0))
    assert read_frf(tmp_path / "b.csv").output_station == 12


def test_identify_names_an_unknown_dk_option():
    from mutext.examples import three_mass as tm
    from mutext.mbi import identify
    with pytest.raises(ModelError, match="unknown option.*'bogus'"):
        identify(**tm.mbi_arguments(tm.TRIALS["1a"]), dk_options={"bogus": 1}, max_tries=1)


@pytest.mark.parametrize("override, words", [
    ({"bearing2.k": -1e8}, ["bearing2.k", "non-negative", "-1e+08"]),
    ({"bearing2.c": float("nan")}, ["bearing2.c", "finite"]),
    ({"bearing2.k": "abc"}, ["bearing2.k", "number"]),
    ({"shaft1.L": 0.0}, ["shaft1.L", "positive"]),
])
def test_values_set_through_values_obey_the_model_files_rules(override, words):
    # the model file refuses a negative bearing stiffness at parse; the same value set through
    # values= must be refused too, not turned into a rotor that grows without bound
    from mutext.examples.cracked_rotor import healthy_rotor
    model = healthy_rotor()
    with pytest.raises(ModelError) as err:
        model.matrices(override)
    for w in words:
        assert w in str(err.value)
    v = model.values()
    v[model.parameter_names.index(next(iter(override)))] = -1.0
    with pytest.raises(ModelError, match="must be"):
        model.matrices(v)
    assert np.all(np.isfinite(model.matrices({"bearing2.k": 0.0}).K))   # zero is allowed for a bearing
