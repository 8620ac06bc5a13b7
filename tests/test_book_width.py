"""The book's pages fit their text column: code, display equations and figures.

The book's text column (sphinx-book-theme, with the page's table of contents
beside it) is about 760 px wide: 47 em of 16 px body text, 88 characters of
the 14 px monospace code font, or a figure 7 inches wide at the 100 dpi of the
inline backend.  Anything wider scrolls sideways (code, outputs, equations) or
is scaled down until its text is unreadable (figures).

The source checks (fast) read the MyST pages:

* every line of a code cell or code block is at most 88 characters;
* every display equation's estimated rendered width is at most 37 em, estimated
  by :func:`tex_width` from its TeX (matrices add their columns, aligned rows
  are measured one by one, sub- and superscripts count 70 %);
* every literal ``figsize=(w, h)`` has ``w`` at most 7 inches.

The estimate is calibrated so that the equations that did overflow the column
(the two-mass generalized plant and the LMIs of the H-infinity chapter, the
identification plant, the rotor's mass matrix) measure above the bound when
written on one line.  :func:`too_wide_built` reads the built pages (every line
of code and output at most 88 characters, every figure at most 800 px wide); the
slow test of ``tests/test_book.py`` runs it on the book it builds.
"""
from __future__ import annotations

import re
import struct
from pathlib import Path

import pytest

BOOK = Path(__file__).resolve().parents[1] / "book"
CODE_CHARS = 88
EQUATION_EM = 37.0
FIGURE_INCHES = 7.0
FIGURE_PX = 800


def pages():
    return sorted(p for p in BOOK.glob("*.md") if p.name != "README.md")


# ------------------------------------------------------------------------------ parsing

def code_lines(text: str):
    """``(line number, line)`` of every line inside a fenced code block or code cell."""
    inside, fence = False, ""
    for n, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if not inside:
            m = re.match(r"^(`{3,}|~{3,})(.*)$", stripped)
            if m and not m.group(2).lstrip().startswith("{math}"):
                inside, fence = True, m.group(1)
            continue
        if stripped.startswith(fence) and stripped.strip("`~") == "":
            inside = False
            continue
        if stripped.startswith(":") and re.match(r"^:\w+:", stripped):
            continue                      # cell options (:tags: ...)
        yield n, line


def display_equations(text: str):
    """``(line number, tex)`` of every ``$$ ... $$`` block and ``{math}`` directive outside code."""
    lines = text.splitlines()
    code = {n for n, _ in code_lines(text)}
    n = 0
    while n < len(lines):
        line = lines[n].strip()
        if (n + 1) not in code and line.startswith("$$"):
            rest = line[2:]
            if rest.endswith("$$") and len(rest) >= 2:
                yield n + 1, rest[:-2]
                n += 1
                continue
            start, body = n + 1, [rest]
            n += 1
            while n < len(lines) and not lines[n].strip().endswith("$$"):
                body.append(lines[n])
                n += 1
            if n < len(lines):
                body.append(lines[n].strip()[:-2])
            yield start, "\n".join(body)
        elif line.startswith(("```{math}", ":::{math}")):
            start, body = n + 1, []
            n += 1
            while n < len(lines) and not lines[n].strip().startswith(("```", ":::")):
                if not lines[n].strip().startswith(":"):
                    body.append(lines[n])
                n += 1
            yield start, "\n".join(body)
        n += 1


# ------------------------------------------------------------------------------ TeX width

_MATRIX = {"bmatrix", "pmatrix", "vmatrix", "Bmatrix", "matrix", "array", "cases", "smallmatrix"}
_ROWS = {"aligned", "align", "align*", "split", "gathered", "multline", "multline*", "gather",
         "alignedat", "eqnarray"}
_ZERO = {"left", "right", "big", "Big", "bigg", "Bigg", "bigl", "bigr", "Bigl", "Bigr", "displaystyle",
         "limits", "nolimits", "label", "nonumber", "notag", "boldsymbol", "mathbf", "mathit", "mathsf",
         "bm", "textstyle"}
_SPACE = {",": 0.17, ";": 0.28, ":": 0.22, " ": 0.25, "!": -0.17, "quad": 1.0, "qquad": 2.0,
          "enspace": 0.5, "thinspace": 0.17}
_TEXT = {"mathrm", "text", "operatorname", "textrm", "mbox", "mathtt"}
_OPS = {"sup", "inf", "min", "max", "det", "log", "ln", "sin", "cos", "exp", "lim", "arg", "Re", "Im",
        "tan", "dim", "ker", "deg"}
_ACCENT = {"bar", "hat", "tilde", "dot", "ddot", "vec", "overline", "underline", "widehat", "widetilde",
           "mathcal", "mathbb", "mathfrak", "mathscr"}
_REL = set("=<>") | {"le", "ge", "leq", "geq", "prec", "succ", "preceq", "succeq", "approx", "sim",
                     "equiv", "to", "mapsto", "rightarrow", "leftarrow", "Rightarrow", "iff", "in",
                     "subset", "ne", "neq", "coloneqq"}


def _group(tex: str, i: int):
    """The brace group starting at ``tex[i] == '{'``: (content, index after it)."""
    depth, j = 0, i
    while j < len(tex):
        if tex[j] == "\\":
            j += 2
            continue
        if tex[j] == "{":
            depth += 1
        elif tex[j] == "}":
            depth -= 1
            if depth == 0:
                return tex[i + 1:j], j + 1
        j += 1
    return tex[i + 1:], len(tex)


def _argument(tex: str, i: int):
    """One argument (a brace group, a command or a character) at ``i``: (tex, index after)."""
    while i < len(tex) and tex[i] in " \n\t":
        i += 1
    if i >= len(tex):
        return "", i
    if tex[i] == "{":
        return _group(tex, i)
    if tex[i] == "\\":
        m = re.match(r"\\([A-Za-z]+|.)", tex[i:])
        return m.group(0), i + len(m.group(0))
    return tex[i], i + 1


def _split_top(tex: str, sep: str):
    """Split ``tex`` at ``sep`` (``\\\\`` or ``&``) outside braces and environments."""
    parts, depth, env, start, i = [], 0, 0, 0, 0
    while i < len(tex):
        if tex.startswith("\\begin{", i):
            env += 1
        elif tex.startswith("\\end{", i):
            env -= 1
        if tex[i] == "\\" and not tex.startswith(sep, i):
            i += 2
            continue
        if tex[i] == "{":
            depth += 1
        elif tex[i] == "}":
            depth -= 1
        elif depth == 0 and env == 0 and tex.startswith(sep, i):
            parts.append(tex[start:i])
            i += len(sep)
            start = i
            continue
        i += 1
    parts.append(tex[start:])
    return parts


def _environment(tex: str, i: int):
    """At ``\\begin{name}``: (name, body, index after ``\\end{name}``)."""
    name, j = _group(tex, i + len("\\begin"))
    depth, k = 1, j
    while k < len(tex):
        if tex.startswith("\\begin{", k):
            depth += 1
        elif tex.startswith("\\end{", k):
            depth -= 1
            if depth == 0:
                end = tex.index("}", k) + 1
                body = tex[j:k]
                if name in ("array", "alignedat") and body.lstrip().startswith("{"):
                    body = body[_group(body, body.index("{"))[1]:]     # the column spec
                return name, body, end
        k += 1
    return name, tex[j:], len(tex)


def tex_width(tex: str) -> float:
    r"""Estimated rendered width of display TeX in em (about 16 px each in the book).

    Letters and digits 0.55 em, relations with their spacing 1.4 em, binary
    operators 1.2 em, punctuation 0.45 em, named operators 0.5 em a letter,
    text 0.5 em a character; sub- and superscripts 70 % of their content;
    fractions the wider of numerator and denominator; a matrix the sum of its
    widest cells plus 1 em between columns and 1 em for its delimiters; an
    aligned environment its widest row.  A rough model of MathJax's output, good
    to about 15 % on this book's equations.
    """
    w, i = 0.0, 0
    while i < len(tex):
        c = tex[i]
        if c in " \n\t&":
            i += 1
        elif c in "^_":
            arg, i = _argument(tex, i + 1)
            w += 0.7 * tex_width(arg)
        elif c == "{":
            body, i = _group(tex, i)
            w += tex_width(body)
        elif c == "}":
            i += 1
        elif c == "\\":
            if tex.startswith("\\begin{", i):
                name, body, i = _environment(tex, i)
                if name in _MATRIX:
                    rows = [_split_top(r, "&") for r in _split_top(body, "\\\\") if r.strip()]
                    ncol = max((len(r) for r in rows), default=0)
                    cols = [max((tex_width(r[j]) for r in rows if j < len(r)), default=0.0)
                            for j in range(ncol)]
                    w += sum(cols) + 1.0 * max(ncol - 1, 0) + 1.0
                else:               # aligned and friends, or unknown: widest row
                    rows = _split_top(body, "\\\\")
                    w += max((tex_width(r) for r in rows), default=0.0)
                continue
            m = re.match(r"\\([A-Za-z]+|.)", tex[i:])
            name = m.group(1)
            i += len(m.group(0))
            if name in _SPACE:
                w += _SPACE[name]
            elif name in _ZERO:
                if name in ("label",):
                    _, i = _argument(tex, i)
                continue
            elif name == "\\":
                continue
            elif name in _TEXT:
                arg, i = _argument(tex, i)
                w += 0.5 * len(re.sub(r"\\[A-Za-z]+|[{}$\\]", "", arg))
            elif name in ("frac", "dfrac", "tfrac"):
                a, i = _argument(tex, i)
                b, i = _argument(tex, i)
                w += max(tex_width(a), tex_width(b)) * (1.0 if name == "dfrac" else 0.85) + 0.3
            elif name == "sqrt":
                a, i = _argument(tex, i)
                w += tex_width(a) + 0.9
            elif name in _ACCENT:
                a, i = _argument(tex, i)
                w += tex_width(a)
            elif name in _OPS:
                w += 0.5 * len(name) + 0.3
            elif name in _REL:
                w += 1.4
            elif name in ("cdot", "times", "pm", "mp", "star", "otimes", "oplus", "circ"):
                w += 1.2
            elif name in ("ldots", "cdots", "dots", "vdots", "ddots"):
                w += 1.3
            elif name in ("sum", "prod", "int", "oint"):
                w += 1.2
            else:               # a Greek letter or a symbol
                w += 0.6
        elif c in "=<>":
            w += 1.4
            i += 1
        elif c in "+-*/":
            w += 1.2 if c in "+-" else 0.55
            i += 1
        elif c in ",;.:!":
            w += 0.45
            i += 1
        elif c in "()[]|":
            w += 0.4
            i += 1
        else:
            w += 0.55
            i += 1
    return w


def figure_widths(text: str):
    """``(line number, width)`` of every literal ``figsize=(w, h)`` in a code line."""
    for n, line in code_lines(text):
        for m in re.finditer(r"figsize\s*=\s*\(\s*([0-9.]+)\s*,", line):
            yield n, float(m.group(1))


# ------------------------------------------------------------------------------ the book

def _too_wide_code(path):
    return [f"{path.name}:{n}: {len(line)} characters" for n, line in code_lines(path.read_text())
            if len(line) > CODE_CHARS]


def _too_wide_equations(path):
    return [f"{path.name}:{n}: about {tex_width(tex):.0f} em" for n, tex in
            display_equations(path.read_text()) if tex_width(tex) > EQUATION_EM]


def _too_wide_figures(path):
    return [f"{path.name}:{n}: figsize width {w} in" for n, w in figure_widths(path.read_text())
            if w > FIGURE_INCHES]


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.stem)
def test_code_lines_fit_the_column(page):
    bad = _too_wide_code(page)
    assert not bad, f"code lines longer than {CODE_CHARS} characters:\n" + "\n".join(bad)


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.stem)
def test_display_equations_fit_the_column(page):
    bad = _too_wide_equations(page)
    assert not bad, (f"display equations wider than {EQUATION_EM} em (split them with aligned or "
                     f"multline):\n" + "\n".join(bad))


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.stem)
def test_figures_fit_the_column(page):
    bad = _too_wide_figures(page)
    assert not bad, f"figures wider than {FIGURE_INCHES} in:\n" + "\n".join(bad)


# ------------------------------------------------------------------------------ the checks themselves

PLANTED = """# A page

```{code-cell} ipython3
x = 1
print("a line of code that is far too long for the column of the book, it goes on and on and on")
```

$$
\\begin{bmatrix} N_R & 0\\\\ 0 & I\\end{bmatrix}^T
\\begin{bmatrix} AR + RA^T & RC_1^T & B_1\\\\ C_1R & -\\gamma I & D_{11}\\\\
B_1^T & D_{11}^T & -\\gamma I\\end{bmatrix}
\\begin{bmatrix} N_R & 0\\\\ 0 & I\\end{bmatrix} \\prec 0,
\\qquad
\\begin{bmatrix} N_S & 0\\\\ 0 & I\\end{bmatrix}^T
\\begin{bmatrix} A^TS + SA & SB_1 & C_1^T\\\\ B_1^TS & -\\gamma I & D_{11}^T\\\\
C_1 & D_{11} & -\\gamma I\\end{bmatrix}
\\begin{bmatrix} N_S & 0\\\\ 0 & I\\end{bmatrix} \\prec 0
$$

$$
\\begin{aligned}
& \\begin{bmatrix} N_R & 0\\\\ 0 & I\\end{bmatrix}^T
\\begin{bmatrix} AR + RA^T & RC_1^T & B_1\\\\ C_1R & -\\gamma I & D_{11}\\\\
B_1^T & D_{11}^T & -\\gamma I\\end{bmatrix}
\\begin{bmatrix} N_R & 0\\\\ 0 & I\\end{bmatrix} \\prec 0,\\\\
& \\begin{bmatrix} N_S & 0\\\\ 0 & I\\end{bmatrix}^T
\\begin{bmatrix} A^TS + SA & SB_1 & C_1^T\\\\ B_1^TS & -\\gamma I & D_{11}^T\\\\
C_1 & D_{11} & -\\gamma I\\end{bmatrix}
\\begin{bmatrix} N_S & 0\\\\ 0 & I\\end{bmatrix} \\prec 0
\\end{aligned}
$$

```{code-cell} ipython3
fig, ax = plt.subplots(figsize=(11, 4))
```
"""


def test_checks_catch_planted_overflows(tmp_path):
    page = tmp_path / "planted.md"
    page.write_text(PLANTED)
    assert _too_wide_code(page) == ["planted.md:5: 97 characters"]
    eqs = list(display_equations(PLANTED))
    assert len(eqs) == 2
    # the two LMIs side by side overflow; the same two stacked in an aligned environment fit
    assert tex_width(eqs[0][1]) > EQUATION_EM > tex_width(eqs[1][1])
    assert [e.split(":")[1] for e in _too_wide_equations(page)] == [str(eqs[0][0])]
    assert _too_wide_figures(page) == ["planted.md:34: figsize width 11.0 in"]


@pytest.mark.parametrize("tex, low, high", [
    ("x", 0.4, 0.7),
    ("a + b = c", 4.0, 5.5),
    (r"\begin{bmatrix} 1 & 0\\ 0 & 1\end{bmatrix}", 2.5, 4.0),
    (r"\frac{a+b}{c}", 2.0, 3.0),
    (r"x_{\max}", 0.9, 2.0),
    (r"\begin{aligned} a &= b\\ cccccccc &= d\end{aligned}", 5.5, 7.5),
])
def test_width_estimate_of_simple_tex(tex, low, high):
    assert low <= tex_width(tex) <= high


# ------------------------------------------------------------------------------ the built pages

def pre_blocks(html: str) -> list[str]:
    """Text of every ``<pre>`` block of an HTML page (code and outputs)."""
    from html import unescape
    return [unescape(re.sub(r"<[^>]+>", "", b)) for b in re.findall(r"<pre[^>]*>(.*?)</pre>", html, flags=re.S)]


def too_wide_built(html_dir: Path) -> list[str]:
    """Lines of code and output longer than the column, and figures wider than it, in a built book
    (used by the slow test of ``tests/test_book.py``, which builds the book once for all its checks)."""
    bad = []
    for page in sorted(html_dir.glob("*.html")):
        if page.stem in ("genindex", "search"):
            continue
        for block in pre_blocks(page.read_text()):
            for line in block.splitlines():
                if len(line.rstrip()) > CODE_CHARS:
                    bad.append(f"{page.name}: {len(line.rstrip())} characters: {line.strip()[:60]}")
    for png in sorted((html_dir / "_images").glob("*.png")):
        width = struct.unpack(">I", png.read_bytes()[16:20])[0]
        if width > FIGURE_PX:
            bad.append(f"{png.name}: {width} px wide")
    return bad


def test_built_page_check_catches_planted_overflows(tmp_path):
    (tmp_path / "_images").mkdir()
    (tmp_path / "page.html").write_text("<pre><span>x = 1</span>\n" + "y" * 95 + "</pre><p>" + "z" * 200)
    png = b"\x89PNG\r\n\x1a\n" + b"\x00\x00\x00\rIHDR" + struct.pack(">II", 1200, 400) + b"\x00" * 8
    (tmp_path / "_images" / "wide.png").write_bytes(png)
    (tmp_path / "_images" / "fits.png").write_bytes(png[:16] + struct.pack(">II", 640, 400))
    assert too_wide_built(tmp_path) == ["page.html: 95 characters: " + "y" * 60, "wide.png: 1200 px wide"]
