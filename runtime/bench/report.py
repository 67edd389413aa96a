"""The benchmark's report: the table on stdout, in families of like against like,
with the targets, and the result file of the run."""
import json

from ..atomic import write_new_file

#: The C loop's baselines: key, label.  The first three are the Kane model as its users would ship it.
C_BASELINES = [
    ("kane_casadi_c_accel", "Kane model, CasADi C: M, F and ca.solve (what a CasADi user ships)"),
    ("kane_sympy_c_accel", "Kane model, SymPy's C printer (cse) + generic LU"),
    ("kane_pydy_c_accel", "Kane model, PyDy's C (its Cython ODE function's code) + generic LU"),
    ("casadi_generated_reference_accel", "CasADi C of our 9x9 KKT reference (a verification model)"),
    ("kane_casadi_c_accel_jacobian", "Kane model's accel Jacobian (5x14) by CasADi AD, CasADi C (vs our accel)"),
]
#: The Python-call baselines: key, label.
PYTHON_BASELINES = [
    ("pydy_cython_rhs_ns", "PyDy generate_ode_function, Cython, one call (own coordinates)"),
    ("kane_lambdified_accel_ns", "Kane model, lambdify(cse=True) (PyDy's default), one call"),
    ("kane_lambdified_math_accel_ns", "Kane model, lambdify(cse=True, math module), hand-tuned, one call"),
    ("kane_lambdified_default_accel_ns", "Kane model, lambdify with defaults, one call"),
    ("kane_casadi_function_ns", "Kane model, CasADi Function (ca.solve), one call (own coordinates)"),
    ("casadi_python_accel_ns", "CasADi Function of our KKT reference (a verification model), one call"),
    ("numpy_paper_accel_ns", "NumPy transcription of the paper's matrix formulas, one call"),
]
STEPS = ("step_lie_euler", "step_rkmk4", "step_cf4")


def _table(rows):
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    lines = ["  ".join(cell.ljust(w) if i == 0 else cell.rjust(w) for i, (cell, w) in enumerate(zip(r, widths)))
             for r in rows]
    lines.insert(1, "-" * len(lines[0]))
    return lines


def targets(res):
    """(name, met) of every target of the issues that this run measures."""
    c, py = res["c_loop"], res["python"]
    ours = c["accel"]["ns"]
    out = [("accel <= 150 ns", ours <= 150)]
    if "raw_cffi_accel_ns" in py:
        out.append(("Model.accel <= 2x the raw cffi call", py["python_model_accel_ns"] <= 2 * py["raw_cffi_accel_ns"]))
        out.append(("Model.step <= 2x the raw cffi call", all(
            py[f"python_model_step_{m}_ns"] <= 2 * py[f"raw_cffi_step_{m}_ns"] for m in ("lie-euler", "rkmk4"))))
    for key in ("step_rkmk4", "step_cf4"):
        if key in c:
            out.append((f"{key[5:]} step <= 6x one checked accel (C loop)", c[key]["ns"] <= 6 * ours))
    if "accel_jacobian" in c:
        out.append(("accel_jacobian <= 8x one checked accel (C loop)", c["accel_jacobian"]["ns"] <= 8 * ours))
        if "step_jacobian_lie_euler" in c:
            out.append(("Lie-Euler step_jacobian <= 2x accel_jacobian (C loop)",
                        c["step_jacobian_lie_euler"]["ns"] <= 2 * c["accel_jacobian"]["ns"]))
        for key in ("step_jacobian_rkmk4", "step_jacobian_cf4"):
            if key in c:
                out.append((f"{key[14:].upper()} step_jacobian <= 6x accel_jacobian (C loop)",
                            c[key]["ns"] <= 6 * c["accel_jacobian"]["ns"]))
        if "kane_casadi_c_accel_jacobian" in c:
            out.append(("accel_jacobian >= 10x faster than CasADi AD C of the Kane Jacobian",
                        10 * c["accel_jacobian"]["ns"] <= c["kane_casadi_c_accel_jacobian"]["ns"]))
    if "lqr_control" in c:
        out.append(("the C controller (LQR, one sample) <= 1 us (C loop)", c["lqr_control"]["ns"] <= 1000))
    if "accel_general_robot" in c:
        out.append(("accel of a general robot <= 1.3x the paper-geometry kernel (C loop; paper robots are "
                    "given that kernel automatically)", c["accel_general_robot"]["ns"] <= 1.3 * ours))
    if "t_shape_rkmk4_ms" in py:
        out.append(("t-shape rkmk4 end to end <= 4 ms", py["t_shape_rkmk4_ms"] <= 4))
    if "python_batch_accel_ns_per_state" in py:
        floor = res.get("memory_floor_ns_per_state")
        beyond = (f"; the memory traffic alone takes {floor:.1f} ns of the {ours / 3:.1f} ns allowed" if floor else "")
        out.append((f"Model.accel batch of {py['batch_size']:,} <= 1/3 of one checked accel (C loop), per state{beyond}",
                    3 * py["python_batch_accel_ns_per_state"] <= ours))
    return out


def sections(res):
    """The report's families as [(title, rows)], rows[0] the header: rendered as text (format_report)
    and as the README's Markdown tables (format_markdown)."""
    c, py = res["c_loop"], res["python"]
    ours = c["accel"]["ns"]
    out = []
    rows = [("quantity", "time", "vs our checked accel")]
    rows.append(("our accel, checked API", f"{ours:,.1f} ns", "1"))
    rows.append(("our accel, raw generated kernel", f"{c['accel_unchecked']['ns']:,.1f} ns", ""))
    rows.append(("our inertia", f"{c['inertia']['ns']:,.1f} ns", ""))
    for key in STEPS:
        if key in c:
            rows.append((f"our {key.replace('_', ' ')}", f"{c[key]['ns']:,.1f} ns", f"{c[key]['ns'] / ours:.1f}x"))
    if "accel_jacobian" in c:
        rows.append(("our accel_jacobian (Ja 5x12 and Jb 5x2)", f"{c['accel_jacobian']['ns']:,.1f} ns",
                     f"{c['accel_jacobian']['ns'] / ours:.1f}x"))
    for key, label in (("step_jacobian_lie_euler", "Lie-Euler"), ("step_jacobian_rkmk4", "RKMK4"),
                       ("step_jacobian_cf4", "CF4")):
        if key in c:
            rows.append((f"our {label} step_jacobian (F 12x12 and G 12x2)", f"{c[key]['ns']:,.1f} ns",
                         f"{c[key]['ns'] / ours:.1f}x"))
    if "lqr_control" in c:
        rows.append(("our LQR controller, one sample (sr_lqr_control, state checked)", f"{c['lqr_control']['ns']:,.1f} ns",
                     f"{c['lqr_control']['ns'] / ours:.1f}x"))
    if "accel_general_robot" in c:
        rows.append(("our accel of a general robot (general kernels)", f"{c['accel_general_robot']['ns']:,.1f} ns",
                     f"{c['accel_general_robot']['ns'] / ours:.1f}x"))
        rows.append(("our rkmk4 step of a general robot", f"{c['step_rkmk4_general_robot']['ns']:,.1f} ns",
                     f"{c['step_rkmk4_general_robot']['ns'] / c['step_rkmk4']['ns']:.1f}x our rkmk4 step"))
    if "checked_accel_batch" in c:
        rows.append(("our checked accel batch (sr_checked_accel_batch, full state check), per state",
                     f"{c['checked_accel_batch']['ns']:,.1f} ns", f"{c['checked_accel_batch']['ns'] / ours:.2f}x"))
    for method in ("lie_euler", "rkmk4", "cf4"):
        if f"step_batch_{method}" in c:
            rows.append((f"our {method.replace('_', '-')} step batch (sr_step_batch, vectorised), per state",
                         f"{c[f'step_batch_{method}']['ns']:,.1f} ns",
                         f"{c[f'step_batch_{method}']['ns'] / c[f'step_{method}']['ns']:.2f}x our {method.replace('_', ' ')} step"))
    if res.get("c_loop_native"):
        native = res["c_loop_native"]
        rows.append(("our accel, checked API, -march=native", f"{native['accel']['ns']:,.1f} ns", ""))
        if "checked_accel_batch" in native:
            rows.append(("our checked accel batch, -march=native, per state", f"{native['checked_accel_batch']['ns']:,.1f} ns",
                         f"{native['checked_accel_batch']['ns'] / ours:.2f}x"))
        for method in ("lie_euler", "rkmk4", "cf4"):
            if f"step_batch_{method}" in native:
                rows.append((f"our {method.replace('_', '-')} step batch, -march=native, per state",
                             f"{native[f'step_batch_{method}']['ns']:,.1f} ns",
                             f"{native[f'step_batch_{method}']['ns'] / c[f'step_{method}']['ns']:.2f}x our {method.replace('_', ' ')} step"))
    for key, label in C_BASELINES:
        if key in c:
            rows.append((label, f"{c[key]['ns']:,.1f} ns", f"{c[key]['ns'] / ours:,.1f}x slower"))
    out.append(("C against C (the C loop, no Python in the timed region)", rows))

    mine = py["python_model_accel_ns"]
    rows = [("quantity", "time", "vs Model.accel"), ("Model.accel", f"{mine:,.0f} ns", "1")]
    if "raw_cffi_accel_ns" in py:
        raw = py["raw_cffi_accel_ns"]
        rows.append(("raw cffi call of sr_accel, buffers prepared", f"{raw:,.0f} ns",
                     f"Model.accel = {mine / raw:.2f}x it"))
        for method in ("lie-euler", "rkmk4"):
            step, raw = py[f"python_model_step_{method}_ns"], py[f"raw_cffi_step_{method}_ns"]
            rows.append((f"Model.step {method} / raw cffi sr_step", f"{step:,.0f} / {raw:,.0f} ns",
                         f"{step / raw:.2f}x"))
    for key, label in PYTHON_BASELINES:
        if key in py:
            rows.append((label, f"{py[key]:,.0f} ns", f"{py[key] / mine:,.1f}x slower"))
    out.append(("Python call against Python call (one call from Python, best of several rounds)", rows))

    batch = py["python_batch_accel_ns_per_state"]
    rows = [("quantity", "time", "ratio"), (f"Model.accel batch of {py['batch_size']:,}", f"{batch:,.1f} ns",
                                             f"{batch / ours:.2f}x one checked accel in C")]
    if "python_batch_accel_first_call_ns_per_state" in py:
        rows.append(("  the same, first call (output memory touched for the first time)",
                     f"{py['python_batch_accel_first_call_ns_per_state']:,.1f} ns", ""))
    if "memory_floor_ns_per_state" in res:
        floor = res["memory_floor_ns_per_state"]
        rows.append((f"  its memory floor: C reading x, u and writing 5 numbers a state, nothing else (one core)",
                     f"{floor:,.1f} ns", f"{floor / ours:.2f}x one checked accel in C"))
    if "python_batch_accel_in_cache_ns_per_state" in py:
        small = py["python_batch_accel_in_cache_ns_per_state"]
        rows.append((f"Model.accel batch of {py['batch_size_in_cache']:,} (in the caches)", f"{small:,.1f} ns",
                     f"{small / ours:.2f}x one checked accel in C"))
    if "python_batch_step_lie_euler_ns_per_state" in py:
        step, loop = py["python_batch_step_lie_euler_ns_per_state"], py["python_loop_step_lie_euler_ns_per_state"]
        rows.append((f"Model.step lie-euler batch of {py['batch_size_in_cache']:,} / the same in a loop of single calls",
                     f"{step:,.1f} / {loop:,.1f} ns", f"{loop / step:.1f}x faster as a batch"))
    for name, ns in py.get("alternative_batch_ns_per_state", {}).items():
        rows.append((f"batch accel, {name}", f"{ns:,.1f} ns", f"{ns / batch:,.0f}x slower"))
    for key, value in py.items():
        if key.startswith("t_shape_"):
            rows.append((f"t-shape, {key[8:-3]}", f"{value:.2f} ms", ""))
    if "lie_euler_loop_ms" in py:
        ours_le = py["t_shape_lie-euler_ms"] * py["lie_euler_loop_steps"] / 10_000
        for name, ms in py["lie_euler_loop_ms"].items():
            rows.append((f"t-shape {py['lie_euler_loop_steps']:,} steps, Lie-Euler in a Python loop, {name}",
                         f"{ms:,.1f} ms", f"{ms / ours_le:,.0f}x our C lie-euler"))
    out.append(("Batches (per state) and the t-shape run (10,000 steps, end to end from Python)", rows))
    if "step_anatomy" in res:
        out.append(anatomy_section(res["step_anatomy"]))
    return out


def anatomy_section(anatomy):
    """Where a fourth-order step's time goes (runtime.bench.harness.step_anatomy), against the checked
    accel of the same program: what 6x (the target for a fourth-order step) would leave for the step's work besides
    its four accelerations, and what that work takes alone."""
    full, glue = anatomy["full"], anatomy["glue_only"]
    one = full["accel"]
    rows = [("quantity", "time", "vs its checked accel"), ("checked accel (sr_accel), independent calls",
                                                           f"{one:,.1f} ns", "1")]
    for key, label in (("accels_chained_through_nu", "four accels, each one's nu from the previous output"),
                       ("accels_chained_through_state", "four accels, every entry they read from the previous output")):
        rows.append((label, f"{full[key]:,.1f} ns", f"{full[key] / one:.2f}x"))
    for method in ("rkmk4", "cf4"):
        step, rest = full[f"step_{method}"], glue[f"step_{method}"]
        rows.append((f"{method} step (sr_step)", f"{step:,.1f} ns", f"{step / one:.2f}x"))
        rows.append((f"{method} step with the dynamics stubbed: check, group action, kinematics, tableau",
                     f"{rest:,.1f} ns", f"{rest / one:.2f}x"))
    budget = 6 * one - full["accels_chained_through_nu"]
    rows.append(("6x one accel minus four chained accels: left for all but the accelerations",
                 f"{budget:,.1f} ns", f"{budget / one:.2f}x"))
    return ("Anatomy of a fourth-order step (C loop)", rows)


def format_report(res):
    """The benchmark result `res` as the printed text report (tables, flop rate, targets met or missed)."""
    c = res["c_loop"]
    lines = [f"CPU: {res.get('cpu', '?')}"]
    for title, rows in sections(res):
        lines += ["", title, *_table(rows)]
    flops = c["accel_flops"]
    lines.append(f"\naccel: {flops} flops after CSE -> {flops / c['accel_unchecked']['ns']:.2f} GFLOP/s (raw kernel)")
    lines.append("targets: " + "; ".join(f"{name}: {'met' if ok else 'MISSED'}" for name, ok in targets(res)))
    return "\n".join(lines)


def format_markdown(res):
    """The families as Markdown tables, for the README (which quotes stored runs)."""
    lines = []
    for title, rows in sections(res):
        lines += [f"**{title}**", "", "| " + " | ".join(rows[0]) + " |", "|---|---:|---:|"]
        lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |" for row in rows[1:]]
        lines.append("")
    lines.append("targets: " + "; ".join(f"{name}: {'met' if ok else 'MISSED'}" for name, ok in targets(res)))
    return "\n".join(lines)


def result_file_name(date):
    """`<date and time>.json` of a run (ISO time with ':' -> '-', which every file system takes)."""
    return f"{date.replace(':', '-')}.json"


def write_results(result, folder):
    """The run as JSON in its own file, `<date and time>.json` (every run is kept,
    so every figure the README quotes is in a stored file).  Never overwrites: a second run within
    the same second gets `-2`, `-3`, ...  Written to a temporary file first, then linked under its
    name (runtime.atomic.write_new_file).  Returns the path written."""
    return write_new_file(folder, result_file_name(result["date"])[:-len(".json")], ".json",
                          json.dumps(result, indent=1) + "\n")
