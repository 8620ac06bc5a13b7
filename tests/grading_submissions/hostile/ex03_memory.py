"""Hostile: exhaust memory (a huge array, endless anonymous mappings, a huge bytes object).

The address-space limit of the child stops all three with MemoryError; the
grader and the other questions carry on.  (The mappings are not written to,
so the test does not fill the machine's RAM up to the limit first.)"""
import mmap

import numpy as np


def natural_frequency(t, y, cycles):
    return float(np.ones(2 ** 33).sum())     # 64 GiB


def damping_ratio(t, y, cycles):
    blocks = []
    while True:
        try:
            blocks.append(mmap.mmap(-1, 2 ** 28))   # 256 MiB each, until the address space is full
        except OSError as exc:
            raise MemoryError(f"after {len(blocks)} blocks of 256 MiB: {exc}") from None


def cart_mass(omega_bare, omega_weighted, m_w):
    return float(len(b"x" * (2 ** 40)))
