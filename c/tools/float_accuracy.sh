#!/bin/sh
# float_accuracy.sh [BUILD_DIR] -- accuracy of the float build (-DSR_USE_FLOAT)
# against the double build, as Markdown tables for docs/embedding.md.
#
# Run `make float-accuracy` in c/: it builds the four programs and calls this
# script.  Needs only a POSIX shell, awk, sort and paste (no Python).
#
#   1. accelerations at 1000 random states (tools/accel_dump.c: the same
#      float-representable inputs in both builds), error of each state as
#      max_i |a_f,i - a_d,i| / max_i |a_d,i|;
#   2. the t-shape example (examples/firmware_tshape.c), float against double,
#      at t = 10 s and at the end (t = 100 s).
set -eu

B=${1:-build}
N=1000
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM

"$B/accel_dump" "$N" >"$tmp/accel_d"
"$B/accel_dump_f" "$N" >"$tmp/accel_f"
"$B/firmware_tshape" >"$tmp/tshape_d"
"$B/firmware_tshape_f" >"$tmp/tshape_f"

# Per-state norm-wise relative error, and the largest absolute error per component.
paste -d, "$tmp/accel_d" "$tmp/accel_f" | awk -F, '
    function abs(v) { return v < 0 ? -v : v }
    {
        nd = 0; ne = 0
        for (i = 1; i <= 5; ++i) {
            e = abs($(i + 5) - $i)
            if (abs($i) > nd) nd = abs($i)
            if (e > ne) ne = e
            if (e > worst[i]) worst[i] = e
        }
        printf "%.6e\n", ne / nd
    }
    END {
        printf "%.2e %.2e %.2e %.2e %.2e\n", worst[1], worst[2], worst[3], worst[4], worst[5] > "/dev/stderr"
    }' 2>"$tmp/worst" | sort -g >"$tmp/rel"

awk -v n="$N" '
    { v[NR] = $1 }
    END {
        print "Accelerations at " n " random states (rates up to 3 rad/s, torques up to 0.2 N m), float build"
        print "vs double; error of a state = (largest |a_float - a_double| entry) / (largest |a_double| entry):"
        print ""
        print "| states | median | 99th percentile | max |"
        print "|---|---|---|---|"
        printf "| %d | %.1e | %.1e | %.1e |\n", NR, v[int((NR + 1) / 2)], v[int(0.99 * NR)], v[NR]
    }' "$tmp/rel"
read -r w1 w2 w3 w4 w5 <"$tmp/worst"
echo ""
echo "Largest absolute error per component [rad/s^2]: a_Sx $w1, a_Sy $w2, a_Sz $w3, a_Y $w4, a_P $w5"
echo ""

# t-shape: rows of t = 10 s and t = 100 s (line 1 is the header, line k+2 is step k).
echo "The t-shape example (10,000 Lie-Euler steps of 0.01 s), float build vs double:"
echo ""
echo "| t [s] | max abs error R_S | R_Y | R_P | q [mm] | omega_S [rad/s] | omega_Y, omega_P [rad/s] |"
echo "|---|---|---|---|---|---|---|"
for line in 1002 10002; do
    d=$(sed -n "${line}p" "$tmp/tshape_d")
    f=$(sed -n "${line}p" "$tmp/tshape_f")
    printf '%s\n%s\n' "$d" "$f" | awk -F, '
        function abs(v) { return v < 0 ? -v : v }
        NR == 1 { for (i = 1; i <= NF; ++i) d[i] = $i }
        NR == 2 {
            # columns: 1 t, 2-10 R_S, 11-19 R_Y, 20-28 R_P, 29-31 q, 32-34 omega_S, 35-36 omega_Y, omega_P
            for (i = 2; i <= NF; ++i) e[i] = abs($i - d[i])
            rs = ry = rp = ws = wj = q2 = 0
            for (i = 2; i <= 10; ++i) if (e[i] > rs) rs = e[i]
            for (i = 11; i <= 19; ++i) if (e[i] > ry) ry = e[i]
            for (i = 20; i <= 28; ++i) if (e[i] > rp) rp = e[i]
            for (i = 29; i <= 31; ++i) q2 += e[i] * e[i]
            for (i = 32; i <= 34; ++i) if (e[i] > ws) ws = e[i]
            for (i = 35; i <= 36; ++i) if (e[i] > wj) wj = e[i]
            printf "| %g | %.1e | %.1e | %.1e | %.1e | %.1e | %.1e |\n", d[1], rs, ry, rp, 1000 * sqrt(q2), ws, wj
        }'
done
