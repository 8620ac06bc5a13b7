"""The book builds warning-free, executing every notebook, and its pages render offline.

The build (slow: a few minutes on two cores) is shared by the slow tests of this module.
"""
import os
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

BOOK = Path(__file__).resolve().parents[1] / "book"


def _jupyter_book():
    exe = Path(sys.executable).parent / "jupyter-book"
    if exe.exists():
        return str(exe)
    return shutil.which("jupyter-book")


@pytest.fixture(scope="module")
def built_book(tmp_path_factory):
    """Build a copy of the book once; yield (html directory, build log)."""
    jb = _jupyter_book()
    if jb is None:
        pytest.skip("jupyter-book is not installed (pip install -e '.[book]')")
    src = tmp_path_factory.mktemp("book") / "book"
    shutil.copytree(BOOK, src, ignore=shutil.ignore_patterns("_build", "__pycache__"))
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run([jb, "build", str(src), "-W", "--keep-going"], capture_output=True,
                          text=True, env=env, timeout=1500)
    log = proc.stdout[-4000:] + proc.stderr[-4000:]
    assert proc.returncode == 0, log
    return src / "_build" / "html", log


@pytest.mark.slow
def test_book_builds(built_book):
    html, log = built_book
    assert (html / "hinf.html").is_file(), log
    text = (html / "hinf.html").read_text()
    assert "Traceback" not in text
    assert "1.0069" in text and "0.9671" in text
    assert list((html / "_images").glob("*.png")), "figures missing"
    # the math renderer ships with the book (book/_ext/mathjax_offline.py), licence beside it
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()
    assert (html / "_static" / "mathjax" / "LICENSE").is_file()
    assert list((html / "_static" / "mathjax" / "output" / "chtml" / "fonts").rglob("*.woff"))


# ---------------------------------------------------------------------------------------
# the built pages in a real browser with no network


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        exe = shutil.which(name)
        if exe:
            return exe
    return None


def _no_network_prefix():
    """``unshare -n`` (a network namespace with no interface) where this user may make one."""
    unshare = shutil.which("unshare")
    if unshare:
        try:
            ok = subprocess.run([unshare, "-n", "true"], capture_output=True, timeout=10).returncode == 0
        except (OSError, subprocess.SubprocessError):
            ok = False
        if ok:
            return [unshare, "-n"]
    return []


@pytest.fixture(scope="module")
def chromium():
    exe = _chromium()
    if exe is None:
        pytest.skip("chromium is not installed (apt-get install chromium)")
    return exe


class _PageAudit(HTMLParser):
    """Math elements of a rendered page (typeset or not, raw TeX left), MathJax errors, images."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.math = []          # one dict per Sphinx math element: typeset, raw text outside MathJax
        self.containers = 0     # every <mjx-container> on the page
        self.errors = 0         # <mjx-merror>: TeX MathJax could not parse
        self.images = []
        self.remote_scripts = []
        self._cur = None
        self._tag = None
        self._depth = 0
        self._mjx = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.images.append(a.get("src") or "")
        elif tag == "script" and (a.get("src") or "").startswith(("http:", "https:", "//")):
            self.remote_scripts.append(a["src"])
        elif tag == "mjx-merror":
            self.errors += 1
        if tag == "mjx-container":
            self.containers += 1
        if self._cur is None:
            cls = (a.get("class") or "").split()
            if tag in ("span", "div") and "math" in cls and "notranslate" in cls:
                self._cur, self._tag, self._depth, self._mjx = {"typeset": False, "raw": ""}, tag, 1, 0
            return
        if tag == self._tag:
            self._depth += 1
        elif tag == "mjx-container":
            self._cur["typeset"] = True
            self._mjx += 1

    def handle_endtag(self, tag):
        if self._cur is None:
            return
        if tag == "mjx-container":
            self._mjx -= 1
        elif tag == self._tag:
            self._depth -= 1
            if self._depth == 0:
                self.math.append(self._cur)
                self._cur = None

    def handle_data(self, data):
        if self._cur is not None and self._mjx == 0:
            self._cur["raw"] += data


def _render(chromium, page, prefix):
    """The DOM of a page after its scripts ran (virtual time: MathJax has finished)."""
    profile = page.parent.parent / f".chromium-{page.stem}"
    cmd = prefix + [chromium, "--headless", "--no-sandbox", "--disable-gpu",
                    "--disable-background-networking", "--disable-component-update",
                    "--no-first-run", f"--user-data-dir={profile}",
                    # belt and braces where no network namespace can be had: resolve no host
                    "--host-resolver-rules=MAP * ~NOTFOUND",
                    "--virtual-time-budget=20000", "--dump-dom", page.as_uri()]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    shutil.rmtree(profile, ignore_errors=True)
    assert proc.returncode == 0 and "</html>" in proc.stdout, proc.stderr[-2000:]
    return proc.stdout


@pytest.mark.slow
def test_book_renders_offline_in_chromium(chromium, built_book):
    """Every chapter, opened from disk with no network: all equations typeset, figures present."""
    html, _ = built_book
    prefix = _no_network_prefix()
    chapters = sorted(p for p in html.glob("*.html") if p.stem not in ("genindex", "search"))
    assert chapters
    report = {}
    for page in chapters:
        audit = _PageAudit()
        audit.feed(_render(chromium, page, prefix))
        audit.close()
        report[page.stem] = (len(audit.math), audit.containers)
        assert not audit.remote_scripts, (page.name, audit.remote_scripts)
        untypeset = [m["raw"].strip()[:80] for m in audit.math if not m["typeset"]]
        assert not untypeset, f"{page.name}: {len(untypeset)} equations not typeset: {untypeset[:3]}"
        raw = [m["raw"].strip()[:80] for m in audit.math if m["raw"].strip()]
        assert not raw, f"{page.name}: raw TeX left beside typeset math: {raw[:3]}"
        assert audit.errors == 0, f"{page.name}: {audit.errors} MathJax errors"
        for src in audit.images:
            if src.startswith("data:"):
                continue
            assert not src.startswith(("http:", "https:", "//")), (page.name, src)
            target = (page.parent / src.split("#")[0].split("?")[0]).resolve()
            assert target.is_file() and target.stat().st_size > 0, (page.name, src)
    print("typeset equations per chapter (math elements, mjx-containers):", report)
    for name in ("hinf", "mu", "mbi"):
        assert report.get(name, (0, 0))[0] > 0, f"{name}: no equations found: {report}"
    hinf = (html / "hinf.html").read_text()
    assert "begin{bmatrix}" in hinf  # the check above saw these typeset, not absent


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


@pytest.mark.slow
def test_built_pages_fit_the_column(built_book):
    """Every line of code and output of the built book, and every figure, fits the text column
    (the checks of tests/test_book_width.py on the HTML, with the outputs the build produced)."""
    from test_book_width import too_wide_built

    html, _ = built_book
    bad = too_wide_built(html)
    assert not bad, "wider than the text column:\n" + "\n".join(bad)
