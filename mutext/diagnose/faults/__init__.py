"""Kinds of effect, each in its own module: its candidates, what it changes, how it is fitted and described.

:mod:`~mutext.diagnose.faults.channel`: effects on the measurement chain (a sensor's or an exciter's
gain, a channel's scale or polarity -- unit slips --, a sensor's delay, a mass that moves with the
sensor); :mod:`~mutext.diagnose.faults.structure`: changes of the whole structure (all damping scaled)
or of the analyser's frequency axis.  The structural kinds (springs,
masses, dampers, bearings, cracks) are still defined in :mod:`mutext.diagnose._hypotheses`.
"""
from . import channel, structure

__all__ = ["channel", "structure"]
