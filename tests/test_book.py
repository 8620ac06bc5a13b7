"""The book builds warning-free, executing every notebook (slow: about half a minute)."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

BOOK = Path(__file__).resolve().parents[1] / "book"


def _jupyter_book():
    exe = Path(sys.executable).parent / "jupyter-book"
    if exe.exists():
        return str(exe)
    return shutil.which("jupyter-book")


@pytest.mark.slow
def test_book_builds(tmp_path):
    jb = _jupyter_book()
    if jb is None:
        pytest.skip("jupyter-book is not installed (pip install -e '.[book]')")
    src = tmp_path / "book"
    shutil.copytree(BOOK, src, ignore=shutil.ignore_patterns("_build"))
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run([jb, "build", str(src), "-W", "--keep-going"], capture_output=True,
                          text=True, env=env, timeout=900)
    log = proc.stdout[-4000:] + proc.stderr[-4000:]
    assert proc.returncode == 0, log
    html = src / "_build" / "html"
    assert (html / "hinf.html").is_file(), log
    text = (html / "hinf.html").read_text()
    assert "Traceback" not in text
    assert "1.0069" in text and "0.9671" in text
    assert list((html / "_images").glob("*.png")), "figures missing"


def test_variant_plant_default_is_thesis_plant():
    """The plant behind the book's 0.9671 table reduces to the thesis plant."""
    import numpy as np

    from mutext.examples import two_mass, two_mass_variants
    from mutext.lti import freqresp

    w = np.array([0.5, 3.0, 12.0, 60.0])
    P0 = two_mass.plant(two_mass.THESIS)
    P1 = two_mass_variants.variant_plant()
    np.testing.assert_allclose(freqresp(P1, w), freqresp(P0, w), rtol=1e-12, atol=1e-14)
    # a damped variant really is damped
    Pd = two_mass_variants.variant_plant(two_mass_variants.VariantSpec(zeta=0.02))
    zeta = -np.linalg.eigvals(Pd.A).real / np.abs(np.linalg.eigvals(Pd.A))
    np.testing.assert_allclose(zeta, 0.02, rtol=1e-9)
