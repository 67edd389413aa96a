"""The fit's segments evaluated together (runtime.identification.segments): every segment's block
is the one it has alone, its trajectory the model's simulation and its state transition the
product of the steps' Jacobians; the batched group-map derivatives are those of each row."""
import dataclasses

import numpy as np
import pytest

from runtime.estimation.sense import simulate_log
from runtime.identification import fit as fitmod
from runtime.identification.fit import free_parameters
from runtime.identification.segments import _simulate, chain, dlocal_batch, dretract_batch, rows, segment_blocks
from runtime.model import Model
from runtime.scenario import TorqueWindow, load_scenario
from runtime.sensor_set import SensorSet
from runtime.state import IDX_E_NU, NE

SCENARIO = load_scenario("battery-geared")
NOMINAL = SCENARIO.params
NAMES = free_parameters("k_S,k_Y,m_P")


@pytest.fixture(scope="module")
def problem():
    """A 1.2 s log cut into 0.4 s segments, the last one longer (its tail joined), so two lengths
    step in lockstep."""
    rng = np.random.default_rng(4)
    program = tuple(TorqueWindow(i * 0.25, (i + 1) * 0.25, float(rng.uniform(-0.3, 0.3)),
                                 float(rng.uniform(-0.15, 0.15))) for i in range(6))
    run = dataclasses.replace(SCENARIO, params=NOMINAL.replace(k_S=0.2, m_P=1.1), torques=program, steps=130)
    log = simulate_log(run, SensorSet.default(), seed=3)
    x, b = fitmod._start_guess(log, NOMINAL)
    prob = fitmod._Problem(log, NOMINAL, NAMES, 0.4, "rkmk4", x, b)
    assert len(set(prob.ends - prob.starts)) == 2
    model = Model(NOMINAL)
    offsets = 1e-3 * np.random.default_rng(5).standard_normal((prob.S, NE))
    x0, D = dretract_batch(model, prob.xref, offsets)
    return prob, model, x0, D, b


def assert_blocks_equal(one, alone):
    for key in ("r", "th", "b", "x", "X", "Phi", "nodes"):
        np.testing.assert_allclose(one[key], alone[key], rtol=1e-12, atol=1e-12, err_msg=key)
    for key in ("node", "kind", "Hx", "Hn", "sig"):
        np.testing.assert_allclose(one["rows"][key], alone["rows"][key], rtol=1e-12, atol=1e-12, err_msg=key)
    assert (one["next"] is None) == (alone["next"] is None)
    if one["next"] is not None:
        np.testing.assert_allclose(one["next"], alone["next"], rtol=1e-12, atol=1e-12)


def test_each_segment_evaluated_with_the_others_has_the_block_it_has_alone(problem):
    prob, model, x0, D, b = problem
    has = np.arange(prob.S) < prob.S - 1
    nxt = (np.roll(x0, -1, axis=0), np.roll(D, -1, axis=0), has)
    together = segment_blocks(prob, model, np.arange(prob.S), x0, D, b, nxt)
    for s in range(prob.S):
        after = (x0[s + 1], D[s + 1]) if s + 1 < prob.S else None
        assert_blocks_equal(together[s], prob.segment_block(model, s, (x0[s], D[s]), after, b))


def test_a_segment_is_the_models_simulation_and_its_transition_the_product_of_its_steps(problem):
    prob, model, x0, D, b = problem
    s = prob.S - 1                                  # the longer, last segment
    blk = segment_blocks(prob, model, np.array([s]), x0[s:], D[s:], b)[0]
    k0, k1 = prob.starts[s], prob.ends[s]
    X = model.simulate(x0[s], prob.data.h, k1 - k0, u=prob.data.u[k0:k1], method="rkmk4", energy_tol=None)
    np.testing.assert_array_equal(blk["X"], X)
    Phi = np.eye(NE)
    for k in range(k1 - k0):
        Phi = model.step_jacobian(X[k], prob.data.u[k0 + k], prob.data.h, "rkmk4")[0] @ Phi
    np.testing.assert_allclose(blk["Phi"][-1], Phi, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(blk["nodes"], np.arange(k0, k1 + 1))


def test_the_chained_sensitivity_is_the_sum_of_each_steps_carried_to_the_end(problem):
    prob, model, x0, _, _ = problem
    segs = np.arange(prob.S)
    X, G, _ = _simulate(prob, model, segs, x0, sensitivities=True)
    for s in (0, prob.S - 1):                       # one of each length
        k0, k1 = prob.starts[s], prob.ends[s]
        u = prob.data.u[k0:k1]
        F = model.step_jacobian(X[s][:-1], u, prob.data.h, "rkmk4")[0]
        Jp = model.step_param_jacobian(X[s][:-1], u, prob.data.h, "rkmk4", columns=prob.idx)
        Sens = np.zeros((NE, prob.nf))
        for k in range(k1 - k0):
            Sens = F[k] @ Sens + Jp[k]
        np.testing.assert_allclose(G[s][-1][:, NE:], Sens, rtol=1e-10, atol=1e-14)
    _, held, _ = _simulate(prob, model, segs[:1], x0[:1], sensitivities=False)
    assert held[0].shape == G[0].shape and not held[0][:, :, NE:].any()


def test_the_batched_group_map_derivatives_are_those_of_each_row(problem):
    prob, model, x0, _, _ = problem
    n = prob.S - 1
    d = np.random.default_rng(6).standard_normal((n, NE)) * 1e-2
    x, D = dretract_batch(model, prob.xref[:n], d)
    A, B = dlocal_batch(model, x0[:n], x0[1:])
    e = 1e-6
    for i in range(n):
        np.testing.assert_array_equal(x[i], model.retract(prob.xref[i], d[i]))
        for j in range(NE):
            step = e * np.eye(NE)[j]
            plus = model.local(x[i], model.retract(prob.xref[i], d[i] + step))
            minus = model.local(x[i], model.retract(prob.xref[i], d[i] - step))
            np.testing.assert_allclose(D[i][:, j], (plus - minus) / (2 * e), rtol=1e-12, atol=1e-12)
            a, b = x0[i], x0[i + 1]
            da = model.local(model.retract(a, step), b) - model.local(model.retract(a, -step), b)
            db = model.local(a, model.retract(b, step)) - model.local(a, model.retract(b, -step))
            np.testing.assert_allclose(A[i][:, j], da / (2 * e), rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(B[i][:, j], db / (2 * e), rtol=1e-12, atol=1e-12)


def test_the_process_noise_reaches_the_end_state_through_the_transition_from_its_entry(problem):
    prob, model, x0, D, b = problem
    s = 0
    blk = segment_blocks(prob, model, np.array([s]), x0[:1], D[:1], b)[0]
    A, _ = prob.noise_map(s, blk)
    d, Phi = prob.data, blk["Phi"]
    k0, k1 = prob.starts[s], prob.ends[s]
    periods = np.unique(d.interval[k0:k1 + 1])
    Minv = np.linalg.inv(model.inertia_batch(blk["X"]))
    entered = 0
    for c, j in enumerate(periods):
        later = np.flatnonzero(d.interval[k0 + 1:k1 + 1] > j)
        expected = np.zeros((NE, 5))
        if later.size:                  # the velocity jump M⁻¹ w τ at the first node of a later period
            kappa = later[0] + 1
            jump = np.zeros((NE, 5))
            jump[IDX_E_NU] = Minv[kappa - 1] * d.tau
            expected = Phi[-1] @ np.linalg.solve(Phi[kappa], jump)
            entered += 1
        np.testing.assert_allclose(A[-NE:, 5 * c:5 * c + 5], expected, rtol=1e-10, atol=1e-12)
    assert entered >= 2


def numpy_chain(steps, nf, F, Jp):
    """The chain as the NumPy loop that C `sr_ident_chain` replaced: G_{k+1} = F_k G_k + [0 | Jp_k]."""
    out, k = [], 0
    for L in steps:
        G = np.zeros((L + 1, NE, NE + nf))
        G[0, :, :NE] = np.eye(NE)
        for i in range(L):
            G[i + 1] = F[k + i] @ G[i]
            G[i + 1, :, NE:] += Jp[k + i]
        out.append(G)
        k += L
    return np.concatenate(out)


@pytest.fixture(scope="module")
def steps_of(problem):
    """The steps' Jacobians of every segment of the problem, segment after segment."""
    prob, model, x0, _, _ = problem
    X, _, _ = _simulate(prob, model, np.arange(prob.S), x0, sensitivities=True)
    steps = prob.ends - prob.starts
    xs = np.concatenate([X[s][:-1] for s in range(prob.S)])
    us = np.concatenate([prob.data.u[k0:k0 + L] for k0, L in zip(prob.starts, steps)])
    F, Jp = model.step_jacobians(xs, us, prob.data.h, "rkmk4", columns=prob.idx)
    return steps, F, Jp


def test_the_c_chain_is_the_numpy_recursion_it_replaced(steps_of, problem):
    steps, F, Jp = steps_of
    nf = problem[0].nf
    expected = numpy_chain(steps, nf, F, Jp)
    np.testing.assert_allclose(chain(steps, nf, F, Jp), expected, rtol=1e-12, atol=1e-12)
    planted = F.copy()
    planted[len(F) // 2, 3, 3] += 1e-9             # one entry of one step
    assert not np.allclose(chain(steps, nf, planted, Jp), expected, rtol=1e-12, atol=1e-12)


def numpy_rows(steps, nf, n_read, has, at, node, Hx, Hn, Hb, r, sig, G, Jpa, D, A, B, Dn, defects):
    """The rows [θ | b | x | next | r] as the NumPy products that C `sr_ident_rows` replaced."""
    first = np.concatenate([[0], np.cumsum(np.asarray(steps) + 1)])
    bounds = np.concatenate([[0], np.cumsum(n_read)])
    out = []
    for s in range(len(steps)):
        q = slice(bounds[s], bounds[s + 1])
        Gs = G[first[s]:first[s + 1]]
        HG = np.einsum("rj,rjk->rk", Hx[q], Gs[at[q]])
        th = -(HG[:, NE:] + np.einsum("rj,rjk->rk", Hn[q], Jpa[node[q]])) / sig[q, None]
        x = -HG[:, :NE] / sig[q, None] @ D[s]
        rows = [th, -Hb[q] / sig[q, None], x]
        if has[s]:
            rows.append(np.zeros((len(x), NE)))
        M = np.hstack(rows + [(r[q] / sig[q])[:, None]])
        if has[s]:
            end = np.hstack([A[s] @ Gs[-1, :, NE:], np.zeros((NE, 6)), A[s] @ Gs[-1, :, :NE] @ D[s], B[s] @ Dn[s],
                             defects[s][:, None]])
            M = np.vstack([M, end])
        out.append(M)
    return out


def test_the_c_rows_are_the_numpy_products_they_replaced(problem):
    prob = problem[0]
    rng = np.random.default_rng(7)
    steps, nf = np.array([5, 3, 4]), prob.nf
    n_read, has = np.array([7, 4, 6]), np.array([1, 1, 0])
    n, nodes = int(n_read.sum()), 15
    at = np.concatenate([rng.integers(0, L + 1, m) for L, m in zip(steps, n_read)])
    args = dict(steps=steps, nf=nf, n_read=n_read, has=has, at=at, node=rng.integers(0, nodes, n),
                Hx=rng.standard_normal((n, NE)), Hn=rng.standard_normal((n, 5)), Hb=rng.standard_normal((n, 6)),
                r=rng.standard_normal(n), sig=rng.uniform(0.1, 2.0, n),
                G=rng.standard_normal((int(np.sum(steps + 1)), NE, NE + nf)), Jpa=rng.standard_normal((nodes, 5, nf)),
                D=rng.standard_normal((3, NE, NE)), A=rng.standard_normal((3, NE, NE)),
                B=rng.standard_normal((3, NE, NE)), Dn=rng.standard_normal((3, NE, NE)),
                defects=rng.standard_normal((3, NE)))
    expected = numpy_rows(**args)
    got = rows(**args)
    assert [M.shape for M in got] == [M.shape for M in expected]
    for M, E in zip(got, expected):
        np.testing.assert_allclose(M, E, rtol=1e-12, atol=1e-12)
    args["Hx"] = args["Hx"].copy()
    args["Hx"][9, 2] *= 1 + 1e-9                   # one reading's sensitivity to one coordinate
    assert not all(np.allclose(M, E, rtol=1e-12, atol=1e-12) for M, E in zip(rows(**args), expected))
