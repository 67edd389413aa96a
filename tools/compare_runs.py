#!/usr/bin/env python3
"""Compare the firmware example run on an emulated Cortex-M with the host build's run.

    compare_runs.py double HOST.csv TARGET.csv
        the double build on the Cortex-M7 against the host double build: holds when the outputs
        are identical, bit for bit (both built with -ffp-contract=off).  Otherwise the number of
        differing entries and the largest relative difference (relative to the larger of the two
        values and of the column's largest magnitude over the run) are printed, with whether it
        is within RELATIVE_TOL, the tolerance allowed for contraction; it still fails.
    compare_runs.py double-libm HOST.csv TARGET.csv [TOL]
        the same, for a program whose results pass through functions that newlib and glibc round
        differently (the float build's closed loop on the estimator: libm's atan2f in the
        controller's Log and pendulum angle; the double build uses the library's own and is
        compared with `double`): holds when identical or within TOL (default RELATIVE_TOL).
    compare_runs.py float HOST_F.csv TARGET_F.csv HOST_D.csv
        the float build on the Cortex-M4F against the host float build: the position q after
        10 s (row t = 10, or the last row of a shorter run) within Q_TOL metres; the distance of
        both from the host double build is reported, then and at the end.

Each comparison is then repeated on a copy of the target's output with one entry perturbed (by
one unit in the last place in double, by 1.5 Q_TOL in float), which must fail: the check is
shown able to fail on every run.  Standard library only.  Exit status 0 when the comparison
holds, 1 otherwise.
"""
import math
import sys

RELATIVE_TOL = 1e-12   # double identical, or within 1e-12 relative for contraction
Q_TOL = 1e-4           # float t-shape after 10 s within 1e-4 m of the host float build
T_CHECK = 10.0         # [s]
Q_COLUMNS = slice(28, 31)  # t, R_S (9), R_Y (9), R_P (9), then q


def read_csv(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [[float(v) for v in line.split(",")] for line in f if line.strip()]
    # 36 columns: t and the state (firmware_tshape); 38: and the torques (firmware_lqr).
    if header[0] != "t" or len(header) not in (36, 38) or any(len(r) != len(header) for r in rows):
        raise SystemExit(f"compare_runs: {path}: not an example's CSV (t, the state[, u_Y, u_P])")
    return rows


def worst_relative(host, target):
    """(largest relative difference, its row, its column) over every entry."""
    if len(host) != len(target):
        return float("inf"), min(len(host), len(target)), 0
    scale = [max(abs(r[j]) for r in host) for j in range(len(host[0]))]
    worst = (0.0, 0, 0)
    for i, (h, t) in enumerate(zip(host, target)):
        for j, (a, b) in enumerate(zip(h, t)):
            if a != b:
                rel = abs(a - b) / max(abs(a), abs(b), scale[j])
                if not rel <= worst[0]:  # NaN counts as worst
                    worst = (rel, i, j)
    return worst


def first_difference(host, target):
    """The first row where the two runs differ."""
    return next((i for i, (h, t) in enumerate(zip(host, target)) if h != t), min(len(host), len(target)))


def double_holds(host, target, label, tol=0.0):
    if host == target:
        print(f"  {label}: identical ({len(target)} rows x {len(target[0])} entries)")
        return True
    rel, row, col = worst_relative(host, target)
    differing = sum(a != b for h, t in zip(host, target) for a, b in zip(h, t))
    bound = max(tol, RELATIVE_TOL)
    print(f"  {label}: NOT identical: {differing} entries differ (the first in row "
          f"{first_difference(host, target)}), largest relative difference {rel:.3g} (row {row}, column {col}), "
          f"{'within' if rel <= bound else 'beyond'} {bound:g}")
    return rel <= tol


def row_at(rows, t):
    for r in rows:
        if abs(r[0] - t) < 1e-9:
            return r
    raise SystemExit(f"compare_runs: no row at t = {t}")


def distance(a, b):
    return sum((x - y) ** 2 for x, y in zip(a[Q_COLUMNS], b[Q_COLUMNS])) ** 0.5


def check_time(rows):
    """T_CHECK, or the last row's time of a shorter run."""
    return min(T_CHECK, rows[-1][0])


def float_holds(host_f, target_f, host_d, label):
    t_end, t_check = target_f[-1][0], check_time(host_f)
    d_host = distance(row_at(target_f, t_check), row_at(host_f, t_check))
    ok = len(target_f) == len(host_f) and d_host <= Q_TOL
    print(f"  {label}: |q_target - q_host_float| at t = {t_check:g} s: {d_host:.3g} m "
          f"(tolerance {Q_TOL:g}): {'ok' if ok else 'MISMATCH'}")
    for t in sorted({t_check, t_end}):
        print(f"    t = {t:g} s: |q_target - q_host_float| = {distance(row_at(target_f, t), row_at(host_f, t)):.3g} m, "
              f"|q_target - q_host_double| = {distance(row_at(target_f, t), row_at(host_d, t)):.3g} m, "
              f"|q_host_float - q_host_double| = {distance(row_at(host_f, t), row_at(host_d, t)):.3g} m")
    return ok


def perturbed(rows, row, col, delta):
    copy = [list(r) for r in rows]
    copy[row][col] += delta
    return copy


def main(argv):
    if len(argv) == 4 and argv[1] == "double":
        host, target = read_csv(argv[2]), read_csv(argv[3])
        ok = double_holds(host, target, "double, Cortex-M7 vs host")
        # q_x at the end, one unit in the last place up.
        row, col = len(target) - 1, Q_COLUMNS.start
        caught = not double_holds(host, perturbed(target, row, col, math.ulp(target[row][col])),
                                  "self-check, q_x at the end moved by one ulp")
    elif len(argv) in (4, 5) and argv[1] == "double-libm":
        host, target = read_csv(argv[2]), read_csv(argv[3])
        tol = float(argv[4]) if len(argv) == 5 else RELATIVE_TOL
        ok = double_holds(host, target, "double, Cortex-M7 vs host (libm may round differently)", tol)
        row, col = len(target) - 1, Q_COLUMNS.start
        caught = not double_holds(host, perturbed(target, row, col, 10 * tol * abs(target[row][col])),
                                  f"self-check, q_x at the end moved by {10 * tol:g} relative", tol)
    elif len(argv) == 5 and argv[1] == "float":
        host_f, target_f, host_d = read_csv(argv[2]), read_csv(argv[3]), read_csv(argv[4])
        ok = float_holds(host_f, target_f, host_d, "float, Cortex-M4F vs host")
        row = next(i for i, r in enumerate(target_f) if abs(r[0] - check_time(host_f)) < 1e-9)
        caught = not float_holds(host_f, perturbed(target_f, row, Q_COLUMNS.start, 1.5 * Q_TOL), host_d,
                                 f"self-check, q_x at {check_time(host_f):g} s moved by 1.5e-4 m")
    else:
        sys.exit(__doc__)
    if not caught:
        print("compare_runs: the perturbed output passed: this check cannot fail")
    return 0 if ok and caught else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
