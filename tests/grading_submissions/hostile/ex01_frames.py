"""Hostile: walk the frames up to the audit hook, switch it off, import the solutions (ex01)."""
import sys
_f = sys._getframe()
while _f is not None and "guard" not in _f.f_locals:
    _f = _f.f_back
_g = _f.f_locals["guard"]
_g.blocked = []
_g.modules = ()
_g.phase = None
from mutext_grader.solutions.ex01_two_mass_hinf import *  # noqa: E402,F401,F403
