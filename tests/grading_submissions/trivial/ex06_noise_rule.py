"""ex06, a submission that does not solve: a verdict read from the noise argument alone, and the size as
the data's relative scatter."""
import numpy as np


def sideband_frequencies(natural_frequencies_hz, speed_hz, orders, f_min, f_max):
    fn = np.asarray(natural_frequencies_hz, float)
    return np.sort(np.concatenate([fn - speed_hz, fn + speed_hz]))     # order 1 always, no band


def sideband_size(freq_hz, re, im, f_candidate, half_width_hz):
    h = np.asarray(re, float) + 1j * np.asarray(im, float)
    return float(np.std(np.abs(np.diff(np.log(np.abs(h))))))


def classify(freq_hz, re, im, natural_frequencies_hz, speed_hz, noise):
    if noise > 8e-4:
        return 0
    return 1 if noise < 6.5e-4 else 2
