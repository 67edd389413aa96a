"""The multiple-shooting fit's segments evaluated together (runtime.identification.fit): each
segment one C simulation; the step, parameter, acceleration and sensor Jacobians of all the
segments' states in one C batch call each; the sensitivity chain one batched matrix product per
step for all segments at once; the readings' rows of all segments formed together.  The Python
work per evaluation is then a fixed number of array operations, not one per step of every
segment; each block equals the one a segment alone would give, to rounding.

    x, D = dretract_batch(model, x_ref, offsets)
    out = segment_blocks(prob, model, np.arange(prob.S), x, D, b)
"""
import numpy as np

from ..sensors import encoders_jacobian_batch, imu_partials_batch, position_jacobian_batch
from ..state import NE, NV, NX
from .sensitivity import accel_sensitivity, accel_state_jacobian, step_jacobians, step_state_jacobian

#: The step of the group maps' central differences (error coordinates: rad, m, rad/s).
GROUP_STEP = 1e-6


def _wrap(a):
    return np.remainder(a + np.pi, 2 * np.pi) - np.pi


def _moves():
    """The 2·12 error steps ±GROUP_STEP e_j, the + ones first."""
    return np.vstack([GROUP_STEP * np.eye(NE), -GROUP_STEP * np.eye(NE)])


def _differenced(moved):
    """(S, 24, 12) values at the + then − steps -> the central differences (S, 12, 12), column j the
    direction j."""
    return np.swapaxes(moved[:, :NE] - moved[:, NE:], 1, 2) / (2 * GROUP_STEP)


def dretract_batch(model, x, d):
    """(x ⊕ d (S, 35), ∂ local(x ⊕ d, x ⊕ (d + δ))/∂δ at δ = 0 (S, 12, 12)) for the rows of x
    (S, 35) and d (S, 12), by central differences of the exact group maps (no dynamics), all rows
    in one retract and one local call."""
    x, d = np.atleast_2d(x), np.atleast_2d(d)
    S = len(x)
    x0 = model.retract(x, d)
    moved = model.retract(np.repeat(x, 2 * NE, axis=0), (d[:, None, :] + _moves()[None]).reshape(-1, NE))
    diff = model.local(np.repeat(x0, 2 * NE, axis=0), moved).reshape(S, 2 * NE, NE)
    return x0, _differenced(diff)


def dlocal_batch(model, a, b):
    """(∂ local(a ⊕ δ, b)/∂δ, ∂ local(a, b ⊕ δ)/∂δ) at δ = 0, each (S, 12, 12), for the rows of a
    and b (S, 35), central differences as `dretract_batch`."""
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    S = len(a)
    steps = np.tile(_moves(), (S, 1))
    a_rep, b_rep = np.repeat(a, 2 * NE, axis=0), np.repeat(b, 2 * NE, axis=0)
    da = model.local(model.retract(a_rep, steps), b_rep).reshape(S, 2 * NE, NE)
    db = model.local(a_rep, model.retract(b_rep, steps)).reshape(S, 2 * NE, NE)
    return _differenced(da), _differenced(db)


def _simulate(prob, model, segs, x0, sensitivities):
    """Per segment of `segs`: its trajectory X (L + 1, 35) and its chain G (L + 1, 12, 12 + nf)
    = [Φ_k | S_k] (the state transition and the parameter sensitivity from its start; S zero
    without `sensitivities`).  Each segment is one C simulation; the segments of one length share
    one batch of step Jacobians and one batched product per step of the chain."""
    d = prob.data
    k0, L = prob.starts[segs], prob.ends[segs] - prob.starts[segs]
    nf = prob.nf
    X = [model.simulate(x0[i], d.h, L[i], u=d.u[k0[i]:k0[i] + L[i]], method=prob.method, energy_tol=None)
         for i in range(len(segs))]
    G = [None] * len(segs)
    for length in np.unique(L):
        g = np.flatnonzero(L == length)
        rows = k0[g][:, None] + np.arange(length)              # (n_g, L) node of each step
        xs = np.concatenate([X[i][:-1] for i in g])
        us = d.u[rows.ravel()]
        if sensitivities:
            F, Jp = step_jacobians(model, xs, us, d.h, prob.method, prob.idx, prob.jacobian)
            Jp = Jp.reshape(len(g), length, NE, nf)
        else:
            F = step_state_jacobian(model, xs, us, d.h, prob.method, prob.jacobian)
        F = F.reshape(len(g), length, NE, NE)
        Gg = np.empty((len(g), length + 1, NE, NE + nf))
        Gg[:, 0] = 0.0
        Gg[:, 0, :, :NE] = np.eye(NE)
        for k in range(length):
            np.matmul(F[:, k], Gg[:, k], out=Gg[:, k + 1])
            if sensitivities:
                Gg[:, k + 1, :, NE:] += Jp[:, k]
        for i, c in enumerate(g):
            G[c] = Gg[i]
    return X, G


def _layout(prob, segs):
    """Where the readings of the segments `segs` sit, the same at every evaluation (kept in
    `prob.layouts` per segs): "counts" the nodes of each segment, "seg_of", "local" and "gnode" per
    node its segment's position in segs, its index in the segment and in the log; "li" the nodes
    with an IMU sample and "imu_rows" those samples; "lk" {1 encoders, 2 fixes} likewise with
    "kind_rows"; the reading rows ordered by time, at one time IMU, encoders, fix ("order" of the
    kinds' rows stacked in that order): their "node", "kinds", noise "sig", the "bounds" of each
    segment's rows, and "nodes" each segment's log nodes."""
    key = segs.tobytes()
    cached = prob.layouts.get(key)
    if cached is not None:
        return cached
    d = prob.data
    counts = prob.ends[segs] - prob.starts[segs] + (segs == prob.S - 1)
    seg_of = np.repeat(np.arange(len(segs)), counts)
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    local = np.arange(len(seg_of)) - first[seg_of]
    gnode = prob.starts[segs][seg_of] + local
    lay = {"counts": counts, "seg_of": seg_of, "local": local, "gnode": gnode, "lk": {}, "kind_rows": {}}
    parts = []                  # (node, kind, sig) per kind
    li = np.flatnonzero(d.imu_row[gnode] >= 0)
    lay["li"], lay["imu_rows"] = li, d.imu_row[gnode[li]]
    if li.size:
        parts.append((np.repeat(li, 6), 0, np.tile(prob.sig_imu, li.size)))
    for kind, rows_of, sig in ((1, d.enc_row, prob.sig_enc), (2, d.fix_row, prob.sig_fix)):
        lk = np.flatnonzero(rows_of[gnode] >= 0)
        lay["lk"][kind], lay["kind_rows"][kind] = lk, rows_of[gnode[lk]]
        if lk.size:
            parts.append((np.repeat(lk, 2), kind, np.full(2 * lk.size, float(sig))))
    node = np.concatenate([p[0] for p in parts])
    kinds = np.concatenate([np.full(len(p[0]), p[1]) for p in parts])
    order = np.lexsort((kinds, node))           # stable: each reading's components stay in order
    lay.update(order=order, node=node[order], kinds=kinds[order], sig=np.concatenate([p[2] for p in parts])[order],
               bounds=np.searchsorted(seg_of[node[order]], np.arange(len(segs) + 1)),
               nodes=[gnode[seg_of == i] for i in range(len(segs))])
    prob.layouts[key] = lay
    return lay


def segment_blocks(prob, model, segs, x0, D, b, nxt=None, sensitivities=True):
    """The blocks of the segments `segs` (indices into prob's segments, ascending) of the
    multiple-shooting problem `prob` (runtime.identification.fit._Problem) on the robot `model`:
    segment i simulated from x0[i] (its start, (S, 35)) whose offset Jacobian is D[i] (S, 12, 12);
    with the IMU's biases b.  `nxt`: (x (S, 35), D (S, 12, 12), has (S,) bool), the next segment's
    start for the end-state differences of the segments with `has`; None: no differences.  Without
    `sensitivities` the parameters' columns are zero.  Each block as `_Problem.segment_block`
    describes it."""
    d, nf = prob.data, prob.nf
    segs = np.asarray(segs)
    X, G = _simulate(prob, model, segs, np.atleast_2d(x0), sensitivities)
    lay = _layout(prob, segs)
    counts, seg_of, local, gnode, node, kinds, order, sig = (lay[k] for k in (
        "counts", "seg_of", "local", "gnode", "node", "kinds", "order", "sig"))
    Xn = np.concatenate([X[i][:c] for i, c in enumerate(counts)])
    Gn = np.concatenate([G[i][:c] for i, c in enumerate(counts)])
    un = d.u[gnode]
    nudot = model.accel(Xn, un)
    Ja = accel_state_jacobian(model, Xn, un, prob.jacobian)
    Jpa = np.zeros((len(Xn), NV, nf))          # ∂ν̇/∂θ where an IMU reads it
    parts = []                  # (r, Hx, Hn, Hb) per kind, in the layout's order of kinds
    li = lay["li"]
    if li.size:
        y, H, Hn = imu_partials_batch(model, Xn[li], nudot[li], mount=prob.mount, bias=b)
        Hx = H[:, :, :NE] + Hn @ Ja[li]
        if sensitivities:
            Jpa[li] = accel_sensitivity(model, Xn[li], un[li], prob.idx, prob.jacobian)
        r = prob.log.imu.data[lay["imu_rows"]] - y
        parts.append((r.ravel(), Hx.reshape(-1, NE), Hn.reshape(-1, NV), H[:, :, NE:].reshape(-1, 6)))
    for kind, batch in ((1, encoders_jacobian_batch), (2, position_jacobian_batch)):
        lk = lay["lk"][kind]
        if not lk.size:
            continue
        y, H = batch(model, Xn[lk])
        if kind == 1:
            r = _wrap(prob.log.encoders.data[lay["kind_rows"][kind]] - y)
        else:
            r = prob.fix_xy[lay["kind_rows"][kind]] - y
        Hx = H[:, :, :NE]
        parts.append((r.ravel(), Hx.reshape(-1, NE), np.zeros((2 * lk.size, NV)), np.zeros((2 * lk.size, 6))))
    r, Hx, Hn, Hb = (np.concatenate([p[i] for p in parts])[order] for i in range(4))
    r = r / sig
    # per row, as a segment alone forms them (the same products in the same order, bit for bit)
    HG = np.einsum("rj,rjk->rk", Hx, Gn[node])         # [∂y/∂x Φ | ∂y/∂x S] of each row, one gather
    th = -(HG[:, NE:] + np.einsum("rj,rjk->rk", Hn, Jpa[node])) / sig[:, None]
    xs = -HG[:, :NE] / sig[:, None]
    Hb = -Hb / sig[:, None]
    bounds = lay["bounds"]
    if nxt is not None:
        has = np.flatnonzero(nxt[2])
        ends = np.array([X[i][-1] for i in has]).reshape(-1, NX)
        A, B = dlocal_batch(model, ends, nxt[0][has])
        defects = model.local(ends, nxt[0][has])
        where = {int(i): j for j, i in enumerate(has)}
    out = []
    for i, s in enumerate(segs):
        sl = slice(bounds[i], bounds[i + 1])
        Phi, Sens = G[i][:, :, :NE], G[i][:, :, NE:]
        blk = {"r": r[sl], "th": th[sl], "b": Hb[sl], "x": xs[sl] @ D[i], "next": None,
               "rows": {"node": local[node[sl]], "kind": kinds[sl], "Hx": Hx[sl], "Hn": Hn[sl], "sig": sig[sl]},
               "X": X[i], "Phi": Phi, "nodes": lay["nodes"][i], "model": model, "n_out": sl.stop - sl.start}
        j = where.get(i) if nxt is not None else None
        if j is not None:
            blk["r"] = np.concatenate([blk["r"], defects[j]])
            blk["th"] = np.vstack([blk["th"], A[j] @ Sens[-1]])
            blk["b"] = np.vstack([blk["b"], np.zeros((NE, 6))])
            blk["x"] = np.vstack([blk["x"], A[j] @ Phi[-1] @ D[i]])
            blk["next"] = np.vstack([np.zeros((len(blk["r"]) - NE, NE)), B[j] @ nxt[1][i]])
        out.append(blk)
    return out
