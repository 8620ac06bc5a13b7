"""The D-G bound as a complex problem (mutext.mu.dg_disc): SLICOT AB13MD as the reference for
both the mixed bound of M and the complex bound of the disc form, and the determinant identity
the substitution rests on, checked by dense algebra."""
import numpy as np
import pytest
from mu_cases import ab13md_structure, crandn

from mutext.errors import ModelError
from mutext.mu import Block, BlockStructure, dg_disc, disc_transform, mu_upper


def _case(nreal):
    """Real 1 x 1 blocks, a complex scalar and a full 2 x 2 block, with AB13MD's arguments."""
    return ab13md_structure(["real"] * nreal + ["c1", "full2"])


@pytest.mark.parametrize("seed", range(10))
def test_disc_form_equals_the_mixed_bound_by_ab13md(seed):
    ab13md = pytest.importorskip("slycot").ab13md
    rng = np.random.default_rng(300 + seed)
    S, nb, it = _case(1 + seed % 3)
    M = crandn(rng, S.ncols, S.nrows)
    if seed % 2 == 0:
        M = M.real + 0.2j * M.imag               # nearly real: G matters most
    mixed = ab13md(M, nb, it)[0]
    complex_ = ab13md(M, nb, np.full_like(it, 2))[0]
    form = dg_disc(M, S)
    assert form.level == pytest.approx(mixed, rel=1e-4)
    # the disc form is a complex problem; AB13MD bounds it with every block complex
    disc = ab13md(form.M, nb, np.full_like(it, 2))[0]
    assert disc == pytest.approx(form.level, rel=1e-4)
    assert disc <= complex_ * (1 + 1e-6)
    assert np.all(form.radii >= 1.0) and np.allclose(form.radii ** 2, 1 + form.centres ** 2)


@pytest.mark.parametrize("seed", range(4))
def test_higher_levels_are_certified_too(seed):
    rng = np.random.default_rng(seed)
    S, _, _ = _case(2)
    M = crandn(rng, S.ncols, S.nrows)
    up = mu_upper(M, S, method="fast")
    for factor in (1.0, 1.1, 2.0):
        form = dg_disc(M, S, upper=up, level=factor * up.value)
        assert mu_upper(form.M, form.structure, method="osborne").value <= form.level * (1 + 1e-6)


@pytest.mark.parametrize("seed", range(6))
def test_substitution_determinant_identity(seed):
    """det(I - Delta M) = det(I - C M / beta) det(I - Delta_c M_b / beta) for Delta = (C + R Delta_c) / beta
    on the real blocks and Delta_c / beta on the complex ones; and every real delta in
    [-1/beta, 1/beta] has its disc coordinate inside the unit disc."""
    rng = np.random.default_rng(50 + seed)
    S, _, _ = _case(2)
    M = crandn(rng, S.ncols, S.nrows)
    form = dg_disc(M, S)
    beta, b, rho = form.level, form.centres, form.radii
    delta = rng.uniform(-1, 1, size=b.size) / beta
    dc_real = (beta * delta - 1j * b) / rho
    assert np.all(np.abs(dc_real) <= 1 + 1e-12)
    Dc = np.zeros((S.nrows, S.ncols), complex)
    D = np.zeros((S.nrows, S.ncols), complex)
    C = np.zeros((S.nrows, S.ncols), complex)
    for j in range(b.size):
        Dc[j, j] = dc_real[j]
        D[j, j] = delta[j]
        C[j, j] = 1j * b[j]
    full = crandn(rng, 1, 1)
    Dc[b.size, b.size] = full[0, 0]
    D[b.size, b.size] = full[0, 0] / beta
    F = crandn(rng, 2, 2)
    Dc[b.size + 1:, b.size + 1:] = F
    D[b.size + 1:, b.size + 1:] = F / beta
    I = np.eye(S.ncols)
    lhs = np.linalg.det(I - D @ M)
    rhs = np.linalg.det(I - C @ M / beta) * np.linalg.det(I - Dc @ form.M / beta)
    assert lhs == pytest.approx(rhs, rel=1e-9, abs=1e-12)


def test_grid_and_errors():
    rng = np.random.default_rng(1)
    S, _, _ = _case(1)
    H = crandn(rng, 5, S.ncols, S.nrows)
    out = disc_transform(H, S, 0.3j, 1.2, 2.0)
    assert out.shape == H.shape
    assert np.allclose(out[2], disc_transform(H[2], S, 0.3j, 1.2, 2.0))
    with pytest.raises(ModelError, match="repeated real"):
        dg_disc(crandn(rng, 3, 3), BlockStructure([Block.real(2), Block.full(1)]))
    with pytest.raises(ModelError, match="below the bound"):
        dg_disc(H[0], S, level=1e-3)
    with pytest.raises(ModelError, match="radii"):
        disc_transform(H, S, 0.3j, -1.0, 2.0)
    with pytest.raises(ModelError, match="must be"):
        disc_transform(H[:, :2, :2], S, 0.3j, 1.0, 2.0)
