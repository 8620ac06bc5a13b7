"""Figures are drawn and saved (Agg backend, no display needed)."""
import matplotlib

matplotlib.use("Agg")

import os  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from mutext import plots  # noqa: E402
from mutext.examples import two_mass  # noqa: E402
from mutext.hinf import hinfsyn  # noqa: E402


@pytest.fixture(scope="module")
def design():
    P = two_mass.plant(two_mass.THESIS)
    return hinfsyn(P, 1, 1), P


def test_two_mass_figures_saved(design, tmp_path):
    res, P = design
    files = plots.two_mass_hinf_figures(res, P, tmp_path / "figs", thesis_gamma=two_mass.THESIS_GAMMA)
    assert len(files) == 3
    for f in files:
        assert os.path.isfile(f) and f.endswith(".png")
        assert os.path.getsize(f) > 5000
    assert not plt.get_fignums(), "figures must be closed after saving"


def test_small_functions_draw(design):
    res, P = design
    w = plots.systems_grid(P)
    assert np.all(np.diff(w) > 0) and w[0] < 7.46 < w[-1]
    fig, ax = plt.subplots()
    plots.bode_mag(ax, P, w, out_index=0, in_index=0)
    plots.bode_phase(ax, res.K, w)
    plots.sigma_plot(ax, res.CL, w)
    assert len(ax.lines) == 3
    plt.close(fig)
    for fig in (plots.closed_loop_figure(res.CL, w, P=P), plots.controller_figure(res.K),
                plots.sigma_figure(res.CL, levels={"gamma": res.gamma})):
        assert fig.axes
        plt.close(fig)
