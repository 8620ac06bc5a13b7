"""The spread of the three-mass rig's true responses, solved from its M, C, K matrices (an
independent reference for mutext.mbi.true_spread and the covers built on it)."""
import itertools

import numpy as np

from mutext.examples import three_mass as tm


def half_gaps(trial: str, w, levels: int = 5) -> np.ndarray:
    """Half the widest gap between the cart-1 responses (force at cart 1) of the trial's true
    rigs, its changed parameters on ``levels`` points of their uncertainty ranges."""
    tr = tm.TRIALS[trial]
    names = tm._changed(tr)
    X = []
    for x in itertools.product(np.linspace(-1, 1, levels), repeat=len(names)):
        p = tr.true.with_(**{n: getattr(tr.true, n) * (1 + tr.uncertainty * v) for n, v in zip(names, x)})
        M, C, K = tm.matrices(p)
        X.append([np.linalg.solve(K - f * f * M + 1j * f * C, [1.0, 0, 0])[0] for f in w])
    X = np.array(X)
    return np.array([np.abs(X - X[i]).max(axis=0) for i in range(len(X))]).max(axis=0) / 2
