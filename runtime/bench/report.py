"""The benchmark's report: the table on stdout (with the targets of issue 7) and the result files."""
import json
import os
import pathlib


def format_report(res):
    c, py = res["c_loop"], res["python"]
    ours = c["accel"]["ns"]
    rows = [("quantity", "time", "vs our accel (C loop)")]

    def row(name, ns, ratio=True):
        rows.append((name, f"{ns:,.1f} ns", f"{ns / ours:,.1f}x" if ratio else ""))

    row("accel, checked API (C loop)", ours)
    row("accel, raw generated kernel (C loop)", c["accel_unchecked"]["ns"])
    row("inertia (C loop)", c["inertia"]["ns"])
    for key in ("step_lie_euler", "step_rkmk4", "step_cf4"):
        if key in c:
            row(f"{key.replace('_', ' ')} (C loop)", c[key]["ns"])
    if "casadi_generated_reference_accel" in c:
        row("CasADi-generated C of the AD reference (C loop)", c["casadi_generated_reference_accel"]["ns"])
    if res.get("c_loop_native"):
        row("accel, checked API, -march=native (C loop)", res["c_loop_native"]["accel"]["ns"])
    row("Model.accel, one call from Python", py["python_model_accel_ns"])
    if "raw_cffi_accel_ns" in py:
        raw = py["raw_cffi_accel_ns"]
        rows.append(("  raw cffi call of sr_accel, buffers prepared (same run)", f"{raw:,.1f} ns",
                     f"Model.accel {py['python_model_accel_ns'] / raw:.2f}x it"))
        for method in ("lie-euler", "rkmk4"):
            step, raw = py[f"python_model_step_{method}_ns"], py[f"raw_cffi_step_{method}_ns"]
            rows.append((f"Model.step {method}, one call from Python / raw cffi sr_step",
                         f"{step:,.1f} / {raw:,.1f} ns", f"{step / raw:.2f}x"))
    row(f"Model.accel batch of {py['batch_size']:,}, per state", py["python_batch_accel_ns_per_state"])
    if "python_batch_accel_first_call_ns_per_state" in py:
        row("  the same, first call (output memory touched for the first time)",
            py["python_batch_accel_first_call_ns_per_state"])
    for name, ns in py.get("alternative_batch_ns_per_state", {}).items():
        rows.append((f"batch accel, {name}, per state", f"{ns:,.1f} ns",
                     f"{ns / py['python_batch_accel_ns_per_state']:,.0f}x our batch"))
    row("NumPy, the paper's matrix formulas, per call", py["numpy_paper_accel_ns"])
    row("CasADi reference from Python, per call", py["casadi_python_accel_ns"])
    if "kane_lambdified_accel_ns" in py:
        row("sympy.physics.mechanics KanesMethod, lambdify(cse=True), per call", py["kane_lambdified_accel_ns"])
        row("sympy.physics.mechanics KanesMethod, lambdify defaults, per call",
            py["kane_lambdified_default_accel_ns"])
    if "kane_lambdified_math_accel_ns" in py:
        row("KanesMethod, lambdify(cse=True) with the math module (hand-tuned), per call",
            py["kane_lambdified_math_accel_ns"])
    for key, value in py.items():
        if key.startswith("t_shape_"):
            rows.append((f"t-shape 10,000 steps, {key[8:-3]}, end to end", f"{value:.2f} ms", ""))
    if "lie_euler_loop_ms" in py:
        ours_le = py["t_shape_lie-euler_ms"] * py["lie_euler_loop_steps"] / 10_000
        for name, ms in py["lie_euler_loop_ms"].items():
            rows.append((f"t-shape {py['lie_euler_loop_steps']:,} steps, Lie-Euler in a Python loop, {name}",
                         f"{ms:,.1f} ms", f"{ms / ours_le:,.0f}x our lie-euler"))
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    lines = ["  ".join(cell.ljust(w) if i == 0 else cell.rjust(w) for i, (cell, w) in enumerate(zip(r, widths)))
             for r in rows]
    lines.insert(1, "-" * len(lines[0]))
    flops = c["accel_flops"]
    lines.append(f"\naccel: {flops} flops after CSE -> {flops / c['accel_unchecked']['ns']:.2f} GFLOP/s (raw kernel)")
    targets = [("accel <= 150 ns", ours <= 150)]
    if "casadi_generated_reference_accel" in c:
        targets.append(("10x faster than the CasADi-generated reference",
                        c["casadi_generated_reference_accel"]["ns"] >= 10 * ours))
    if "kane_lambdified_accel_ns" in py:
        targets.append(("1000x faster per call than Kane lambdified with defaults",
                        py["kane_lambdified_default_accel_ns"] >= 1000 * ours))
        targets.append(("1000x faster per call than Kane lambdified with cse=True",
                        py["kane_lambdified_accel_ns"] >= 1000 * ours))
    if "raw_cffi_accel_ns" in py:
        targets.append(("Model.accel <= 2x the raw cffi call", py["python_model_accel_ns"] <= 2 * py["raw_cffi_accel_ns"]))
        targets.append(("Model.step <= 2x the raw cffi call", all(
            py[f"python_model_step_{m}_ns"] <= 2 * py[f"raw_cffi_step_{m}_ns"] for m in ("lie-euler", "rkmk4"))))
    for method in ("rkmk4", "cf4"):
        if f"t_shape_{method}_ms" in py:
            targets.append((f"t-shape with {method} <= 10 ms", py[f"t_shape_{method}_ms"] <= 10))
    lines.append("targets: " + "; ".join(f"{name}: {'met' if ok else 'MISSED'}" for name, ok in targets))
    return "\n".join(lines)


def result_file_name(date):
    """`<date and time>.json` of a run (ISO time with ':' -> '-', which every file system takes)."""
    return f"{date.replace(':', '-')}.json"


def write_results(result, folder):
    """The run as JSON in its own file, `<date and time>.json` (issue 17, item 7: every run is kept,
    so every figure the README quotes is in a stored file).  Never overwrites: a second run within
    the same second gets `-2`, `-3`, ...  Written to a temporary file first, then linked under its
    name (os.link fails rather than replace an existing file).  Returns the path written."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    stem = result_file_name(result["date"])[:-len(".json")]
    tmp = folder / f".{stem}.json.tmp"
    tmp.write_text(json.dumps(result, indent=1) + "\n")
    try:
        for n in range(1, 1000):
            path = folder / (f"{stem}.json" if n == 1 else f"{stem}-{n}.json")
            try:
                os.link(tmp, path)
                return path
            except FileExistsError:
                continue
        raise FileExistsError(f"{folder}: 999 result files for {stem}")
    finally:
        tmp.unlink()
