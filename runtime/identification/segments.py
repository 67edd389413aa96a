"""The multiple-shooting fit's segments evaluated together (runtime.identification.fit): each
segment one C simulation; the step, parameter, acceleration and sensor Jacobians of all the
segments' states in one C batch call each; the sensitivity chains of all segments in one C call
(`chain`, c/include/sr_ident.h), and the readings' and end-state rows of all segments in another
(`rows`), each segment's [θ | b | x | next | r] one block of a stacked array that the whitening
(C `sr_ident_whiten`) reads as it is.  The Python work per evaluation is then a fixed number of
array operations, not one per step of every segment; each block equals the one a segment alone
would give, to rounding.

    x, D = dretract_batch(model, x_ref, offsets)
    out = segment_blocks(prob, model, np.arange(prob.S), x, D, b)
"""
import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from ..errors import KernelError
from ..sensors import encoders_jacobian_batch, imu_partials_batch, position_jacobian_batch
from ..state import NE, NV, NX

#: The IMU's biases.
NB = 6
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



def _check(field, status):
    if status != lib.SR_OK:
        raise KernelError(field, status)


def buffer(buffers, name, size):
    """A float array of `size` entries kept in the dict `buffers` under `name` and reused while the
    size stays (an evaluation's large outputs: a fresh array of megabytes each evaluation costs
    its page faults again); a new array without `buffers`."""
    if buffers is None:
        return np.empty(size)
    if name not in buffers or buffers[name].size != size:
        buffers[name] = np.empty(size)
    return buffers[name]


def chain(steps, nf, F, Jp=None, buffers=None):
    """The segments' sensitivity chains (C `sr_ident_chain`): for segment s of steps[s] steps,
    G_0 = [I | 0] and G_{k+1} = F_k G_k + [0 | Jp_k]; F (sum(steps), 12, 12) and Jp (sum(steps),
    12, nf) or None (zero) stacked segment after segment.  Returns G (sum(steps + 1), 12, 12 + nf)
    stacked the same way (in `buffers`' array "G", see `buffer`)."""
    steps = np.ascontiguousarray(steps, dtype=np.int64)
    F = np.ascontiguousarray(F, dtype=float)
    n = int(np.sum(steps + 1))
    G = buffer(buffers, "G", n * NE * (NE + nf)).reshape(n, NE, NE + nf)
    jp = ffi.NULL if Jp is None else pointer(np.ascontiguousarray(Jp, dtype=float))
    _check("chain", lib.sr_ident_chain(len(steps), pointer(steps, "long"), nf, pointer(F), jp, pointer(G)))
    return G


def _simulate(prob, model, segs, x0, sensitivities, buffers=None):
    """Per segment of `segs`: its trajectory X (L + 1, 35) and its chain G (L + 1, 12, 12 + nf)
    = [Φ_k | S_k] (the state transition and the parameter sensitivity from its start; S zero
    without `sensitivities`), a view of the segments' chains stacked (`chain`, the third value).
    Each segment is one C simulation; the steps of all segments one batch of step Jacobians."""
    d = prob.data
    k0, L = prob.starts[segs], prob.ends[segs] - prob.starts[segs]
    nf = prob.nf
    X = [model.simulate(x0[i], d.h, L[i], u=d.u[k0[i]:k0[i] + L[i]], method=prob.method, energy_tol=None)
         for i in range(len(segs))]
    xs = np.concatenate([X[i][:-1] for i in range(len(segs))])
    us = d.u[np.concatenate([k0[i] + np.arange(L[i]) for i in range(len(segs))])]
    Jp = None
    if sensitivities:
        F, Jp = step_jacobians(model, xs, us, d.h, prob.method, prob.idx, prob.jacobian)
    else:
        F = step_state_jacobian(model, xs, us, d.h, prob.method, prob.jacobian)
    stacked = chain(L, nf, F, Jp, buffers)
    first = np.concatenate([[0], np.cumsum(L + 1)])
    return X, [stacked[first[i]:first[i + 1]] for i in range(len(segs))], stacked


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
    lay["at"] = np.ascontiguousarray(local[lay["node"]], dtype=np.int64)
    lay["n_read"] = np.diff(lay["bounds"]).astype(np.int64)
    prob.layouts[key] = lay
    return lay


def segment_blocks(prob, model, segs, x0, D, b, nxt=None, sensitivities=True, buffers=None):
    """The blocks of the segments `segs` (indices into prob's segments, ascending) of the
    multiple-shooting problem `prob` (runtime.identification.fit._Problem) on the robot `model`:
    segment i simulated from x0[i] (its start, (S, 35)) whose offset Jacobian is D[i] (S, 12, 12);
    with the IMU's biases b.  `nxt`: (x (S, 35), D (S, 12, 12), has (S,) bool), the next segment's
    start for the end-state differences of the segments with `has`; None: no differences.  Without
    `sensitivities` the parameters' columns are zero.  Each block as `_Problem.segment_block`
    describes it.  With `buffers` (a dict, `buffer`) the blocks' chains and rows are views of
    arrays kept there: valid until the next call with the same dict."""
    d, nf = prob.data, prob.nf
    segs = np.asarray(segs)
    X, G, stacked = _simulate(prob, model, segs, np.atleast_2d(x0), sensitivities, buffers)
    lay = _layout(prob, segs)
    counts, local, gnode, node, kinds, order, sig = (lay[k] for k in (
        "counts", "local", "gnode", "node", "kinds", "order", "sig"))
    Xn = np.concatenate([X[i][:c] for i, c in enumerate(counts)])
    un = d.u[gnode]
    nudot = model.accel(Xn, un)
    Ja = accel_state_jacobian(model, Xn, un, prob.jacobian)
    Jpa = np.zeros((len(Xn), NV, nf)) if sensitivities else None    # ∂ν̇/∂θ where an IMU reads it
    parts = []                  # (r, Hx, Hn, Hb) per kind, in the layout's order of kinds
    li = lay["li"]
    if li.size:
        y, H, Hn = imu_partials_batch(model, Xn[li], nudot[li], mount=prob.mount, bias=b)
        Hx = H[:, :, :NE] + Hn @ Ja[li]
        if sensitivities:
            Jpa[li] = accel_sensitivity(model, Xn[li], un[li], prob.idx, prob.jacobian)
        r = prob.log.imu.data[lay["imu_rows"]] - y
        parts.append((r.ravel(), Hx.reshape(-1, NE), Hn.reshape(-1, NV), H[:, :, NE:].reshape(-1, NB)))
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
        parts.append((r.ravel(), Hx.reshape(-1, NE), np.zeros((2 * lk.size, NV)), np.zeros((2 * lk.size, NB))))
    r, Hx, Hn, Hb = (np.ascontiguousarray(np.concatenate([p[i] for p in parts])[order]) for i in range(4))
    n = len(segs)
    has = np.zeros(n, dtype=np.intc)
    A, B, Dn, defects = (np.zeros((n, NE, NE)), np.zeros((n, NE, NE)), np.zeros((n, NE, NE)), np.zeros((n, NE)))
    if nxt is not None:
        has[:] = np.asarray(nxt[2], dtype=bool)
        w = np.flatnonzero(has)
        ends = np.array([X[i][-1] for i in w]).reshape(-1, NX)
        A[w], B[w] = dlocal_batch(model, ends, nxt[0][w])
        defects[w] = model.local(ends, nxt[0][w])
        Dn[w] = np.asarray(nxt[1])[w]
    M = rows(prob.ends[segs] - prob.starts[segs], nf, lay["n_read"], has, lay["at"], node, Hx, Hn, Hb, r, sig,
             stacked, Jpa, np.ascontiguousarray(D, dtype=float), A, B, Dn, defects, buffers)
    out = []
    for i, s in enumerate(segs):
        sl = slice(lay["bounds"][i], lay["bounds"][i + 1])
        Mi = M[i]
        blk = {"M": Mi, "stack": M, "r": Mi[:, -1], "th": Mi[:, :nf], "b": Mi[:, nf:nf + NB],
               "x": Mi[:, nf + NB:nf + NB + NE], "next": Mi[:, nf + NB + NE:-1] if has[i] else None,
               "rows": {"node": local[node[sl]], "kind": kinds[sl], "Hx": Hx[sl], "Hn": Hn[sl], "sig": sig[sl]},
               "X": X[i], "Phi": G[i][:, :, :NE], "nodes": lay["nodes"][i], "model": model,
               "n_out": sl.stop - sl.start}
        out.append(blk)
    return out


class Rows(list):
    """The segments' rows [θ | b | x | next | r] (`rows`): a list of each segment's (rows, width)
    array, all views of one stacked array `data` (segment after segment, each row-major), which
    C `sr_ident_whiten` reads as it is."""

    def __init__(self, data, shapes):
        self.data, self.shapes = data, shapes
        first = np.concatenate([[0], np.cumsum([m * w for m, w in shapes])])
        super().__init__(data[first[i]:first[i + 1]].reshape(shape) for i, shape in enumerate(shapes))


def rows(steps, nf, n_read, has, at, node, Hx, Hn, Hb, r, sig, G, Jpa, D, A, B, Dn, defects, buffers=None):
    """The segments' unwhitened rows (C `sr_ident_rows`, whose header gives the formulas): per
    segment its readings' rows (n_read[s] of them, stacked in the per-row arrays at, node, Hx (12),
    Hn (5), Hb (6), r, sig), through its chain (`chain`'s stacked G, the reading at node at[q] of
    its segment) and Jpa (nodes, 5, nf; None for zero), then with has[s] its end-state rows (A, B,
    Dn (S, 12, 12), defects (S, 12)).  A `Rows` of the segments' [θ | b | x | next | r] (in
    `buffers`' array "M", see `buffer`)."""
    steps = np.ascontiguousarray(steps, dtype=np.int64)
    has = np.ascontiguousarray(has, dtype=np.intc)
    shapes = [(int(m) + NE * int(h), nf + NB + NE + NE * int(h) + 1) for m, h in zip(n_read, has)]
    out = buffer(buffers, "M", sum(m * w for m, w in shapes))
    node = np.ascontiguousarray(node, dtype=np.int64)
    jpa = ffi.NULL if Jpa is None else pointer(np.ascontiguousarray(Jpa, dtype=float))
    n_nodes = 0 if Jpa is None else len(Jpa)
    _check("rows", lib.sr_ident_rows(len(steps), nf, pointer(steps, "long"), pointer(np.ascontiguousarray(n_read, dtype=np.int64), "long"),
                                     pointer(has, "int"), pointer(at, "long"), pointer(node, "long"), n_nodes, pointer(Hx), pointer(Hn),
                                     pointer(Hb), pointer(r), pointer(np.ascontiguousarray(sig, dtype=float)), pointer(G), jpa, pointer(D),
                                     pointer(A), pointer(B), pointer(Dn), pointer(defects), pointer(out)))
    return Rows(out, shapes)
