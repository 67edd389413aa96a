"""Python-side timings: our `Model` from Python against the alternatives (the NumPy transcription of the
paper's formulas, the CasADi reference, the sympy.physics.mechanics model), per call, in batches and in the
t-shape run, each alternative's numbers checked against ours first."""
import time

import numpy as np

from ..model import METHODS
from ..so3 import exp, rot_x, rot_y
from ..state import IDX_NU, IDX_Q, IDX_RP, IDX_RS, IDX_RY, IDX_WP, IDX_WS, IDX_WY, initial_state, rotations
from .checks import WrongNumbers, check_close
from .timing import best_seconds, per_call_ns, per_call_ns_interleaved


def _repeat(fn, args, calls):
    """fn(*args) `calls` times, each result dropped before the next call: kept in a list, every
    call's fresh output (2.8 MB for 10⁴ states) was first touched page by page, which cost the
    batch step 150 ns per state of page faults on top of its 58 on an AMD EPYC."""
    for _ in range(calls):
        fn(*args)


def t_shape_program(steps=10_000):
    """The torque program of the paper's T-shape manoeuvre over `steps` steps: (steps, 2) [N m]."""
    u = np.zeros((steps, 2))
    for first, last, column, value in [(1, 800, 0, 0.1), (1600, 1900, 1, -0.1), (2500, 3000, 0, -0.1),
                                       (3400, 4500, 1, 0.1)]:
        u[first - 1:last, column] = value
    return u


#: Entries of q, set one by one in the loop below (a slice set from a tuple costs 1 us more a step).
_QX, _QY, _QZ = range(IDX_Q.start, IDX_Q.stop)


def lie_euler_loop(accel, x0, dt, u_prog, r):
    """The t-shape run of an alternative: the paper's Lie–Euler method (Section 5) in a Python loop.

    What a user of that alternative would write around its `accel(x, u)`:
    x <- x . exp(dt f(x)) with R_S <- R_S Exp(dt [[w_S]]), R_Y <- R_Y Exp(dt w_Y [[e_x]]),
    R_P <- R_P Exp(dt w_P [[e_y]]), q <- q + dt r R_S (w_S x gamma), nu <- nu + dt accel(x, u).
    Returns the final state (compared with our C Lie–Euler run before its time counts).
    """
    x = np.array(x0, dtype=float)
    for u in u_prog:
        R_S, R_Y, R_P = rotations(x)
        wx, wy, wz = x[IDX_WS]
        gx, gy, gz = R_S[2]                     # γ, the vertical in the shell frame
        v = R_S @ np.array([wy * gz - wz * gy, wz * gx - wx * gz, wx * gy - wy * gx])
        nu_dot = accel(x, u)
        new = np.empty_like(x)
        new[IDX_RS] = (R_S @ exp((dt * wx, dt * wy, dt * wz))).ravel()
        new[IDX_RY] = (R_Y @ rot_x(dt * x[IDX_WY])).ravel()
        new[IDX_RP] = (R_P @ rot_y(dt * x[IDX_WP])).ravel()
        new[_QX], new[_QY], new[_QZ] = x[_QX] + dt * r * v[0], x[_QY] + dt * r * v[1], x[_QZ]  # q_z = r exact
        new[IDX_NU] = x[IDX_NU] + dt * nu_dot
        x = new
    return x


# -- Python-side timings -------------------------------------------------------------------------
def call_overhead_timings(model, calls, min_seconds=0.02, rounds=25):
    """One call from Python: Model.accel and Model.step against the raw cffi call of
    the checked C function (sr_accel, sr_step) on buffers prepared beforehand, over the same states,
    their rounds interleaved (per_call_ns_interleaved), in ns.  The raw calls' outputs are checked first."""
    from bindings._sr import ffi, lib

    def checked(name, status, raw, ours):
        if status != lib.SR_OK:
            raise WrongNumbers(f"{name}: status {status}")
        check_close(name, raw, ours, 0)

    keep = []                                           # the arrays behind the prepared pointers

    def pointer(arr):
        keep.append(arr)
        return ffi.cast("double *", ffi.from_buffer(arr))

    m = model._model
    raw_accel = [(m, pointer(x), pointer(u), pointer(np.empty(5))) for x, u in calls]
    raw_step = {method: [(m, METHODS[method], args[1], args[2], 0.01, pointer(np.empty(len(x))))
                         for args, (x, _) in zip(raw_accel, calls)] for method in ("lie-euler", "rkmk4")}
    for (x, u), args in zip(calls[:20], raw_accel):
        checked("raw cffi sr_accel", lib.sr_accel(*args), ffi.unpack(args[3], 5), model.accel(x, u))
    cases = {"python_model_accel_ns": (model.accel, calls), "raw_cffi_accel_ns": (lib.sr_accel, raw_accel)}
    for method, raw in raw_step.items():
        for (x, u), args in zip(calls[:20], raw):
            checked(f"raw cffi sr_step {method}", lib.sr_step(*args), ffi.unpack(args[5], len(x)),
                    model.step(x, u, 0.01, method))
        cases[f"python_model_step_{method}_ns"] = (model.step, [(x, u, 0.01, method) for x, u in calls])
        cases[f"raw_cffi_step_{method}_ns"] = (lib.sr_step, raw)
    return per_call_ns_interleaved(cases, min_seconds, rounds)


def compiled_kane_timings(model, calls, progress, min_seconds=0.2, rounds=7):
    """The compiled Kane model called from Python: PyDy's Cython ODE function and
    the CasADi Function (ca.solve of M and F), each on its own coordinates prepared beforehand
    (the conversion from our states is not timed), each checked against Model.accel first; ns."""
    import tempfile

    from .kane_compiled import casadi_kane_function, dependent_speeds, kane_inputs, pydy_cython_rhs
    p = model.params.paper_params.as_array()   # the Kane model reads the paper's twelve parameters
    qw = kane_inputs(np.array([x for x, _ in calls]))
    ud = dependent_speeds(qw, p)
    with tempfile.TemporaryDirectory() as tmp:
        progress("PyDy: generate_ode_function(generator='cython'), compiling")
        rhs = pydy_cython_rhs(tmp)
        pydy_calls = [(np.concatenate([q, d]), 0.0, np.array(u), p) for q, d, (_, u) in zip(qw, ud, calls)]
        for (x, u), args in zip(calls, pydy_calls):
            check_close("PyDy Cython ODE function", rhs(*args)[7:12], model.accel(x, u), 1e-8)
        out = {"pydy_cython_rhs_ns": per_call_ns(rhs, pydy_calls, min_seconds, rounds)}
    progress("CasADi Function of the Kane model (ca.solve), called from Python")
    fn = casadi_kane_function()
    casadi_calls = [(q, np.array(u), p) for q, (_, u) in zip(qw, calls)]
    for (x, u), args in zip(calls, casadi_calls):
        check_close("CasADi Function of the Kane model", np.asarray(fn(*args)).ravel(), model.accel(x, u), 1e-8)
    out["kane_casadi_function_ns"] = per_call_ns(fn, casadi_calls, min_seconds, rounds)
    return out


def python_timings(model, X, U, batch_size, progress, with_kane=True, loop_steps=10_000):
    """Times the Python-level paths (the Model's calls, the cffi calls they wrap, the references and, with
    `with_kane`, the Kane baselines) on the states X and torques U; returns a dict of timings."""
    from ..verification.paper_formulas import PaperModel
    from ..verification.reference import ReferenceModel
    out = {}
    calls = list(zip(X[:200], U[:200]))
    progress("Model.accel and Model.step per call from Python, and the raw cffi calls they wrap")
    out.update(call_overhead_timings(model, calls))

    paper = PaperModel(model.params)
    for x, u in calls[:20]:
        check_close("NumPy paper formulas", paper.accel(x, u), model.accel(x, u), 1e-10)
    progress("NumPy transcription of the paper's formulas")
    out["numpy_paper_accel_ns"] = per_call_ns(paper.accel, calls[:50])

    ref = ReferenceModel(model.params.as_dict())
    progress("CasADi reference from Python")
    out["casadi_python_accel_ns"] = per_call_ns(ref.accel, calls[:50])

    if with_kane:
        from ..verification.alternatives.kane import KaneModel
        progress("sympy.physics.mechanics (KanesMethod) model: deriving and lambdifying")
        kane = KaneModel(model.params.as_dict())
        out["kane_derivation_s"] = float(kane.derivation_seconds)
        for x, u in calls[:20]:
            check_close("KanesMethod model", kane.accel(x, u), model.accel(x, u), 1e-8)
        progress("KanesMethod model per call")
        out["kane_lambdified_accel_ns"] = per_call_ns(kane.accel, calls[:20], min_seconds=0.2)
        progress("KanesMethod model lambdified with sympy's defaults (no cse)")
        plain = KaneModel(model.params.as_dict(), cse=False)
        for x, u in calls[:5]:
            check_close("KanesMethod model, no cse", plain.accel(x, u), model.accel(x, u), 1e-8)
        out["kane_lambdified_default_accel_ns"] = per_call_ns(plain.accel, calls[:5], min_seconds=0.2)
        progress("KanesMethod model lambdified for Python floats (math module), hand-tuned")
        tuned = KaneModel(model.params.as_dict(), module="math")
        for x, u in calls[:20]:
            check_close("KanesMethod model, math module", tuned.accel(x, u), model.accel(x, u), 1e-8)
        out["kane_lambdified_math_accel_ns"] = per_call_ns(tuned.accel, calls[:20], min_seconds=0.2)
        out.update(compiled_kane_timings(model, calls[:20], progress))

    progress(f"batch accel over {batch_size:.0e} states")
    reps = int(np.ceil(batch_size / len(X)))
    XB, UB = np.tile(X, (reps, 1))[:batch_size], np.tile(U, (reps, 1))[:batch_size]
    # The first call on a fresh 10⁶-state batch pays for the output's first touch (page faults;
    # 2x the steady-state time on a VM): it is recorded, and the steady state (best of three
    # further calls) is what the table reports, as for the C loops.
    start = time.perf_counter()
    AB = model.accel(XB, UB)
    out["python_batch_accel_first_call_ns_per_state"] = (time.perf_counter() - start) / batch_size * 1e9
    out["python_batch_accel_ns_per_state"] = best_seconds(lambda: model.accel(XB, UB), 3) / batch_size * 1e9
    out["batch_size"] = batch_size
    # A batch that stays in the caches (10⁴ states, 2.8 MB): what the arithmetic costs without the
    # memory traffic of 10⁶ states (docs/sweeps.md).
    small, calls = min(10_000, batch_size), 20
    XS, US = XB[:small].copy(), UB[:small].copy()
    out["python_batch_accel_in_cache_ns_per_state"] = best_seconds(
        lambda: _repeat(model.accel, (XS, US), calls), 5) / (calls * small) * 1e9
    out["batch_size_in_cache"] = small
    check_close("batch accel", AB[:len(X)], np.array([model.accel(x, u) for x, u in zip(X, U)]), 0)
    # Model.step on the same 10⁴ states (sr_step_batch: Lie-Euler vectorised across them), against
    # one Model.step call per state from a Python loop, the way a user would step them otherwise.
    out["python_batch_step_lie_euler_ns_per_state"] = best_seconds(
        lambda: _repeat(model.step, (XS, US, 0.01), calls), 5) / (calls * small) * 1e9
    out["python_loop_step_lie_euler_ns_per_state"] = best_seconds(
        lambda: [model.step(x, u, 0.01) for x, u in zip(XS, US)], 3) / small * 1e9
    check_close("batch step", model.step(XS[:len(X)], US[:len(X)], 0.01),
                np.array([model.step(x, u, 0.01) for x, u in zip(XS[:len(X)], US[:len(X)])]), 0)

    u_prog = t_shape_program()
    x0 = initial_state()
    for method in METHODS:
        progress(f"t-shape, 10,000 steps, {method}")
        out[f"t_shape_{method}_ms"] = best_seconds(
            lambda: model.simulate(x0, 0.01, 10_000, u_prog, method=method), 5) * 1e3

    batches = [("CasADi reference, Function.map", ref.accel_batch, 2_000)]
    if with_kane:
        batches.append(("KanesMethod lambdify(cse=True) on arrays", kane.accel_batch, 100_000))
    out["alternative_batch_ns_per_state"] = {}
    for name, accel_batch, n in batches:
        progress(f"batch accel, {name}, {n:,} states")
        n = min(n, batch_size)
        check_close(f"batch accel, {name}", accel_batch(XB[:len(X)], UB[:len(X)]), AB[:len(X)], 1e-8)
        def run(accel_batch=accel_batch, n=n, chunk=10_000):
            for i in range(0, n, chunk):
                accel_batch(XB[i:min(i + chunk, n)], UB[i:min(i + chunk, n)])
        out["alternative_batch_ns_per_state"][name] = best_seconds(run, 3) / n * 1e9   # as for our batch

    alternatives = [("ours: Model.accel", model.accel), ("NumPy paper formulas", paper.accel),
                    ("CasADi reference from Python", ref.accel)]
    if with_kane:
        alternatives.append(("KanesMethod lambdify(cse=True)", kane.accel))
    expected = model.simulate(x0, 0.01, loop_steps, u_prog[:loop_steps], method="lie-euler")[-1]
    out["lie_euler_loop_steps"] = loop_steps
    out["lie_euler_loop_ms"] = {}
    for name, accel in alternatives:
        progress(f"t-shape, {loop_steps:,} Lie-Euler steps in a Python loop around {name}")
        start = time.perf_counter()
        final = lie_euler_loop(accel, x0, 0.01, u_prog[:loop_steps], model.params.r)
        out["lie_euler_loop_ms"][name] = (time.perf_counter() - start) * 1e3
        check_close(f"t-shape in a Python loop around {name}", final, expected, 1e-8)
    return out
