"""Serve MathJax 3 from the built book itself, so equations render offline.

Sphinx's default ``mathjax_path`` is a CDN address: a page opened without a
network shows raw LaTeX. This extension points ``mathjax_path`` at
``_static/mathjax/tex-chtml.js`` and, once an HTML build has finished, copies
MathJax there from the PyPI package ``sphinx-mathjax-offline`` (MathJax 3.2.2,
Apache-2.0; part of the ``book`` extra). Only the ``tex-chtml`` combined
component is copied, with the pieces it loads on demand (TeX extensions for
autoload, the CHTML fonts, the menu, the accessibility tools and speech rules,
the SVG output the menu can switch to): about 10 MB instead of the
package's 24 MB. ``book/_static/mathjax/LICENSE`` ships MathJax's licence
beside it.

``MUTEXT_MATHJAX_DIR`` may name another MathJax 3 ``es5`` directory (for
example ``node_modules/mathjax/es5`` from ``npm install mathjax@3``).
"""
from __future__ import annotations

import os
import shutil
from importlib import metadata
from pathlib import Path

from sphinx.errors import ExtensionError

COMPONENT = "tex-chtml.js"
TARGET = "mathjax"  # below _static/
# the other combined components: each is a complete MathJax that tex-chtml.js never loads
_OTHER_COMPONENTS = {
    "tex-chtml-full.js", "tex-chtml-full-speech.js", "tex-mml-chtml.js", "tex-mml-svg.js",
    "tex-svg.js", "tex-svg-full.js", "mml-chtml.js", "mml-svg.js", "node-main.js", "latest.js",
}


def mathjax_source() -> Path:
    """The directory holding MathJax's ``tex-chtml.js`` and its lazily loaded parts."""
    env = os.environ.get("MUTEXT_MATHJAX_DIR")
    candidates = []
    if env:
        candidates.append(Path(env))
    try:
        dist = metadata.distribution("sphinx-mathjax-offline")
    except metadata.PackageNotFoundError:
        dist = None
    if dist is not None:
        candidates.append(Path(dist.locate_file("sphinx-mathjax-offline/static/mathjax")))
    for cand in candidates:
        if (cand / COMPONENT).is_file() and (cand / "output" / "chtml" / "fonts").is_dir():
            return cand
    raise ExtensionError(
        "mathjax_offline: no local MathJax 3 found; install the book's dependencies "
        "(pip install -e '.[book]', which brings sphinx-mathjax-offline) or set "
        "MUTEXT_MATHJAX_DIR to a MathJax 3 es5 directory")


def _set_path(app, config):
    config.mathjax_path = f"{TARGET}/{COMPONENT}"


def _copy(app, exc):
    if exc is not None or app.builder.format != "html":
        return
    src = mathjax_source()
    dest = Path(app.outdir) / "_static" / TARGET

    def ignore(src_dir, names):
        top = Path(src_dir) == src
        return [n for n in names
                if n.startswith(".") or n == "__pycache__" or (top and n in _OTHER_COMPONENTS)]

    shutil.copytree(src, dest, ignore=ignore, dirs_exist_ok=True)


def setup(app):
    mathjax_source()  # fail at the start of a build, not after executing every notebook
    app.connect("config-inited", _set_path)
    app.connect("build-finished", _copy)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
