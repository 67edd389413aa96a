"""Fuzzing the C API (c/fuzz/fuzz_api.c, docs/robustness.md) for a bounded time under ASan + UBSan.

The harness asserts the API contract on every input (documented status codes, finite outputs
on SR_OK, outputs untouched or fully written, nothing written outside the buffers) and aborts
on a violation.  Two engines run the same target:

* the plain-C driver (c/fuzz/driver.c, any compiler with the sanitizers): random bytes from a
  seeded PRNG, double and float builds;
* clang's libFuzzer (coverage-guided), when clang with -fsanitize=fuzzer is installed.

SR_FUZZ_SECONDS (default 10; .ci/run sets 60) is the budget of the main engine: libFuzzer when
available, otherwise the double driver; the other runs get 3 s.
"""
import os
import re
import shutil
import subprocess

import pytest

from c_build import make_shared
from conftest import ROOT

C_DIR = ROOT / "c"
MAKE = shutil.which("make")
CC = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
CLANG = shutil.which("clang")
BUDGET = float(os.environ.get("SR_FUZZ_SECONDS", "10"))
SHORT = 3.0
ENV = dict(os.environ, ASAN_OPTIONS="detect_leaks=0:abort_on_error=1", UBSAN_OPTIONS="abort_on_error=1")

pytestmark = pytest.mark.skipif(not (MAKE and CC), reason="needs make and a C compiler")


def make(build, *targets, check=True):
    result = subprocess.run([MAKE, "-s", "-j2", f"BUILD={build}", *targets], cwd=C_DIR, capture_output=True,
                            text=True, env=ENV)
    if check and result.returncode != 0:
        pytest.fail(f"make {' '.join(targets)} failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    return result


def sanitizers_work(tmp_path):
    probe = tmp_path / "probe.c"
    probe.write_text("int main(void) { return 0; }\n")
    return subprocess.run([CC, "-fsanitize=address,undefined", str(probe), "-o", str(tmp_path / "probe")],
                          capture_output=True).returncode == 0


def libfuzzer_works(tmp_path):
    if not CLANG:
        return False
    probe = tmp_path / "fz.c"
    probe.write_text("#include <stdint.h>\n#include <stddef.h>\n"
                     "int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }\n")
    return subprocess.run([CLANG, "-fsanitize=fuzzer,address,undefined", str(probe), "-o", str(tmp_path / "fz")],
                          capture_output=True).returncode == 0


@pytest.fixture(scope="module")
def fuzz_build(tmp_path_factory):
    """(the BUILD with the two plain-C drivers, whether libFuzzer works).  The drivers are built in
    the BUILD the tests share (tests/c_build.py): their sanitizer library is the one the C tests'
    sanitizer run uses."""
    probes = tmp_path_factory.mktemp("fuzz-probes")
    if not sanitizers_work(probes):
        pytest.skip("the C compiler has no AddressSanitizer/UBSan")
    out, made = make_shared(tmp_path_factory, "{build}/fuzz_driver", "{build}/fuzz_driver_f", env=ENV)
    if made.returncode != 0:
        pytest.fail(f"building the fuzz drivers failed:\n{made.stdout[-3000:]}\n{made.stderr[-3000:]}")
    return out, libfuzzer_works(probes)


@pytest.mark.parametrize("program", ["fuzz_driver", "fuzz_driver_f"])
def test_api_contract_holds_for_random_inputs_under_sanitizers(fuzz_build, program):
    build, have_libfuzzer = fuzz_build
    seconds = BUDGET if program == "fuzz_driver" and not have_libfuzzer else SHORT
    result = subprocess.run([build / program, "-t", str(seconds), "-s", "20241122"], capture_output=True,
                            text=True, env=ENV, timeout=seconds * 10 + 60)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-4000:]
    m = re.search(r"fuzz: (\d+) executions in ([\d.]+) s", result.stdout)
    assert m and int(m.group(1)) > 1000, result.stdout


#: Inputs that once broke the contract (libFuzzer's crash files), replayed on every run and given to
#: libFuzzer as seeds (c/fuzz/regressions/, c/Makefile fuzz-libfuzzer).
REGRESSIONS = sorted((C_DIR / "fuzz" / "regressions").iterdir())


@pytest.mark.parametrize("program", ["fuzz_driver", "fuzz_driver_f"])
def test_inputs_that_once_broke_the_contract_now_hold_it(fuzz_build, program):
    build, _ = fuzz_build
    assert REGRESSIONS, "c/fuzz/regressions/ is empty"
    result = subprocess.run([build / program, *map(str, REGRESSIONS)], capture_output=True, text=True, env=ENV,
                            timeout=120)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-4000:]


def test_api_contract_holds_under_libfuzzer(fuzz_build, tmp_path):
    _, have_libfuzzer = fuzz_build
    if not have_libfuzzer:
        pytest.skip("clang with libFuzzer (-fsanitize=fuzzer) is not installed")
    # Its own BUILD: the run writes a corpus there for a minute, which must not hold the shared one.
    result = make(tmp_path, "fuzz-libfuzzer", f"FUZZ_SECONDS={int(BUDGET)}", "FUZZ_SEED=20241122", check=False)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-4000:]
    runs = re.search(r"stat::number_of_executed_units:\s+(\d+)", result.stderr)
    assert runs and int(runs.group(1)) > 1000, result.stderr[-2000:]


#: Targets that break the contract, each by wrapping one function: (the wrapper, the function the
#: harness must name).
BROKEN = {
    # success with a NaN
    "energy-nan": ('static int bad_energy(const sr_model *m, const sr_real *x, sr_real *e)\n'
                   '{ (void)m; (void)x; *e = (sr_real)NAN; return SR_OK; }\n'
                   '#define sr_energy bad_energy', "sr_energy"),
    # an error that forgets the estimator's last state
    "slope-update-writes-on-error": (
        'static int bad_slope_update(sr_slope_estimator *e, const sr_real *x, const sr_real *u)\n'
        '{ const int s = sr_slope_update(e, x, u); if (s != SR_OK && e) e->started = 0; return s; }\n'
        '#define sr_slope_update bad_slope_update', "sr_slope_update"),
    # a torque beyond u_max with SR_OK
    "control-offsets-beyond-u-max": (
        'static int bad_control_offsets(const sr_lqr *l, const sr_model *m, const sr_real *x, const sr_lqr_target *t,\n'
        '    const sr_lqr_offsets *o, sr_lqr_memory *mem, sr_real *u, sr_real *raw)\n'
        '{ const int s = sr_lqr_control_offsets(l, m, x, t, o, mem, u, raw); if (s == SR_OK) u[0] = l->u_max * 1.5f;'
        ' return s; }\n'
        '#define sr_lqr_control_offsets bad_control_offsets', "sr_lqr_control_offsets"),
}


@pytest.mark.parametrize("broken", list(BROKEN))
def test_driver_finds_a_contract_violation(fuzz_build, tmp_path, broken):
    """The harness can fail: a target that breaks the contract (a non-finite output with SR_OK, the
    estimator changed on an error, a torque beyond the limit) aborts."""
    build, _ = fuzz_build
    wrapper, function = BROKEN[broken]
    bad = tmp_path / "bad_target.c"
    # Wrap the function after the header declares it: the harness must notice.
    bad.write_text((C_DIR / "fuzz" / "fuzz_api.c").read_text().replace(
        '#include "spherical_robot.h"', '#include "spherical_robot.h"\n#include <math.h>\n' + wrapper, 1))
    exe = tmp_path / "bad_driver"
    compile_ = subprocess.run([CC, "-std=c99", "-O1", "-I", str(C_DIR / "include"), "-I", str(ROOT / "generated"), str(bad),
                               str(C_DIR / "fuzz" / "driver.c"), str(build / "libsphericalrobot_asan.a"),
                               "-fsanitize=address,undefined", "-lm", "-o", str(exe)], capture_output=True, text=True)
    assert compile_.returncode == 0, compile_.stderr
    result = subprocess.run([exe, "-n", "100"], capture_output=True, text=True, env=ENV)
    assert result.returncode != 0
    assert f"contract violated by {function}" in result.stderr and "failing input: seed" in result.stderr
