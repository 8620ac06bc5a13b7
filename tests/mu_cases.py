"""Random test matrices and AB13MD-compatible block structures, shared by the mu tests."""
import numpy as np

from mutext.mu import Block, BlockStructure

#: the block kinds SLICOT AB13MD takes: 1 x 1 real, complex 1 x 1 and square full complex 2 x 2
_KINDS = {"real": (Block.real, 1, 1), "c1": (lambda: Block.full(1), 1, 2), "full2": (lambda: Block.full(2), 2, 2)}


def crandn(rng, *shape):
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


def ab13md_structure(kinds):
    """The structure of the given kinds ("real", "c1", "full2") and its arguments ``nblock``,
    ``itype`` for slycot.ab13md."""
    made = [_KINDS[k] for k in kinds]
    return (BlockStructure([make() for make, _, _ in made]), np.array([n for _, n, _ in made]),
            np.array([t for _, _, t in made]))


def ab13md_sweep(CL, omega, kinds):
    """SLICOT AB13MD's upper bound (real blocks real) of a loop at each frequency, independent
    of mutext: the response by dense complex solves, the structure given by its ``kinds``."""
    from slycot import ab13md
    _, nblock, itype = ab13md_structure(kinds)
    A, B, C, D = (np.asarray(M, float) for M in (CL.A, CL.B, CL.C, CL.D))
    out = []
    for w in omega:
        H = D + C @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B)
        out.append(ab13md(H.astype(complex), nblock, itype)[0])
    return np.array(out)
