"""ex06, a submission that does not solve: one verdict for every sweep, the modes handed back as the
candidates, a constant size."""
import numpy as np

VERDICTS = ("none", "once per revolution", "twice per revolution")


def sideband_frequencies(natural_frequencies_hz, speed_hz, orders, f_min, f_max):
    return np.asarray(natural_frequencies_hz, float)


def sideband_size(freq_hz, re, im, f_candidate, half_width_hz):
    return 0.0


def classify(freq_hz, re, im, natural_frequencies_hz, speed_hz, noise):
    return VERDICTS.index("once per revolution")
