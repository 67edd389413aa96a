"""`python -m runtime bench-table`: the figures that README.md and docs/performance.md quote, rendered
from one stored run of `make bench`, the pinned reference (bench/results/reference.json).

The documents hold the rendered Markdown between two markers, `<!-- bench-table:SECTION -->` and
`<!-- /bench-table -->`; a test compares each block with what this module renders from the
reference, so the quoted figures change only when the reference file is replaced on purpose
(`--write` rewrites the blocks from it).  Ratios are taken like against like, within the one run:
our C against the strongest C baseline, a Python call against a Python call.
"""
import argparse
import json
import pathlib
import re
import sys

from .report import C_BASELINES, PYTHON_BASELINES

ROOT = pathlib.Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "bench" / "results" / "reference.json"
DOCUMENTS = {"headline": ROOT / "README.md", "performance": ROOT / "docs" / "performance.md"}
END = "<!-- /bench-table -->"

#: The Kane model compiled the ways its users ship it; the CasADi C of our KKT reference is a
#: verification model and the Jacobian row another quantity, so neither is "the strongest baseline".
KANE_C = ("kane_casadi_c_accel", "kane_sympy_c_accel", "kane_pydy_c_accel")
#: The Python-call baselines a user would pick for speed (the verification models left out).
KANE_PYTHON = ("pydy_cython_rhs_ns", "kane_lambdified_accel_ns", "kane_lambdified_math_accel_ns",
               "kane_lambdified_default_accel_ns", "kane_casadi_function_ns")
METHODS = (("lie_euler", "Lie–Euler"), ("rkmk4", "RKMK4"), ("cf4", "CF4"))


def begin_marker(section):
    """The HTML comment that opens a quoted table of `section` in a Markdown document."""
    return f"<!-- bench-table:{section} -->"


def _ns(value):
    return f"{value:,.0f} ns" if value >= 100 else f"{value:,.1f} ns"


def _markdown(header, rows, align="|---|---:|---:|"):
    lines = ["| " + " | ".join(header) + " |", align]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return lines


def _caption(res, path_label):
    return (f"From `{path_label}`: CPU {res.get('cpu', 'not recorded')}, one pinned core, "
            f"{res['states']:,} random states, `{res['params']}`.")


def headline(res, path_label="bench/results/reference.json"):
    """The README's one table: the kernels against the strongest baseline of their kind."""
    c, py = res["c_loop"], res["python"]
    ours = c["accel"]["ns"]
    labels = dict(C_BASELINES) | dict(PYTHON_BASELINES)
    kane = min((k for k in KANE_C if k in c), key=lambda k: c[k]["ns"])
    rows = [("checked `sr_accel` (C)", _ns(ours), "1"),
            (f"strongest C baseline: {labels[kane]}", _ns(c[kane]["ns"]), f"{c[kane]['ns'] / ours:.1f}× slower"),
            ("one step (C): " + " / ".join(name for _, name in METHODS),
             " / ".join(_ns(c[f"step_{m}"]["ns"])[:-3] for m, _ in METHODS) + " ns",
             " / ".join(f"{c[f'step_{m}']['ns'] / ours:.1f}×" for m, _ in METHODS))]
    jac = c["accel_jacobian"]["ns"]
    rows.append(("`sr_accel_jacobian` (C)", _ns(jac), f"{jac / ours:.1f}×"))
    rows.append(("Kane model's accel Jacobian by CasADi AD, CasADi C", _ns(c["kane_casadi_c_accel_jacobian"]["ns"]),
                 f"{c['kane_casadi_c_accel_jacobian']['ns'] / jac:.1f}× slower than `sr_accel_jacobian`"))
    rows.append(("step Jacobian (C): " + " / ".join(name for _, name in METHODS),
                 " / ".join(_ns(c[f"step_jacobian_{m}"]["ns"])[:-3] for m, _ in METHODS) + " ns",
                 " / ".join(f"{c[f'step_jacobian_{m}']['ns'] / jac:.2f}×" for m, _ in METHODS)
                 + " `sr_accel_jacobian`"))
    rows.append(("LQR controller, one sample (`sr_lqr_control`)", _ns(c["lqr_control"]["ns"]),
                 f"{c['lqr_control']['ns'] / ours:.1f}×"))
    mine = py["python_model_accel_ns"]
    rows.append(("`Model.accel`, one call from Python", _ns(mine),
                 f"{mine / py['raw_cffi_accel_ns']:.2f}× the raw cffi call"))
    best = min((k for k in KANE_PYTHON if k in py), key=lambda k: py[k])
    rows.append((f"strongest Python-call baseline: {labels[best]}", _ns(py[best]), f"{py[best] / mine:,.0f}× slower"))
    rows.append(("t-shape, 10,000 RKMK4 steps end to end from Python", f"{py['t_shape_rkmk4_ms']:.2f} ms", ""))
    lines = [_caption(res, path_label), ""]
    lines += _markdown(("quantity", "time", "ratio (checked `sr_accel` = 1 unless named)"), rows)
    return "\n".join(lines)


def performance(res, path_label="bench/results/reference.json"):
    """docs/performance.md's tables: every family of the run, like against like."""
    c, py = res["c_loop"], res["python"]
    ours = c["accel"]["ns"]
    lines = [_caption(res, path_label), "", "**C against C** (the C loop, no Python in the timed region)", ""]
    rows = [("`sr_accel`, checked", _ns(ours), "1"),
            ("`sr_accel`, the raw generated kernel", _ns(c["accel_unchecked"]["ns"]), ""),
            ("`sr_inertia`", _ns(c["inertia"]["ns"]), "")]
    rows += [(f"`sr_step`, {name}", _ns(c[f"step_{m}"]["ns"]), f"{c[f'step_{m}']['ns'] / ours:.2f}×")
             for m, name in METHODS]
    rows.append(("`sr_accel_jacobian`", _ns(c["accel_jacobian"]["ns"]), f"{c['accel_jacobian']['ns'] / ours:.2f}×"))
    rows += [(f"`sr_step_jacobian`, {name}", _ns(c[f"step_jacobian_{m}"]["ns"]),
              f"{c[f'step_jacobian_{m}']['ns'] / ours:.2f}×") for m, name in METHODS]
    rows.append(("`sr_lqr_control`, one sample", _ns(c["lqr_control"]["ns"]), f"{c['lqr_control']['ns'] / ours:.2f}×"))
    rows.append(("`sr_accel` of a general robot (general kernels)", _ns(c["accel_general_robot"]["ns"]),
                 f"{c['accel_general_robot']['ns'] / ours:.2f}×"))
    rows.append(("`sr_step` RKMK4 of a general robot", _ns(c["step_rkmk4_general_robot"]["ns"]),
                 f"{c['step_rkmk4_general_robot']['ns'] / ours:.2f}×"))
    rows.append(("`sr_checked_accel_batch`, per state", _ns(c["checked_accel_batch"]["ns"]),
                 f"{c['checked_accel_batch']['ns'] / ours:.2f}×"))
    rows += [(f"`sr_step_batch`, {name}, per state", _ns(c[f"step_batch_{m}"]["ns"]),
              f"{c[f'step_batch_{m}']['ns'] / ours:.2f}×") for m, name in METHODS]
    for key, label in C_BASELINES:
        if key in c:
            rows.append((label, _ns(c[key]["ns"]), f"{c[key]['ns'] / ours:.2f}×"))
    lines += _markdown(("quantity", "time", "vs checked `sr_accel`"), rows)

    mine = py["python_model_accel_ns"]
    lines += ["", "**Python call against Python call** (one call, best of several rounds)", ""]
    rows = [("`Model.accel`", _ns(mine), "1"),
            ("raw cffi call of `sr_accel`, buffers prepared", _ns(py["raw_cffi_accel_ns"]),
             f"{py['raw_cffi_accel_ns'] / mine:.2f}×")]
    for method, name in (("lie-euler", "Lie–Euler"), ("rkmk4", "RKMK4")):
        step, raw = py[f"python_model_step_{method}_ns"], py[f"raw_cffi_step_{method}_ns"]
        rows.append((f"`Model.step` {name} / raw cffi `sr_step`", f"{_ns(step)[:-3]} / {_ns(raw)}",
                     f"{step / mine:.2f}× / {raw / mine:.2f}×"))
    for key, label in PYTHON_BASELINES:
        if key in py:
            rows.append((label, _ns(py[key]), f"{py[key] / mine:,.0f}×"))
    lines += _markdown(("quantity", "time", "vs `Model.accel`"), rows)

    batch = py["python_batch_accel_ns_per_state"]
    lines += ["", "**Batches and end to end from Python**", ""]
    rows = [(f"`Model.accel` on {py['batch_size']:,} states, per state", _ns(batch), f"{batch / ours:.2f}×"),
            (f"`Model.accel` on {py['batch_size_in_cache']:,} states (in the caches), per state",
             _ns(py["python_batch_accel_in_cache_ns_per_state"]),
             f"{py['python_batch_accel_in_cache_ns_per_state'] / ours:.2f}×"),
            ("memory floor: reading x, u and writing 5 numbers a state, nothing else",
             _ns(res["memory_floor_ns_per_state"]), f"{res['memory_floor_ns_per_state'] / ours:.2f}×"),
            (f"`Model.step` Lie–Euler on {py['batch_size_in_cache']:,} states / a Python loop of single calls, per state",
             f"{_ns(py['python_batch_step_lie_euler_ns_per_state'])[:-3]} / {_ns(py['python_loop_step_lie_euler_ns_per_state'])}",
             "")]
    for name, ns in py.get("alternative_batch_ns_per_state", {}).items():
        rows.append((f"batch accel, {name}, per state", _ns(ns), f"{ns / ours:,.0f}×"))
    for key, value in py.items():
        if key.startswith("t_shape_"):
            rows.append((f"t-shape, 10,000 steps, {key[8:-3]}", f"{value:.2f} ms", ""))
    for name, ms in py.get("lie_euler_loop_ms", {}).items():
        rows.append((f"t-shape, {py['lie_euler_loop_steps']:,} Lie–Euler steps in a Python loop, {name}",
                     f"{ms:,.1f} ms", ""))
    lines += _markdown(("quantity", "time", "vs checked `sr_accel`"), rows)

    full, glue = res["step_anatomy"]["full"], res["step_anatomy"]["glue_only"]
    one = full["accel"]
    lines += ["", "**Anatomy of a fourth-order step** (bench/step_anatomy.c)", ""]
    rows = [("checked `sr_accel`, independent calls", _ns(one), "1"),
            ("four accels, each one's ν from the previous output", _ns(full["accels_chained_through_nu"]),
             f"{full['accels_chained_through_nu'] / one:.2f}×"),
            ("four accels, every entry they read from the previous output", _ns(full["accels_chained_through_state"]),
             f"{full['accels_chained_through_state'] / one:.2f}×")]
    for m, name in METHODS[1:]:
        rows.append((f"{name} step", _ns(full[f"step_{m}"]), f"{full[f'step_{m}'] / one:.2f}×"))
        rows.append((f"{name} step with the dynamics stubbed (check, group action, kinematics, tableau)",
                     _ns(glue[f"step_{m}"]), f"{glue[f'step_{m}'] / one:.2f}×"))
    lines += _markdown(("quantity", "time", "vs its checked `sr_accel`"), rows)
    return "\n".join(lines)


RENDERERS = {"headline": headline, "performance": performance}


def render(section, res, path_label="bench/results/reference.json"):
    """The Markdown table of `section` ('headline' or 'performance') rendered from the run `res`."""
    return RENDERERS[section](res, path_label)


def quoted_block(text, section):
    """The Markdown a document holds between the section's markers (None without markers)."""
    match = re.search(re.escape(begin_marker(section)) + r"\n(.*?)\n" + re.escape(END), text, re.S)
    return match.group(1) if match else None


def replace_block(text, section, markdown):
    """`text` with the section's quoted block replaced by `markdown`; ValueError without markers."""
    if quoted_block(text, section) is None:
        raise ValueError(f"no {begin_marker(section)} ... {END} block")
    pattern = re.escape(begin_marker(section)) + r"\n.*?\n" + re.escape(END)
    return re.sub(pattern, lambda _: f"{begin_marker(section)}\n{markdown}\n{END}", text, count=1, flags=re.S)


def main(argv=None):
    """`python -m runtime bench-table`: print (or --write) the quoted tables rendered from the reference run."""
    parser = argparse.ArgumentParser(prog="python -m runtime bench-table",
                                     description="Render the quoted benchmark tables from the pinned reference run.")
    parser.add_argument("--reference", type=pathlib.Path, default=REFERENCE, metavar="FILE",
                        help="a stored run of `make bench` (default: bench/results/reference.json)")
    parser.add_argument("--section", choices=sorted(RENDERERS), default="headline",
                        help="headline: README.md's table; performance: docs/performance.md's tables")
    parser.add_argument("--write", action="store_true",
                        help="rewrite the section's block in its document instead of printing it")
    args = parser.parse_args(argv)
    try:
        res = json.loads(args.reference.read_text())
    except (OSError, ValueError) as exc:
        parser.error(f"--reference: cannot read {args.reference}: {exc}")
    try:
        label = args.reference.resolve().relative_to(ROOT).as_posix()
    except ValueError:
        label = str(args.reference)
    try:
        markdown = render(args.section, res, label)
    except KeyError as exc:
        parser.error(f"--reference: {args.reference} has no {exc} (not a run of `make bench`?)")
    if not args.write:
        print(markdown)
        return 0
    document = DOCUMENTS[args.section]
    document.write_text(replace_block(document.read_text(), args.section, markdown))
    print(f"bench-table: wrote the {args.section} table of {document.relative_to(ROOT)}", file=sys.stderr)
    return 0
