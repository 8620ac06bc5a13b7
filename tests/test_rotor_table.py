"""Rotor input files: station tables (thesis appendix format), unit conversion, TOML model files."""
import math
import os

import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.examples import three_mass
from mutext.rotor import data_path, load_model, loads_model, parse_station_table, read_station_table
from mutext.rotor import units as U

ROW = "0 1.0 0.63 0 0 0 30 0.3 0 0 0 0"
LAST = "0 0 0.63 0 0 0 30 0.3 0 0 0 0"


def table(*rows):
    return "\n".join(rows) + "\n"


# ----------------------------------------------------------------------------- units

def test_unit_factors_exact():
    assert U.INCH == 0.0254
    assert U.POUND_MASS == 0.45359237
    assert math.isclose(U.POUND_FORCE, 4.4482216152605, rel_tol=1e-14)
    assert math.isclose(U.PSI, 6894.757293168361, rel_tol=1e-14)
    assert math.isclose(U.to_si(1.0, "density", "inch-pound"), 27679.904710203125, rel_tol=1e-12)
    assert math.isclose(U.to_si(1.0, "inertia", "inch-pound"), 0.45359237 * 0.0254**2, rel_tol=1e-14)
    assert math.isclose(U.to_si(1.0, "stiffness", "inch-pound"), 175.12683524647636, rel_tol=1e-12)
    assert U.to_si(3.0, "length", "SI") == 3.0
    assert math.isclose(U.from_si(U.to_si(2.5, "modulus", "inch-pound"), "modulus", "inch-pound"), 2.5)
    assert math.isclose(U.rpm_to_rad_s(60.0), 2 * math.pi)
    with pytest.raises(ModelError, match="unknown unit system"):
        U.to_si(1.0, "length", "imperial")
    with pytest.raises(ModelError, match="unknown quantity"):
        U.to_si(1.0, "speed_of_light")


def test_pound_mass_reading_equals_weight_over_g0():
    # 4.81 lb read as lbm equals 4.81 lbf divided by g0 = 386.0886 in/s^2 in lbf s^2/in, converted to kg
    g0_in = U.STANDARD_GRAVITY / U.INCH
    slinch = U.POUND_FORCE / U.INCH          # kg per (lbf s^2 / in)
    assert math.isclose(U.to_si(4.81, "mass", "inch-pound"), 4.81 / g0_in * slinch, rel_tol=1e-13)


# ----------------------------------------------------------------------------- station table

def test_thesis_tables_read_in_si():
    h = read_station_table(data_path("rotor_healthy.txt"))
    c = read_station_table(data_path("rotor_cracked.txt"))
    assert len(h) == len(c) == 30
    assert math.isclose(h.total_length, 26.001 * 0.0254, rel_tol=1e-12)     # "26 in long"
    s16 = h[16]
    assert math.isclose(s16.added_mass, 4.81 * 0.45359237, rel_tol=1e-12)
    assert math.isclose(c[16].added_mass, 5.21 * 0.45359237, rel_tol=1e-12)
    assert math.isclose(s16.added_polar_inertia, 21.1 * 0.45359237 * 0.0254**2, rel_tol=1e-12)
    assert math.isclose(s16.added_transverse_inertia, 12.01 * 0.45359237 * 0.0254**2, rel_tol=1e-12)
    assert math.isclose(h[1].youngs_modulus, 30e6 * U.PSI, rel_tol=1e-12)     # 206.8 GPa
    assert math.isclose(h[1].density, 0.3 * 27679.904710203125, rel_tol=1e-12)
    assert math.isclose(c[1].density, 0.29 * 27679.904710203125, rel_tol=1e-12)
    assert math.isclose(h[12].outer_diameter, 1.88 * 0.0254)
    assert h.flagged("translational_input") == [2, 12, 15, 29]
    assert h.flagged("translational_output") == [2, 6, 13, 15, 24, 29]
    assert h.flagged("rotational_input") == [] and h.flagged("rotational_output") == []
    # exciter and sensor 0.05 in apart
    assert math.isclose(h.positions[12] - h.positions[11], 0.05 * 0.0254, rel_tol=1e-9)
    # the two tables differ only in density and the disk weight
    for a, b in zip(h, c):
        if a.number != 16:
            assert a.added_mass == b.added_mass
        assert (a.length, a.outer_diameter, a.inner_diameter) == (b.length, b.outer_diameter, b.inner_diameter)


def test_comments_and_blank_lines_ignored():
    t = parse_station_table("# header\n\n" + ROW + "  # trailing comment\n   \n" + LAST + "\n# end\n")
    assert len(t) == 2 and t[1].source == "<string>:3"


@pytest.mark.parametrize("text, match", [
    (table("0 1.0 0.63 0 0 0 30 0.3 0 0 0", LAST), r"f\.txt, line 1: expected 12 columns.*found 11"),
    (table(ROW, "0 0 0.63 0 0 0 30 0.3 0 0 0 0 7"), r"line 2: expected 12 columns.*found 13"),
    (table("0 1.0 abc 0 0 0 30 0.3 0 0 0 0", LAST), r"line 1, column 3 \(outer_diameter \[in\]\): 'abc' is not a number"),
    (table("0 1.0 0.63 0 0 0 30 nan 0 0 0 0", LAST), r"line 1, column 8 \(density.*not finite"),
    (table("0 -1.0 0.63 0 0 0 30 0.3 0 0 0 0", LAST), r"line 1, column 2 \(length \[in\]\): must be non-negative"),
    (table("0 1.0 -0.63 0 0 0 30 0.3 0 0 0 0", LAST), r"column 3 \(outer_diameter.*non-negative"),
    (table("-1 1.0 0.63 0 0 0 30 0.3 0 0 0 0", LAST), r"column 1 \(added_mass \[lb\]\).*non-negative"),
    (table("0 1.0 0.63 0 0 -2 30 0.3 0 0 0 0", LAST), r"column 6 \(added_transverse_inertia"),
    (table("0 1.0 0.63 0.63 0 0 30 0.3 0 0 0 0", LAST), r"column 4 \(inner_diameter.*smaller than the outer"),
    (table("0 1.0 0.63 0.8 0 0 30 0.3 0 0 0 0", LAST), r"column 4 \(inner_diameter"),
    (table("0 1.0 0.63 0 0 0 0 0.3 0 0 0 0", LAST), r"column 7 \(youngs_modulus \[Mpsi\]\): must be positive"),
    (table("0 1.0 0.63 0 0 0 30 0 0 0 0 0", LAST), r"column 8 \(density \[lb/in\^3\]\): must be positive"),
    (table("0 1.0 0.63 0 0 0 30 0.3 2 0 0 0", LAST), r"column 9 \(translational_input.*0 or 1, got 2"),
    (table("0 1.0 0.63 0 0 0 30 0.3 0 0 0 0.5", LAST), r"column 12 \(rotational_output.*0 or 1"),
    (table(ROW, ROW), r"line 2, column 2 \(length.*last station \(station 2\) must have length 0"),
    (table(ROW, LAST.replace("0 0 0.63", "0 0 0.63"), LAST), r"line 2, column 2.*station 2 has a zero-length"),
    (table("0 1.0 0 0 0 0 30 0.3 0 0 0 0", LAST), r"column 3.*zero outer diameter"),
    (table(LAST), r"at least 2 stations"),
    ("# only comments\n", r"at least 2 stations"),
])
def test_table_errors_name_file_line_column(text, match):
    with pytest.raises(ModelError, match=match) as ei:
        parse_station_table(text, source="f.txt")
    assert str(ei.value).startswith("f.txt")


def test_table_missing_file():
    with pytest.raises(ModelError, match="cannot read station table 'nope.txt'"):
        read_station_table("nope.txt")


# ----------------------------------------------------------------------------- model files

def test_three_mass_toml_equals_example():
    s = load_model(data_path("three_mass.toml"))
    M, C, K, G = s.matrices()
    M0, C0, K0 = three_mass.matrices(three_mass.TABLE_3_1)
    np.testing.assert_array_equal(M, M0)
    np.testing.assert_array_equal(C, C0)
    np.testing.assert_array_equal(K, K0)
    assert not G.any()
    assert s.dof_names == ["m1", "m2", "m3"]
    assert s.input_names == ["f1", "f3"] and s.output_names == ["x1", "x3"]
    # same transfer function as the example's state-space model
    from mutext.lti import freqresp
    w = np.array([0.3, 3.0, 12.0, 40.0])
    np.testing.assert_allclose(freqresp(s.state_space(), w), freqresp(three_mass.mechanical_model(), w),
                               rtol=1e-12)
    # parameters are named by the file's names and are symbolic
    assert s.parameter("k3").value == 386.0
    M, C, K, _ = s.matrices({"k3": 200.0, "m3": 1.6074})
    assert K[2, 2] == 806.5 + 200.0 and M[2, 2] == 1.6074


def test_thesis_rotor_toml():
    r = load_model(data_path("rotor.toml"))
    assert r.n_stations == 30 and r.ndof == 120 and r.planes == 2
    assert math.isclose(r.speed, 20 * math.pi)
    assert "i12" in r.input_names and "x13" in r.output_names and "F12" in r.input_names
    assert r.parameter("bearing2.k").value == 1e7 and r.parameter("bearing29.k").value == 1e7
    assert r.parameter("exciter12.ki").value == 40.0
    assert math.isclose(r.parameter("rho").value, 0.3 * 27679.904710203125)
    assert math.isclose(r.parameter("disk16.m").value, 4.81 * 0.45359237)
    c = load_model(data_path("rotor.toml"), station_table=data_path("rotor_cracked.txt"))
    assert math.isclose(c.parameter("rho").value, 0.29 * 27679.904710203125)


def _write(tmp_path, text, name="m.toml"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


INLINE = """
name = "two-element shaft"
[shaft]
poisson_ratio = 0.3
[[station]]
length = 0.5
outer_diameter = 0.05
youngs_modulus = 2.0e11
density = 7800
[[station]]
length = 0.5
outer_diameter = 0.05
youngs_modulus = 2.0e11
density = 7800
[[station]]
"""


def test_inline_stations_and_units(tmp_path):
    r = load_model(_write(tmp_path, INLINE + '[[bearing]]\nstation = 1\nstiffness = 1e6\n'))
    assert r.n_stations == 3 and math.isclose(r.positions[-1], 1.0)
    assert r.parameter("bearing1.k").value == 1e6
    # the same model in inch-pound units gives the same matrices
    ip = f"""
units = "inch-pound"
[shaft]
poisson_ratio = 0.3
[[station]]
length = {0.5 / 0.0254}
outer_diameter = {0.05 / 0.0254}
youngs_modulus = {2e11 / U.PSI}
density = {7800 / U.to_si(1, 'density', 'inch-pound')}
[[station]]
length = {0.5 / 0.0254}
outer_diameter = {0.05 / 0.0254}
youngs_modulus = {2e11 / U.PSI}
density = {7800 / U.to_si(1, 'density', 'inch-pound')}
[[station]]
[[bearing]]
station = 1
stiffness = {1e6 / U.to_si(1, 'stiffness', 'inch-pound')}
"""
    r2 = load_model(_write(tmp_path, ip, "ip.toml"))
    for A, B in zip(r.matrices(), r2.matrices()):
        np.testing.assert_allclose(A, B, rtol=1e-12, atol=1e-12 * np.abs(A).max())


def test_station_table_path_is_relative_to_the_model_file(tmp_path):
    sub = tmp_path / "tables"
    sub.mkdir()
    (sub / "t.txt").write_text(open(data_path("rotor_healthy.txt")).read())
    r = load_model(_write(tmp_path, '[shaft]\nstation_table = "tables/t.txt"\n'))
    assert r.n_stations == 30
    cwd = os.getcwd()
    try:
        os.chdir(sub)
        assert load_model(str(tmp_path / "m.toml")).n_stations == 30
    finally:
        os.chdir(cwd)


@pytest.mark.parametrize("extra, match", [
    ('[[bearing]]\nstation = 1\nstifness = 1e6\n', r"\[\[bearing\]\] #1: unknown key 'stifness' \(did you mean 'stiffness'\?\)"),
    ('[[bearing]]\nstation = 1\n', r"\[\[bearing\]\] #1: missing 'stiffness'"),
    ('[[bearing]]\nstation = 4\nstiffness = 1e6\n', r"\[\[bearing\]\] #1, station: station 4 is outside 1\.\.3"),
    ('[[bearing]]\nstation = 1.5\nstiffness = 1e6\n', r"station: expected an integer"),
    ('[[bearing]]\nstation = 1\nstiffness = -1e6\n', r"\[\[bearing\]\] #1, stiffness: must be non-negative"),
    ('[[bearing]]\nstation = 1\nstiffness = "stiff"\n', r"stiffness: expected a finite number"),
    ('[[exciter]]\nstation = 2\n', r"\[\[exciter\]\] #1: missing 'force_per_ampere'"),
    ('[[sensor]]\nstation = 2\ndirection = "z"\n', r"\[\[sensor\]\] #1, direction: must be 'x' or 'y'"),
    ('[[disk]]\nstation = 2\nmass = 3\nwidth = 0.1\n', r"\[\[disk\]\] #1: give mass.*or the geometry"),
    ('[damping]\nmodal = 0.01\nalpha = 1\n', r"\[damping\]: give modal or alpha/beta"),
    ('[damping]\nmodal = 1.5\n', r"\[damping\], modal: a damping ratio must be below 1"),
    ('speed = 1\nspeed_rpm = 2\n', r"give speed \(rad/s\) or speed_rpm"),
    ('planes = 3\n', r"planes: must be 1 or 2"),
    ('colour = "red"\n', r"top level: unknown key 'colour'"),
    ('[[mass]]\nname = "m1"\nmass = 1\n', r"mixes rotor tables"),
])
def test_model_errors_name_file_table_key(tmp_path, extra, match):
    # top-level keys must come before the first table in TOML
    text = extra + INLINE if not extra.startswith("[") else INLINE + extra
    path = _write(tmp_path, text)
    with pytest.raises(ModelError, match=match) as ei:
        load_model(path)
    assert str(ei.value).startswith(path)


@pytest.mark.parametrize("text, match", [
    ('units = "metric"\n[[mass]]\nname = "a"\nmass = 1\n', r"units: expected one of"),
    ('[[mass]]\nname = "a"\nmass = 0\n', r"\[\[mass\]\] #1, mass: must be positive"),
    ('[[mass]]\nname = "a"\nmass = 1\n[[spring]]\nname = "k"\nstiffness = 1\nbetween = ["a", "b"]\n',
     r"\[\[spring\]\] #1, between: unknown mass 'b'"),
    ('[[mass]]\nname = "a"\nmass = 1\n[[spring]]\nname = "k"\nstiffness = 1\nbetween = ["a"]\n',
     r"between: expected two names"),
    ('[[mass]]\nname = "a"\nmass = 1\n[[damper]]\nname = "c"\nbetween = ["a", "ground"]\n',
     r"\[\[damper\]\] #1: missing 'damping'"),
    ('[[mass]]\nname = "a"\nmass = 1\n[[force]]\nname = "f"\nmass = "z"\n', r"\[\[force\]\] #1, mass: unknown mass 'z'"),
    ('[[mass]]\nname = "a"\nmass = 1\n[[mass]]\nname = "a"\nmass = 2\n', r"\[\[mass\]\] #2, name: 'a' is used twice"),
    ('[[mass]]\nname = "a"\nmass = 1\n[[spring]]\nname = "a"\nstiffness = 1\nbetween = ["a", "ground"]\n',
     r"two elements are named 'a'"),
    ('x = [1,\n', r"not valid TOML"),
    ('name = "empty"\n', r"neither a rotor"),
])
def test_lumped_model_errors(tmp_path, text, match):
    path = _write(tmp_path, text)
    with pytest.raises(ModelError, match=match) as ei:
        load_model(path)
    assert str(ei.value).startswith(path)


def test_missing_station_table_and_model_file(tmp_path):
    path = _write(tmp_path, '[shaft]\nstation_table = "absent.txt"\n')
    with pytest.raises(ModelError, match=r"\[shaft\], station_table: file 'absent.txt' not found"):
        load_model(path)
    with pytest.raises(ModelError, match="cannot read model file"):
        load_model(str(tmp_path / "absent.toml"))


def test_unknown_parameter_suggests_names():
    s = loads_model(open(data_path("three_mass.toml")).read())
    with pytest.raises(ModelError, match=r"unknown parameter 'k4'; did you mean"):
        s.matrices({"k4": 1.0})
    with pytest.raises(ModelError, match="expected 9 parameter values"):
        s.matrices(np.ones(3))


def test_crack_table_uses_the_crack_element_hook():
    pytest.importorskip("mutext.rotor.crack")
    text = open(data_path("rotor.toml")).read()
    base = os.path.dirname(data_path("rotor.toml"))
    r0 = loads_model(text, base_dir=base)
    r = loads_model(text + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\n", base_dir=base)
    assert "crack15.depth_ratio" in r.parameter_names
    assert r.natural_frequencies(n=1)[0] < r0.natural_frequencies(n=1)[0]
    np.testing.assert_allclose(r.matrices({"crack15.depth_ratio": 0.0}).K, r0.matrices().K,
                               rtol=1e-12, atol=1e-9 * np.abs(r0.matrices().K).max())
    with pytest.raises(ModelError, match=r"\[\[crack\]\] #1: missing 'depth_ratio'"):
        loads_model(text + "\n[[crack]]\nstation = 15\n", base_dir=base)
    with pytest.raises(ModelError, match=r"\[\[crack\]\] #1, station: station 30 is outside 1\.\.29"):
        loads_model(text + "\n[[crack]]\nstation = 30\ndepth_ratio = 0.4\n", base_dir=base)
    with pytest.raises(ModelError, match=r"\[\[crack\]\] #1: bad crack entry.*'colour'"):
        loads_model(text + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\ncolour = 1\n", base_dir=base)
