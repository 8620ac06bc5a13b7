"""Kinds of effect, each in its own module: its candidates, what it changes, how it is written into the
model file (:mod:`mutext.rotor.model_writer`) and described.

:mod:`~mutext.diagnose.faults.lumped`: a chain's springs, dampers and masses changed, springs and
dampers to ground added; :mod:`~mutext.diagnose.faults.rotor`: a rotor's bearings changed, springs,
dampers and masses added at its stations; :mod:`~mutext.diagnose.faults.bearing_cross`: a bearing's
skew cross-coupled stiffness (two-plane rotors); :mod:`~mutext.diagnose.faults.crack`: an open crack in a
shaft element; :mod:`~mutext.diagnose.faults.absorber`: a tuned-mass absorber (an added degree of
freedom, three parameters); :mod:`~mutext.diagnose.faults.pedestal`: a spring to ground set on a
pedestal (mass and spring, two parameters); :mod:`~mutext.diagnose.faults.distributed`: one relative
stiffness change shared by a run of consecutive springs; :mod:`~mutext.diagnose.faults.channel`:
effects on the measurement chain (a sensor's or an exciter's gain, a channel's scale or polarity --
unit slips --, a sensor's delay, a mass that moves with the sensor);
:mod:`~mutext.diagnose.faults.structure`: changes of the whole structure (all damping scaled) or of the
analyser's frequency axis.  :mod:`mutext.diagnose._hypotheses`
assembles them.
"""
from . import absorber, bearing_cross, channel, crack, distributed, lumped, pedestal, rotor, structure

__all__ = ["absorber", "bearing_cross", "channel", "crack", "distributed", "lumped", "pedestal", "rotor",
           "structure"]
