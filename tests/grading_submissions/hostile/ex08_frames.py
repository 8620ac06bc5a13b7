"""Hostile: walk the frames up to the audit hook, switch it off, import the solutions and the grader's own
W_z search (ex08)."""
import sys
_f = sys._getframe()
while _f is not None and "guard" not in _f.f_locals:
    _f = _f.f_back
_g = _f.f_locals["guard"]
_g.blocked = []
_g.modules = ()
_g.phase = None
from mutext_grader.solutions.ex08_mbi import *  # noqa: E402,F401,F403
from mutext_grader.ex08_mbi import reference_wz  # noqa: E402


def smallest_wz(rig, wz_low, wz_high, omega):
    return reference_wz(rig, omega)
