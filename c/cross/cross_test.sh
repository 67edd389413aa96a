#!/bin/sh
# cross_test.sh [OUT] -- the library on emulated Cortex-M parts (`make cross-test` in c/, which
# passes CROSS_PREFIX, QEMU, MAKE, M4_CPU_FLAGS and M7_CPU_FLAGS; run from c/).
#
#  1. the tools: arm-none-eabi-gcc + newlib, qemu-system-arm, cmake; installed with apt-get when
#     missing and we are root (as .ci/run does for clang), otherwise a clear failure;
#  2. host builds (this Makefile, host CC) of the firmware example and the C tests, double and float;
#  3. with the same Makefile and only its variables (CC, AR, CFLAGS, LDFLAGS, BUILD): the float
#     library, tests and example for the Cortex-M4F, the double ones for the Cortex-M7;
#  4. the float library for the M4 once more under -Wdouble-promotion -Wfloat-conversion -Werror,
#     and its objects checked for software double routines (__aeabi_d*);
#  5. the C tests under QEMU (mps2-an386, mps2-an500): the same "N passed, 0 failed" as the host;
#  6. the firmware examples under QEMU against the host build of the same precision
#     (tools/compare_runs.py: double identical, bit for bit; float within 1e-4 m at 10 s): the open-loop t-shape and
#     the closed loops (the LQR at 100 Hz, c/examples/firmware_lqr.c; the NMPC at 20 Hz,
#     c/examples/firmware_nmpc.c, run with -icount shift=0: its instructions per sample are
#     printed, every warm-started sample held to NMPC_INSTRUCTION_BUDGET); the double t-shape again
#     with -ffp-contract=fast must be caught, and its difference is printed (also the float one);
#     the loop on the estimator (c/examples/firmware_ekf_lqr.c on the recorded samples of
#     examples/ekf_lqr_vector) against the host build of its precision, run with -icount shift=0:
#     the filter's instructions per 200 Hz sample are printed, the M4F's median held to
#     EKF_INSTRUCTION_BUDGET; the LQR's closed loop with the weighted slope estimate
#     (c/examples/firmware_lqr.c on examples/slope_vector) on the Cortex-M4F against the host float
#     build, run with -icount shift=0: its instructions per sample printed, the median held to
#     SLOPE_INSTRUCTION_BUDGET;
#  7. the CMake toolchain file (c/cmake/arm-none-eabi.cmake): both libraries configured and built
#     for the two CPUs, and checked like the Makefile's;
#  8. the M4 sizes and stacks (tools/m4_report.py): a Lie-Euler-only firmware linked and run under QEMU,
#     checked for __aeabi_d*.
# Every step runs even if an earlier one failed; the exit status is 1 if any failed.
set -u
OUT=${1:-build/cross}
CROSS_PREFIX=${CROSS_PREFIX:-arm-none-eabi-}
QEMU=${QEMU:-qemu-system-arm}
MAKE=${MAKE:-make}
M4_CPU_FLAGS=${M4_CPU_FLAGS:--mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard}
M7_CPU_FLAGS=${M7_CPU_FLAGS:--mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard}
CC_CROSS=${CROSS_PREFIX}gcc
JOBS=${CROSS_JOBS:-$(nproc 2>/dev/null || echo 2)}   # parallel compiles: the builds are most of the time
QEMU_TIMEOUT=${QEMU_TIMEOUT:-900}   # seconds per emulated program; the slowest takes ~1 min
# Instructions of any warm-started NMPC sample: a quarter of the 50 ms period of a 400 MHz
# Cortex-M7 at one instruction a cycle.
NMPC_INSTRUCTION_BUDGET=${NMPC_INSTRUCTION_BUDGET:-5000000}
# Instructions of the median 200 Hz sample of the filter on the Cortex-M4F (float): a prediction
# (RKMK4 step and its Jacobian), an IMU and an encoder update.
EKF_INSTRUCTION_BUDGET=${EKF_INSTRUCTION_BUDGET:-300000}
# Instructions of the median 100 Hz sample of the weighted slope estimate and the law on the
# Cortex-M4F (float): ten one-period predictions of two RKMK4 steps, the fit, the law.
SLOPE_INSTRUCTION_BUDGET=${SLOPE_INSTRUCTION_BUDGET:-300000}

failures=0
step() { printf '\n== %s\n' "$*"; }
fail() { echo "cross-test: FAIL: $*"; failures=$((failures + 1)); }

# ---- 1. tools ---------------------------------------------------------------------------------
missing=""
command -v "$CC_CROSS" >/dev/null 2>&1 || missing="$missing gcc-arm-none-eabi libnewlib-arm-none-eabi"
command -v "$QEMU" >/dev/null 2>&1 || missing="$missing qemu-system-arm"
command -v cmake >/dev/null 2>&1 || missing="$missing cmake"
if [ -n "$missing" ]; then
    step "installing$missing"
    if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
        started=$(date +%s)
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
            --no-install-recommends $missing >/dev/null ||
            { echo "cross-test: apt-get could not install$missing"; exit 1; }
        echo "cross-test: installed in $(( $(date +%s) - started )) s"
    else
        echo "cross-test: missing$missing; install them (Debian: apt-get install$missing) or run as root"
        exit 1
    fi
fi
echo "$("$CC_CROSS" --version | head -n 1); $("$QEMU" --version | head -n 1)"

# The two targets: name, CPU flags, QEMU machine, linker script, library scalar.
M4_DIR=$OUT/m4 M7_DIR=$OUT/m7 HOST_DIR=$OUT/host

# cross_make DIR CPU_FLAGS LINKER_SCRIPT TARGET...: c/Makefile for a Cortex-M, through its variables.
cross_make() {
    dir=$1 cpu=$2 script=$3
    shift 3
    mkdir -p "$dir" &&
        "$CC_CROSS" $cpu -O2 -std=c99 -Wall -Wextra -Wpedantic -Werror -c cross/startup.c -o "$dir/startup.o" &&
        $MAKE -j"$JOBS" --no-print-directory CC="$CC_CROSS" AR="${CROSS_PREFIX}ar" CFLAGS="$cpu -O2" CPPFLAGS=-DSR_TEST_EMULATED \
            LDFLAGS="-Lcross -T cross/$script --specs=rdimon.specs -nostartfiles $dir/startup.o" \
            BUILD="$dir" "$@"
}

# soft_double_symbols FILE...: the software double-precision routines the files use or define.
soft_double_symbols() {
    "${CROSS_PREFIX}nm" "$@" 2>/dev/null | awk '$NF ~ /^__aeabi_(d|[fil]2d|ui2d|ul2d)/ { print $NF }' | sort -u
}

# ---- 2.-3. builds -------------------------------------------------------------------------------
step "host builds (double and float)"
$MAKE -j"$JOBS" --no-print-directory BUILD="$HOST_DIR" "$HOST_DIR/firmware_tshape" "$HOST_DIR/firmware_tshape_f" \
    "$HOST_DIR/firmware_lqr" "$HOST_DIR/firmware_lqr_f" "$HOST_DIR/firmware_nmpc" "$HOST_DIR/firmware_nmpc_f" \
    "$HOST_DIR/sr_tests" "$HOST_DIR/sr_tests_f" || fail "host build"
step "Cortex-M4F build (float): $M4_CPU_FLAGS -O2"
cross_make "$M4_DIR" "$M4_CPU_FLAGS" mps2-an386.ld "$M4_DIR/firmware_tshape_f" "$M4_DIR/firmware_lqr_f" \
    "$M4_DIR/firmware_nmpc_f" "$M4_DIR/sr_tests_f" ||
    fail "Cortex-M4F build"
step "Cortex-M7 build (double): $M7_CPU_FLAGS -O2"
cross_make "$M7_DIR" "$M7_CPU_FLAGS" mps2-an500.ld "$M7_DIR/firmware_tshape" "$M7_DIR/firmware_lqr" \
    "$M7_DIR/firmware_nmpc" "$M7_DIR/sr_tests" ||
    fail "Cortex-M7 build"

# ---- 4. no double arithmetic in the float build ---------------------------------------------------
step "float library for the M4 under -Wdouble-promotion -Wfloat-conversion -Werror; no __aeabi_d*"
if $MAKE -j"$JOBS" --no-print-directory CC="$CC_CROSS" AR="${CROSS_PREFIX}ar" BUILD="$OUT/m4-strict" \
        CFLAGS="$M4_CPU_FLAGS -O2 -Wdouble-promotion -Wfloat-conversion" "$OUT/m4-strict/libsphericalrobot_f.a"; then
    found=$(soft_double_symbols "$OUT/m4-strict/libsphericalrobot_f.a")
    [ -z "$found" ] && echo "  no software double routine referenced" || fail "float library uses$found"
else
    fail "float library does not build under -Wdouble-promotion -Wfloat-conversion -Werror"
fi
# The check itself must be able to fail: one float expression with a double constant.
printf 'float scaled(float x);\nfloat scaled(float x) { return x * 0.1; }\n' >"$OUT/double_slip.c"
"$CC_CROSS" $M4_CPU_FLAGS -O2 -c "$OUT/double_slip.c" -o "$OUT/double_slip.o" &&
    found=$(soft_double_symbols "$OUT/double_slip.o") && [ -n "$found" ] &&
    echo "  self-check: 'x * 0.1' on a float is caught ($(echo $found))" ||
    fail "the __aeabi_d* check does not see a double slipped into float code"

# ---- 5.-6. under QEMU ----------------------------------------------------------------------------
# run_qemu MACHINE ELF OUTPUT [QEMU OPTION...]: the program's semihosting output into OUTPUT; its exit status.
run_qemu() {
    machine=$1 elf=$2 output=$3
    shift 3
    timeout "$QEMU_TIMEOUT" "$QEMU" -M "$machine" -nographic -monitor none -serial none \
        -semihosting-config enable=on,target=native "$@" -kernel "$elf" >"$output"
}

# c_tests LABEL MACHINE TARGET_ELF HOST_PROGRAM
c_tests() {
    step "C tests, $1 ($2 under QEMU) against the host"
    "$4" >"$OUT/$(basename "$4").host.txt" 2>&1
    want=$(tail -n 1 "$OUT/$(basename "$4").host.txt")
    started=$(date +%s)
    run_qemu "$2" "$3" "$OUT/$(basename "$3").$2.txt"
    rc=$?
    got=$(tail -n 1 "$OUT/$(basename "$3").$2.txt")
    echo "  host: $want; target: $got (exit $rc, $(( $(date +%s) - started )) s)"
    case $got in *" passed, 0 failed") ;; *) fail "$1 C tests: $got" ;; esac
    [ "$rc" = 0 ] || fail "$1 C tests exited with $rc"
    [ "$got" = "$want" ] || fail "$1 C tests ran a different number of tests than the host"
}
c_tests "Cortex-M4F float" mps2-an386 "$M4_DIR/sr_tests_f" "$HOST_DIR/sr_tests_f"
c_tests "Cortex-M7 double" mps2-an500 "$M7_DIR/sr_tests" "$HOST_DIR/sr_tests"

step "firmware example (t-shape, 10,000 Lie-Euler steps) under QEMU against the host"
"$HOST_DIR/firmware_tshape" >"$OUT/tshape.host.csv" || fail "host double example"
"$HOST_DIR/firmware_tshape_f" >"$OUT/tshape_f.host.csv" || fail "host float example"
run_qemu mps2-an500 "$M7_DIR/firmware_tshape" "$OUT/tshape.m7.csv" || fail "Cortex-M7 example exited with $?"
run_qemu mps2-an386 "$M4_DIR/firmware_tshape_f" "$OUT/tshape_f.m4.csv" || fail "Cortex-M4F example exited with $?"
python3 ../tools/compare_runs.py double "$OUT/tshape.host.csv" "$OUT/tshape.m7.csv" || fail "Cortex-M7 example"
python3 ../tools/compare_runs.py float "$OUT/tshape_f.host.csv" "$OUT/tshape_f.m4.csv" "$OUT/tshape.host.csv" ||
    fail "Cortex-M4F example"

step "closed-loop firmware example (the LQR at 100 Hz, heading step, 30 s) under QEMU against the host"
"$HOST_DIR/firmware_lqr" >"$OUT/lqr.host.csv" || fail "host double closed loop"
"$HOST_DIR/firmware_lqr_f" >"$OUT/lqr_f.host.csv" || fail "host float closed loop"
run_qemu mps2-an500 "$M7_DIR/firmware_lqr" "$OUT/lqr.m7.csv" || fail "Cortex-M7 closed loop exited with $?"
run_qemu mps2-an386 "$M4_DIR/firmware_lqr_f" "$OUT/lqr_f.m4.csv" || fail "Cortex-M4F closed loop exited with $?"
# Bit for bit: the controller's atan2 (Log, pendulum angle) and sin/cos of the heading are the
# library's own (c/src/sr_trig.c), not newlib's on the target and glibc's on the host.
python3 ../tools/compare_runs.py double "$OUT/lqr.host.csv" "$OUT/lqr.m7.csv" || fail "Cortex-M7 closed loop"
python3 ../tools/compare_runs.py float "$OUT/lqr_f.host.csv" "$OUT/lqr_f.m4.csv" "$OUT/lqr.host.csv" ||
    fail "Cortex-M4F closed loop"

step "closed-loop firmware example with the weighted slope estimate (examples/slope_vector, 10 s) on the Cortex-M4F"
$MAKE -j"$JOBS" --no-print-directory BUILD="$HOST_DIR" "$HOST_DIR/firmware_lqr_slope" "$HOST_DIR/firmware_lqr_slope_f" ||
    fail "host build of the example with the slope estimate"
cross_make "$M4_DIR" "$M4_CPU_FLAGS" mps2-an386.ld "$M4_DIR/firmware_lqr_slope_f" ||
    fail "Cortex-M4F build of the example with the slope estimate"
"$HOST_DIR/firmware_lqr_slope" >"$OUT/slope.host.csv" || fail "host double, with the slope estimate"
"$HOST_DIR/firmware_lqr_slope_f" >"$OUT/slope_f.host.csv" || fail "host float, with the slope estimate"
# Under -icount shift=0 the firmware prints the instructions of each sample's estimate and law
# (SysTick, calibrated); the median is held to SLOPE_INSTRUCTION_BUDGET.
run_qemu mps2-an386 "$M4_DIR/firmware_lqr_slope_f" "$OUT/slope_f.m4.csv" -icount shift=0 2>"$OUT/slope_f.m4.txt" ||
    fail "Cortex-M4F example with the slope estimate exited with $?"
counts=$(grep '^instructions per sample' "$OUT/slope_f.m4.txt")
echo "  Cortex-M4F float: ${counts:-no instruction counts: $(cat "$OUT/slope_f.m4.txt")}"
median=$(echo "$counts" | sed -n 's/.* p50 \([0-9]*\),.*/\1/p')
[ -n "$median" ] && [ "$median" -le "$SLOPE_INSTRUCTION_BUDGET" ] ||
    fail "Cortex-M4F slope estimate: the median sample beyond $SLOPE_INSTRUCTION_BUDGET instructions (${median:-none counted})"
python3 ../tools/compare_runs.py float "$OUT/slope_f.host.csv" "$OUT/slope_f.m4.csv" "$OUT/slope.host.csv" ||
    fail "Cortex-M4F closed loop with the slope estimate"

step "firmware example on the estimator (sensor samples in, EKF, LQR; examples/ekf_lqr_vector, 1 s) under QEMU"
EKF_VECTOR=examples/ekf_lqr_vector
$MAKE -j"$JOBS" --no-print-directory BUILD="$HOST_DIR" CPPFLAGS="-I$EKF_VECTOR" "$HOST_DIR/firmware_ekf_lqr" \
    "$HOST_DIR/firmware_ekf_lqr_f" || fail "host build of the example on the estimator"
cross_make "$M4_DIR" "$M4_CPU_FLAGS" mps2-an386.ld CPPFLAGS="-I$EKF_VECTOR" "$M4_DIR/firmware_ekf_lqr_f" ||
    fail "Cortex-M4F build of the example on the estimator"
cross_make "$M7_DIR" "$M7_CPU_FLAGS" mps2-an500.ld CPPFLAGS="-I$EKF_VECTOR" "$M7_DIR/firmware_ekf_lqr" ||
    fail "Cortex-M7 build of the example on the estimator"
"$HOST_DIR/firmware_ekf_lqr" <"$EKF_VECTOR/events.txt" >"$OUT/ekf.host.csv" || fail "host double, on the estimator"
"$HOST_DIR/firmware_ekf_lqr_f" <"$EKF_VECTOR/events.txt" >"$OUT/ekf_f.host.csv" || fail "host float, on the estimator"
# Under -icount shift=0 the firmware prints the instructions of the filter's 200 Hz samples
# (SysTick, calibrated); the M4F's median is held to EKF_INSTRUCTION_BUDGET.
run_qemu mps2-an500 "$M7_DIR/firmware_ekf_lqr" "$OUT/ekf.m7.csv" -icount shift=0 <"$EKF_VECTOR/events.txt" \
    2>"$OUT/ekf.m7.txt" || fail "Cortex-M7 example on the estimator exited with $?"
echo "  Cortex-M7 double: $(grep '^instructions per filter sample' "$OUT/ekf.m7.txt" || cat "$OUT/ekf.m7.txt")"
run_qemu mps2-an386 "$M4_DIR/firmware_ekf_lqr_f" "$OUT/ekf_f.m4.csv" -icount shift=0 <"$EKF_VECTOR/events.txt" \
    2>"$OUT/ekf_f.m4.txt" || fail "Cortex-M4F example on the estimator exited with $?"
counts=$(grep '^instructions per filter sample' "$OUT/ekf_f.m4.txt")
echo "  Cortex-M4F float: ${counts:-no instruction counts: $(cat "$OUT/ekf_f.m4.txt")}"
median=$(echo "$counts" | sed -n 's/.* p50 \([0-9]*\),.*/\1/p')
[ -n "$median" ] && [ "$median" -le "$EKF_INSTRUCTION_BUDGET" ] ||
    fail "Cortex-M4F filter: the median sample beyond $EKF_INSTRUCTION_BUDGET instructions (${median:-none counted})"
# Both against the host build of their precision: the double one identical (the library's own
# trigonometry); the float one identical or within 1e-12 relative, where newlib's and glibc's atan2f
# round an argument differently.
python3 ../tools/compare_runs.py double "$OUT/ekf.host.csv" "$OUT/ekf.m7.csv" || fail "Cortex-M7, on the estimator"
python3 ../tools/compare_runs.py double-libm "$OUT/ekf_f.host.csv" "$OUT/ekf_f.m4.csv" || fail "Cortex-M4F, on the estimator"
"${CROSS_PREFIX}size" "$M4_DIR/firmware_ekf_lqr_f" "$M7_DIR/firmware_ekf_lqr"

# The NMPC, bit for bit in double (its node, its Log and the firmware's target pass sin, cos and
# atan2 of arbitrary arguments: the library's own, the same bits on both); the float build within
# 1e-4 m.  Under -icount shift=0 the firmware prints the instructions of each sample (SysTick,
# calibrated).
step "NMPC closed-loop firmware example (20 Hz on the circle, 3 s) under QEMU against the host"
"$HOST_DIR/firmware_nmpc" >"$OUT/nmpc.host.csv" || fail "host double NMPC"
"$HOST_DIR/firmware_nmpc_f" >"$OUT/nmpc_f.host.csv" || fail "host float NMPC"
# nmpc_on LABEL MACHINE ELF CSV: runs it, prints its size and instruction counts, holds the worst
# warm-started sample to NMPC_INSTRUCTION_BUDGET (the cold start runs once, at rest, before the loop).
nmpc_on() {
    started=$(date +%s)
    run_qemu "$2" "$3" "$4" -icount shift=0 2>"$4.txt" || fail "$1 NMPC exited with $?"
    counts=$(grep '^instructions per sample' "$4.txt")
    echo "  $1 ($(( $(date +%s) - started )) s): ${counts:-no instruction counts: $(cat "$4.txt")}"
    "${CROSS_PREFIX}size" "$3" | awk 'NR == 2 { printf "  flash (text + data) %d B, static RAM (data + bss) %d B\n", $1 + $2, $2 + $3 }'
    worst=$(echo "$counts" | sed -n 's/.* max \([0-9]*\) .*/\1/p')
    [ -n "$worst" ] && [ "$worst" -le "$NMPC_INSTRUCTION_BUDGET" ] ||
        fail "$1 NMPC: a warm-started sample beyond $NMPC_INSTRUCTION_BUDGET instructions (${worst:-none counted})"
}
nmpc_on "Cortex-M7 double" mps2-an500 "$M7_DIR/firmware_nmpc" "$OUT/nmpc.m7.csv"
nmpc_on "Cortex-M4F float" mps2-an386 "$M4_DIR/firmware_nmpc_f" "$OUT/nmpc_f.m4.csv"
python3 ../tools/compare_runs.py double "$OUT/nmpc.host.csv" "$OUT/nmpc.m7.csv" || fail "Cortex-M7 NMPC"
python3 ../tools/compare_runs.py float "$OUT/nmpc_f.host.csv" "$OUT/nmpc_f.m4.csv" "$OUT/nmpc.host.csv" ||
    fail "Cortex-M4F NMPC"

# A slightly different kernel must be caught: the same double build with fused multiply-adds
# (-ffp-contract=fast; the M7's FPU has VFMA).  Its distance from the host is what contraction
# costs; the float build's is printed for information.
step "the Cortex-M7 double build with -ffp-contract=fast must differ from the host"
cross_make "$OUT/m7-contract" "$M7_CPU_FLAGS -ffp-contract=fast" mps2-an500.ld "$OUT/m7-contract/firmware_tshape" &&
    run_qemu mps2-an500 "$OUT/m7-contract/firmware_tshape" "$OUT/tshape.m7-contract.csv" ||
    fail "Cortex-M7 build or run with -ffp-contract=fast"
if python3 ../tools/compare_runs.py double "$OUT/tshape.host.csv" "$OUT/tshape.m7-contract.csv"; then
    fail "the double comparison did not see fused multiply-adds"
fi
step "for information: the Cortex-M4F float build with -ffp-contract=fast"
cross_make "$OUT/m4-contract" "$M4_CPU_FLAGS -ffp-contract=fast" mps2-an386.ld "$OUT/m4-contract/firmware_tshape_f" &&
    run_qemu mps2-an386 "$OUT/m4-contract/firmware_tshape_f" "$OUT/tshape_f.m4-contract.csv" &&
    python3 ../tools/compare_runs.py float "$OUT/tshape_f.host.csv" "$OUT/tshape_f.m4-contract.csv" "$OUT/tshape.host.csv" ||
    echo "  (not a failure: contraction is off in the builds above)"

# ---- 7. CMake -------------------------------------------------------------------------------------
# cmake_build CPU FLOAT(ON/OFF)
cmake_build() {
    dir=$OUT/cmake-$1-$2
    step "CMake, toolchain file cmake/arm-none-eabi.cmake, SR_CPU=$1, SR_USE_FLOAT=$2"
    if cmake -S . -B "$dir" -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake -DSR_CPU="$1" \
            -DSR_USE_FLOAT="$2" -DSR_BUILD_TESTS=OFF >"$dir.log" 2>&1 && cmake --build "$dir" -j "$JOBS" >>"$dir.log" 2>&1; then
        lib=$(ls "$dir"/libsphericalrobot*.a)
        attrs=$("${CROSS_PREFIX}readelf" -A "$lib" | sort -u | grep -E 'Tag_CPU_name|Tag_FP_arch|Tag_ABI_VFP_args' | tr -s ' \n' ' ')
        echo "  $lib:$attrs"
        if [ "$2" = ON ]; then
            found=$(soft_double_symbols "$lib")
            [ -z "$found" ] || fail "CMake float library uses$found"
        fi
    else
        cat "$dir.log"
        fail "CMake build for $1"
    fi
}
cmake_build cortex-m4 ON
cmake_build cortex-m7 OFF

# ---- 8. sizes and stacks ---------------------------------------------------------------------------
step "Cortex-M4F sizes and stacks (tools/m4_report.py)"
python3 ../tools/m4_report.py --build "$OUT/report" --cross-prefix "$CROSS_PREFIX" --qemu "$QEMU" ||
    fail "m4_report"

echo
if [ "$failures" -ne 0 ]; then
    echo "cross-test: $failures FAILED"
    exit 1
fi
echo "cross-test: all passed"
