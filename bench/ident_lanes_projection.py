"""What lanes forms of the analytic sensitivity's two generated kernels would gain: the state-derivative
kernel of the stages (sr_gen_general_accel_jacobian_terms) and the regressor (sr_gen_regressor), emitted
over n states as the generator emits sr_gen_accel_lanes (derive/codegen/emit.py: the same CSE'd body,
`lane_guard` for its test, one loop without branches), compiled with the Python extension's flags
(-O3 -ffp-contract=off -DSR_CLONES), and timed against the scalar kernels of generated/ on the states of
the identify-bench's 30 s log (seed 0), with every output compared bit for bit.

Two things differ from `emit_lanes`, both needed for GCC 12 to vectorise these loops: each output array
has its stride, and GCC is allowed more run-time alias tests than its default
(--param vect-max-version-for-alias-checks=100: the five output arrays of the state-derivative kernel
need more than 10, and at the default the loop stays scalar; one output array with a row of all 165
outputs per state does not vectorise either); and the expressions of the parameters alone (the
regressor's sin and cos of the slope) are computed once before the loop (a call in the loop keeps
it scalar).  Nothing here is written to generated/: a measurement, for the
decision whether the generator and the sensitivity path should take this form.  (They took it: the generator
now emits sr_gen_*_lanes with the same hoisting, `emit.hoisted`, which this script uses.)

    .venv/bin/python bench/ident_lanes_projection.py [--out DIR]

Takes about 2-3 CPU-min (the kernels' derivation and CSE, then GCC on 1,500 lines).  The result is kept
as lanes-projection-<date and time>.json in --out (bench/results/identify).
"""
import argparse
import datetime
import json
import os
import pathlib
import re
import struct
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from runtime.atomic import write_new_file  # noqa: E402
from runtime.bench.timing import cpu_name  # noqa: E402

KERNELS = ("general_accel_jacobian_terms", "regressor")


def lanes_text(kernel, layouts):
    """(C text of sr_gen_<name>_rows, the outputs' (name, width)): the kernel over n states, each
    output a row per state in its own array."""
    from derive.codegen import emit as E
    per_lane = dict(E.PER_LANE, nud="nud_stride*i")
    used, body = E.kernel_body(kernel, E.lane_guard, row="ROW")
    body = [re.sub(r"\b(\w+)\[ROW(\d+)\]", r"\1[\1_stride*i + \2]", line) for line in body]
    entries = E.input_entries(kernel, used, layouts)
    once = [f"    const sr_real {s.name} = {a}[{i}];" for s, a, i in entries if a not in per_lane]
    each = [f"    const sr_real {s.name} = {a}[{per_lane[a]} + {i}];" for s, a, i in entries if a in per_lane]
    before, inside = E.hoisted(body, [s.name for s, a, _ in entries if a not in per_lane])
    args = [E.INPUT_DOCS[kernel.inputs[0]][0], "long n"]
    args += [f"const sr_real *restrict {a}, long {a}_stride" for a in kernel.inputs[1:]]
    args += [f"sr_real *restrict {o.name}, long {o.name}_stride" for o in kernel.outputs]
    signature = f"void sr_gen_{kernel.name}_rows({', '.join(args)}, sr_real *restrict ok)"
    loop = each + ["    sr_real good = 1;"] + inside + ["    ok[i] = good;"]
    text = "\n".join(["SR_LANES_CLONES " + signature, "{", *once, *before, "    long i;", "    for (i = 0; i < n; ++i) {",
                      *("    " + line for line in loop), "    }", "}", ""])
    return text, [(o.name, len(o.exprs)) for o in kernel.outputs]


HARNESS = r"""
#include "sr_generated.h"
#include <stdio.h>
#include <string.h>
#include <time.h>
%(protos)s
static double cpu(void) { return (double)clock() / CLOCKS_PER_SEC; }
static double X[%(n)d * 35], U[%(n)d * 2], A[%(n)d * 5], P[SR_GEN_NPARAM], CG[SR_GEN_GENERAL_NCONST];
static double M[%(n)d * 15], F[%(n)d * 5], DF[%(n)d * 60], DU[%(n)d * 10], DM[%(n)d * 75], Y[%(n)d * 135];
static double M2[%(n)d * 15], F2[%(n)d * 5], DF2[%(n)d * 60], DU2[%(n)d * 10], DM2[%(n)d * 75], Y2[%(n)d * 135], OK[%(n)d];
int main(int argc, char **argv)
{
    const long n = %(n)d, reps = %(reps)d, block = 64;
    long i, r, k, bad = 0, bad_ok = 0;
    double t[5];
    FILE *fp = fopen(argv[1], "rb");
    (void)argc;
    if (!fp || fread(P, 8, SR_GEN_NPARAM, fp) != SR_GEN_NPARAM || fread(X, 8, n * 35, fp) != (size_t)(n * 35)
        || fread(U, 8, n * 2, fp) != (size_t)(n * 2) || fread(A, 8, n * 5, fp) != (size_t)(n * 5)) return 2;
    fclose(fp);
    sr_gen_general_constants(P, CG);
    t[0] = cpu();
    for (r = 0; r < reps; ++r)
        for (i = 0; i < n; ++i)
            bad += sr_gen_general_accel_jacobian_terms(CG, X + 35 * i, U + 2 * i, M + 15 * i, F + 5 * i, DF + 60 * i,
                                                       DU + 10 * i, DM + 75 * i) != SR_GEN_OK;
    t[1] = cpu();
    for (r = 0; r < reps; ++r)
        for (i = 0; i < n; i += block)
            sr_gen_general_accel_jacobian_terms_rows(CG, n - i < block ? n - i : block, X + 35 * i, 35, U + 2 * i, 2,
                                                     M2 + 15 * i, 15, F2 + 5 * i, 5, DF2 + 60 * i, 60, DU2 + 10 * i, 10,
                                                     DM2 + 75 * i, 75, OK + i);
    t[2] = cpu();
    for (r = 0; r < reps; ++r)
        for (i = 0; i < n; ++i) bad += sr_gen_regressor(P, X + 35 * i, A + 5 * i, Y + 135 * i) != SR_GEN_OK;
    t[3] = cpu();
    for (r = 0; r < reps; ++r)
        for (i = 0; i < n; i += block)
            sr_gen_regressor_rows(P, n - i < block ? n - i : block, X + 35 * i, 35, A + 5 * i, 5, Y2 + 135 * i, 135,
                                  OK + i);
    t[4] = cpu();
    for (i = 0; i < n; ++i) {
        bad_ok += OK[i] != 1;
        k = memcmp(M2 + 15 * i, M + 15 * i, 15 * 8) || memcmp(F2 + 5 * i, F + 5 * i, 5 * 8)
            || memcmp(DF2 + 60 * i, DF + 60 * i, 60 * 8) || memcmp(DU2 + 10 * i, DU + 10 * i, 10 * 8)
            || memcmp(DM2 + 75 * i, DM + 75 * i, 75 * 8) || memcmp(Y2 + 135 * i, Y + 135 * i, 135 * 8);
        bad += k;
    }
    printf("{\"states\": %%ld, \"differing_states\": %%ld, \"lanes_flag_cleared\": %%ld, "
           "\"terms_scalar_us\": %%.4f, \"terms_lanes_us\": %%.4f, \"regressor_scalar_us\": %%.4f, \"regressor_lanes_us\": %%.4f}\n",
           n, bad, bad_ok, (t[1] - t[0]) / reps / n * 1e6, (t[2] - t[1]) / reps / n * 1e6, (t[3] - t[2]) / reps / n * 1e6,
           (t[4] - t[3]) / reps / n * 1e6);
    return 0;
}
"""


def states_file(path):
    """The states, torques and accelerations of the identify-bench's 30 s log (seed 0) and its
    nominal robot's parameters, as the harness reads them."""
    from runtime import Model
    from runtime.identification.bench import DEFAULT_PARAMS
    from runtime.identification.coverage import simulated_log
    log, nominal, _ = simulated_log(DEFAULT_PARAMS[0], 30.0, 0)
    X = np.ascontiguousarray(log.truth_states()[:-1])
    u = np.ascontiguousarray(log.torque_at(log.truth.t[:-1]))
    a = np.ascontiguousarray(Model(nominal).accel(X, u))
    path.write_bytes(np.ascontiguousarray(nominal.as_array(), float).tobytes() + X.tobytes() + u.tobytes() + a.tobytes())
    return len(X)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "results" / "identify")
    parser.add_argument("--reps", type=int, default=20)
    args = parser.parse_args(argv)
    from derive.codegen import emit as E
    from derive.codegen.constant_pool import pool_constants
    from derive.codegen.kernels import array_layouts, kernels
    ks, constants = pool_constants(kernels())
    ks, general_constants = pool_constants(ks, E.GENERAL_CONSTANTS)
    layouts = array_layouts(constants, general_constants)
    emitted = {k.name: lanes_text(k, layouts) for k in ks if k.name in KERNELS}
    load = [os.getloadavg()]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        n = states_file(tmp / "states.bin")
        protos = "\n".join(text.split("\n")[0].replace("SR_LANES_CLONES ", "") + ";" for text, _ in emitted.values())
        (tmp / "rows.c").write_text('#include "sr_generated.h"\n#include <math.h>\n\n'
                                    + "\n".join(text for text, _ in emitted.values()))
        (tmp / "harness.c").write_text(HARNESS % {"protos": protos, "n": n, "reps": args.reps})
        flags = ["-std=c99", "-O3", "-ffp-contract=off", "-DSR_CLONES", "--param", "vect-max-version-for-alias-checks=100",
                 f"-I{ROOT / 'generated'}", f"-I{ROOT / 'c/include'}",
                 f"-I{ROOT / 'c/src'}"]
        subprocess.run(["gcc", *flags, str(tmp / "rows.c"), str(tmp / "harness.c"), str(ROOT / "generated/sr_generated.c"),
                        str(ROOT / "c/src/sr_trig.c"), "-lm", "-o", str(tmp / "harness")], check=True)
        done = subprocess.run([str(tmp / "harness"), str(tmp / "states.bin")], check=True, capture_output=True, text=True)
    load.append(os.getloadavg())
    result = json.loads(done.stdout)
    if result["differing_states"] or result["lanes_flag_cleared"]:
        raise SystemExit(f"the lanes forms differ from the scalar kernels: {result}")
    now = datetime.datetime.now().strftime("%Y-%m-%dT%H-%M-%S")
    record = {"date": now, "cpu": cpu_name(), "load_start_end": load, "what": __doc__.split("\n\n")[0], **result,
              "outputs": {name: layout for name, (_, layout) in emitted.items()}}
    for k in ("terms", "regressor"):
        print(f"{k}: scalar {result[k + '_scalar_us']:.3f} us a state, lanes {result[k + '_lanes_us']:.3f} "
              f"({result[k + '_scalar_us'] / result[k + '_lanes_us']:.2f}x), {n} states equal bit for bit")
    path = write_new_file(args.out, f"lanes-projection-{now}", ".json", json.dumps(record, indent=1) + "\n")
    print(f"written: {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
