"""The design searches' array path (restitution.analysis.scaled.solve_scaled_arrays) against the
table path it stands in for (solve_scaled_many: a DataFrame through solve_many): the same COR and
status, bit for bit, on every kind of row, and the fallback wherever its reading would differ."""

import math

import numpy as np
import pytest

from restitution import SceneError
from restitution.analysis import design, scaled


def _chains(rng, s, n, beta):
    """s random scaled chains of n masses (mass ratios over 4 decades, springs over 2)."""
    m = 10.0 ** rng.uniform(-2, 2, (s, n))
    k = 10.0 ** rng.uniform(-1, 1, (s, n - 1))
    return design._scaled_chains(m, k, beta)


def _both(m, k, kc, max_events=100_000):
    many = scaled.solve_scaled_many(list(zip(m, k, kc, strict=True)), max_events)
    arrays = scaled.solve_scaled_arrays(m, k, kc, max_events)
    return many, arrays


def _same(a, b):
    np.testing.assert_array_equal(a[1], b[1])  # status ok
    assert a[0].tobytes() == b[0].tobytes()  # COR bit for bit, NaN where voided


@pytest.mark.parametrize("beta", [0.0, 0.05])
@pytest.mark.parametrize("n", [3, 6])
def test_same_cor_and_status_as_the_table_path(n, beta):
    m, k, kc = _chains(np.random.default_rng(n), 60, n, beta)
    many, arrays = _both(m, k, kc)
    # most finish (the COR columns are compared, not NaNs); a few long sequences of 6 masses
    # end ill-conditioned, and those are compared too
    assert many[1].mean() > 0.9
    _same(many, arrays)


def test_the_array_path_runs_without_a_table(monkeypatch):
    """Plain chains never reach solve_many (the point of the path): fail if they do."""
    m, k, kc = _chains(np.random.default_rng(1), 20, 4, 0.0)
    expected = scaled.solve_scaled_many(list(zip(m, k, kc, strict=True)))
    monkeypatch.setattr(scaled, "solve_many", lambda *a, **kw: pytest.fail("table path taken"))
    _same(expected, scaled.solve_scaled_arrays(m, k, kc))


def test_unfinished_rows_are_not_ok_on_both_paths():
    m, k, kc = _chains(np.random.default_rng(2), 40, 5, 0.0)
    many, arrays = _both(m, k, kc, max_events=2)  # most need more than 2 contacts
    assert (~many[1]).any() and many[1].any()
    _same(many, arrays)
    assert np.isnan(arrays[0][~arrays[1]]).all()


@pytest.mark.parametrize(
    "edit",
    [
        "paper",  # a row of the paper's form: its own kernel on the table path
        "ratio",  # a mass ratio past RATIOS: the table's row-by-row reading words the error
        "edge",  # a ratio within the reading's margin of its bound: row by row too
    ],
)
def test_rows_the_table_reads_otherwise_take_the_table_path(edit, monkeypatch):
    m, k, kc = _chains(np.random.default_rng(3), 10, 4, 0.0)
    if edit == "paper":
        a = 2.2
        m[4] = [1.0, a, a, a]
        k[4] = a / (1.0 + a)
    elif edit == "ratio":
        m[4, 2] = 1e12
    else:
        low = design.RATIOS["masses[i]/masses[0]"][0]
        m[4, 3] = low * (1.0 + 1e-12)
    taken = []
    real = scaled.solve_scaled_many
    monkeypatch.setattr(
        scaled, "solve_scaled_many", lambda *a, **kw: taken.append(1) or real(*a, **kw)
    )
    if edit == "ratio":
        with pytest.raises(design.SceneError, match="masses"):
            scaled.solve_scaled_arrays(m, k, kc)
        assert taken
        return
    arrays = scaled.solve_scaled_arrays(m, k, kc)
    assert taken
    _same(real(list(zip(m, k, kc, strict=True))), arrays)


def test_design_objective_is_the_worst_over_each_members_chains():
    """The robust objective of a population through arrays against a per-chain loop
    (scaled_chain per member and error vector, each chain solved on its own): the batch's
    grouping by member. The search's runs are unchecked (next test)."""
    fam = design.family("masses", 5)
    obj = design._Objective(fam, 0.0, 0.01, 100_000)
    X = np.random.default_rng(4).uniform(-2.0, 2.0, (fam.dim, 6))
    old = np.full(X.shape[1], -math.inf)
    for s in range(X.shape[1]):
        m, k = fam.chain(X[:, s])
        for d in obj._box(fam.n_masses):
            mm = m * (1.0 + d)
            cm, ck, ckc = design.scaled_chain(mm / mm[0], k, 0.0)
            cor, ok = scaled.solve_scaled_arrays([cm], [ck], [ckc], check=False)
            old[s] = max(old[s], cor[0] if ok[0] else design._BAD)
    assert obj.batch(X).tobytes() == old.tobytes()


@pytest.mark.parametrize("beta", [0.0, 0.05])
def test_unchecked_search_rows_keep_the_checked_cor(beta):
    """check=False (the design search's objective) runs each scene once, without the replica
    check: where the checked row is a result, the same COR and contact count bit for bit; the
    rows are flagged FLAG_UNCHECKED, and a scene the check calls ill-conditioned finishes with
    its first run's COR (a search may rank it; a design is solved again, checked)."""
    from restitution.kernels import layout as L
    from restitution.kernels.exact_chain import solve_chain_batch
    from restitution.model.units import kernel_params
    from restitution.tables.linear_rows import omega_column

    m, k, kc = _chains(np.random.default_rng(6), 60, 6, beta)
    c = np.zeros_like(k)
    ms, ks, cs, kcs = kernel_params(m, k, c, kc[:, None], m[:, :1], omega_column(m, k)[:, None])
    n = np.full(len(m), 6, dtype=np.int64)
    checked = solve_chain_batch(ms, ks, cs, n, kcs[:, 0], 100_000)
    search = solve_chain_batch(ms, ks, cs, n, kcs[:, 0], 100_000, check=False)
    st = checked[:, L.OUT_STATUS]
    done = (st == L.STATUS_OK) | (st == L.STATUS_PERMANENT_CONTACT)
    assert done.mean() > 0.8
    for col in (L.OUT_COR, L.OUT_NCOL, L.OUT_TCOL):
        assert search[done, col].tobytes() == checked[done, col].tobytes()
    assert (search[:, L.OUT_STATUS][done] == st[done]).all()
    assert (search[:, L.OUT_FLAGS].astype(int) & L.FLAG_UNCHECKED).all()
    assert not (checked[:, L.OUT_FLAGS].astype(int) & L.FLAG_UNCHECKED).any()
    ill = st == L.STATUS_ILL_CONDITIONED
    if beta == 0.0:  # (this seed's sample holds such scenes at the rigid wall)
        assert ill.any()
    assert (search[ill, L.OUT_STATUS] == L.STATUS_OK).all()
    assert np.isfinite(search[ill, L.OUT_COR]).all()
    # the arrays path: ok there is the finished first run, a superset of the checked ok
    cor, ok = scaled.solve_scaled_arrays(m, k, kc, check=False)
    cor_c, ok_c = scaled.solve_scaled_arrays(m, k, kc)
    assert (ok >= ok_c).all() and (ok & ~ok_c).sum() == ill.sum()
    assert cor[ok_c].tobytes() == cor_c[ok_c].tobytes()


def _hist_times(m, k, kc, max_events=100_000):
    """solve_scaled's result and its history's contact times (the documented path)."""
    r = scaled.solve_scaled(m, k, kc, history=True, max_events=max_events)
    return r, r.history["omega_t_start"].to_numpy(), r.history["omega_t_end"].to_numpy()


def _bits(x):
    return np.asarray(x, dtype=np.float64).tobytes()


@pytest.mark.parametrize("beta", [0.0, 0.05])
def test_contact_times_are_the_history_s_bit_for_bit(beta):
    """contact_times (the design polish's grazing evaluations) gives solve_scaled(history=True)'s
    result and contact times, bit for bit, on general chains, a paper-form chain and rows that
    do not finish (a budget of 2 contacts)."""
    rng = np.random.default_rng(11)
    m, k, kc = _chains(rng, 40, 5, beta)
    a = 2.2
    m[3], k[3] = [1.0, a, a, a, a], a / (1.0 + a)
    for budget in (100_000, 2):
        for i in range(len(m)):
            want, ts, te = _hist_times(m[i], k[i], kc[i], budget)
            got, gs, ge = scaled.contact_times(m[i], k[i], kc[i], max_events=budget)
            assert (got.history is None) == (i != 3)  # the paper's form: solve_scaled's own
            assert (got.status, got.n_collisions, got.method) == (
                want.status, want.n_collisions, want.method
            )  # fmt: skip
            assert _bits([got.cor, got.error_estimate]) == _bits([want.cor, want.error_estimate])
            assert _bits(gs) == _bits(ts) and _bits(ge) == _bits(te)


def test_unchecked_contact_times_are_the_checked_run_s():
    """check=False runs a general chain once, without its replicas: the same contact times as
    the checked run and, at a rigid wall, the same COR bit for bit wherever the checked row
    finished; only the status may differ (a row the replicas call ill-conditioned)."""
    m, k, kc = _chains(np.random.default_rng(12), 60, 6, 0.0)
    finished = 0
    for i in range(len(m)):
        want, ts, te = _hist_times(m[i], k[i], kc[i])
        got, gs, ge = scaled.contact_times(m[i], k[i], kc[i], check=False)
        assert _bits(gs) == _bits(ts) and _bits(ge) == _bits(te)
        assert got.n_collisions == want.n_collisions
        if want.success:
            finished += 1
            assert got.success and _bits(got.cor) == _bits(want.cor)
    assert finished > 50


def test_contact_times_refuses_what_solve_refuses():
    m, k, kc = _chains(np.random.default_rng(13), 1, 4, 0.0)
    m[0, 2] = 1e12  # a mass ratio past the solvers' range
    with pytest.raises(SceneError, match="mass"):
        scaled.solve_scaled(m[0], k[0], kc[0])
    with pytest.raises(SceneError, match="mass"):
        scaled.contact_times(m[0], k[0], kc[0], check=False)
