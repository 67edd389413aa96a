"""The embeddable C library on its own, built with c/Makefile and c/CMakeLists.txt.

* the C tests (c/tests/) pass in the double and the float build, and under
  AddressSanitizer + UndefinedBehaviorSanitizer;
* the library's objects reference no allocator and hold no mutable globals;
* every public function returns a status code;
* the firmware-style example (c/examples/firmware_tshape.c) prints, bit for
  bit, the trajectory of the Python runtime for the same scenario, and its
  float build stays within the accuracy documented in docs/embedding.md;
* CMake builds it stand-alone and through add_subdirectory.

The plain builds go to one BUILD directory that the tests share under a lock
(tests/c_build.py), the others to fresh directories under pytest's tmp, never to
c/build, so that concurrent test runs in one checkout cannot race on the same objects.  No Python is involved in building the C.
"""
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from c_build import make_shared
from conftest import ROOT

C_DIR = ROOT / "c"
INCLUDE = C_DIR / "include"   # the public headers: the one include path of a user (with generated/)
MAKE = shutil.which("make")
CC = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
DT, STEPS = 0.01, 10_000

# Libraries a firmware image may be asked to provide: libm and the mem* family.
MATH = {"sin", "cos", "sincos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "hypot", "exp", "log",
        "pow", "fabs", "floor", "ceil", "fmod", "fma", "fmin", "fmax", "copysign", "nearbyint",
        "remainder"}
ALLOWED_EXTERNAL = MATH | {f + "f" for f in MATH} | {"memcpy", "memset", "memmove"}
ALLOCATORS = {"malloc", "calloc", "realloc", "free", "aligned_alloc", "posix_memalign", "memalign",
              "valloc", "reallocarray", "strdup", "strndup"}
# nm symbol types of writable data: initialized (d/D, small g/G), uninitialized (b/B, s/S), common, weak objects.
MUTABLE_TYPES = set("bBdDgGsSCvV")

pytestmark = pytest.mark.skipif(not (MAKE and CC), reason="needs make and a C compiler")


def run(cmd, cwd=C_DIR, env=None, check=True):
    result = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    if check and result.returncode != 0:
        pytest.fail(f"{' '.join(map(str, cmd))} failed ({result.returncode}):\n"
                    f"{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    return result


def make(build, *targets, env=None):
    return run([MAKE, "-s", "-j2", f"BUILD={build}", "CFLAGS=-O2", *targets], env=env)


@pytest.fixture(scope="module")
def build(tmp_path_factory):
    """c/Makefile's default target (libraries, example, C tests) plus the tools, in the BUILD the tests
    share (tests/c_build.py); nothing may write into it but c/Makefile."""
    out, result = make_shared(tmp_path_factory, "all", "tools")
    if result.returncode != 0:
        pytest.fail(f"make all tools failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    return out


def tshape_torques():
    """The t-shape program from the issue: step n (1-based) uses row n-1."""
    u = np.zeros((STEPS, 2))
    u[0:800, 0] = 0.1        # yoke +0.1 N m, steps 1-800
    u[1599:1900, 1] = -0.1   # pendulum -0.1 N m, steps 1600-1900
    u[2499:3000, 0] = -0.1   # yoke -0.1 N m, steps 2500-3000
    u[3399:4500, 1] = 0.1    # pendulum +0.1 N m, steps 3400-4500
    return u


def read_csv(text):
    """Header and rows of the example's CSV, every field parsed by float() (exact for %.17g)."""
    lines = text.splitlines()
    return lines[0].split(","), np.array([[float(v) for v in line.split(",")] for line in lines[1:]])


def passed_line(output):
    last = output.strip().splitlines()[-1]
    m = re.fullmatch(r"(\d+) passed, 0 failed", last)
    assert m, f"unexpected last line {last!r}"
    return int(m.group(1))


def nm_symbols(path):
    """(type, name) of every symbol of a library or object."""
    out = run(["nm", str(path)]).stdout
    return [(p[-2], p[-1]) for p in (line.split() for line in out.splitlines()) if len(p) >= 2 and ":" not in p[-1]]


# ---- the C tests ---------------------------------------------------------------------------

@pytest.mark.parametrize("program, scalar", [("sr_tests", "double"), ("sr_tests_f", "float")])
def test_c_tests_pass(build, program, scalar):
    out = run([build / program]).stdout
    assert f"sr_real = {scalar}" in out
    assert passed_line(out) >= 30


def test_c_tests_pass_under_address_and_undefined_behaviour_sanitizers(tmp_path_factory, tmp_path):
    probe = tmp_path / "probe.c"
    probe.write_text("int main(void) { return 0; }\n")
    if run([CC, "-fsanitize=address,undefined", str(probe), "-o", str(tmp_path / "probe")],
           check=False).returncode != 0:
        pytest.skip("the C compiler has no AddressSanitizer/UBSan")
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=0")  # no heap in the library; LSan needs ptrace
    # `make sanitize`'s two programs, built in the shared BUILD and run outside its lock.
    build, made = make_shared(tmp_path_factory, "{build}/sr_tests_asan", "{build}/sr_tests_asan_f")
    assert made.returncode == 0, made.stdout[-3000:] + made.stderr[-3000:]
    for program in ("sr_tests_asan", "sr_tests_asan_f"):
        out = run([build / program], env=env).stdout
        assert passed_line(out) >= 30, out


# ---- symbols: no allocation, no mutable globals ------------------------------------------

@pytest.mark.parametrize("lib", ["libsphericalrobot.a", "libsphericalrobot_f.a"])
def test_library_references_no_allocator_and_only_libm(build, lib):
    symbols = nm_symbols(build / lib)
    defined = {name for kind, name in symbols if kind != "U"}
    external = {name for kind, name in symbols if kind == "U"} - defined
    assert not external & ALLOCATORS, f"allocation in {lib}: {sorted(external & ALLOCATORS)}"
    assert external <= ALLOWED_EXTERNAL, f"{lib} needs more than libm: {sorted(external - ALLOWED_EXTERNAL)}"


@pytest.mark.parametrize("lib", ["libsphericalrobot.a", "libsphericalrobot_f.a"])
def test_library_has_no_mutable_globals(build, lib):
    mutable = [(kind, name) for kind, name in nm_symbols(build / lib) if kind in MUTABLE_TYPES]
    assert not mutable, f"writable data in {lib}: {mutable}"
    # Also unnamed data: no member may have a non-empty writable section.
    for line in run(["size", "-A", str(build / lib)]).stdout.splitlines():
        parts = line.split()
        if len(parts) >= 2 and re.match(r"\.(data|bss|sdata|sbss)\b", parts[0]) \
                and not parts[0].startswith(".data.rel.ro"):
            assert int(parts[1]) == 0, f"{lib}: {line.strip()}"


@pytest.mark.parametrize("header, at_least", [("spherical_robot.h", 12), ("sr_sensors.h", 11), ("sr_ekf.h", 7)])
def test_every_public_function_returns_a_status_code(header, at_least):
    text = re.sub(r"/\*.*?\*/", "", (INCLUDE / header).read_text(), flags=re.S)
    prototypes = re.findall(r"^([A-Za-z_][\w \t\*]*?)\b(sr_\w+)\s*\(", text, flags=re.M)
    assert len(prototypes) >= at_least
    for ret, name in prototypes:
        expected = "const char *" if name.endswith("_string") else "int"
        assert ret.strip() == expected.strip(), f"{name} returns {ret.strip()!r}"


# ---- the firmware-style example ---------------------------------------------------------------

@pytest.fixture(scope="module")
def example_double(build):
    return read_csv(run([build / "firmware_tshape"]).stdout)


@pytest.fixture(scope="module")
def example_float(build):
    return read_csv(run([build / "firmware_tshape_f"]).stdout)


def test_example_prints_time_and_the_35_state_entries(example_double):
    header, rows = example_double
    assert len(header) == 36 and header[0] == "t" and header[1] == "RS_00" and header[-1] == "w_P"
    assert rows.shape == (STEPS + 1, 36)
    assert np.array_equal(rows[:, 0], np.arange(STEPS + 1) * DT)


def test_example_equals_the_python_runtime_bit_for_bit(example_double):
    from runtime import Model, Params, initial_state

    # initial_state() builds R_Y = rot_x(0), R_P = rot_y(0), whose -sin(0) entries are -0.0; the
    # example starts from the identity matrices as written in C (+0.0).  Adding 0.0 turns -0.0
    # into +0.0, so both sides start from the same bits.
    x0 = initial_state() + 0.0
    expected = Model(Params.paper_simulation()).simulate(x0, DT, STEPS, tshape_torques())
    got = example_double[1][:, 1:]
    differ = np.nonzero(got.view(np.uint64) != expected.view(np.uint64))
    assert differ[0].size == 0, (
        f"{differ[0].size} entries differ; first at step {differ[0][0]}, entry {differ[1][0]}: "
        f"{got[differ][0]!r} vs {expected[differ][0]!r}")


def test_float_example_tracks_the_double_one(example_double, example_float):
    """Bounds about 5x the errors measured in docs/embedding.md."""
    d, f = example_double[1], example_float[1]
    assert f.shape == d.shape  # the float build survives all 10,000 steps
    err = np.abs(f - d)
    assert err[1000].max() < 2e-5      # t = 10 s
    assert err[-1].max() < 1e-2        # t = 100 s
    assert np.linalg.norm(err[-1, 28:31]) < 5e-3   # position after 100 s [m]


def test_float_accelerations_agree_with_double(build):
    a_d = np.array([[float(v) for v in line.split(",")] for line in run([build / "accel_dump"]).stdout.split()])
    a_f = np.array([[float(v) for v in line.split(",")] for line in run([build / "accel_dump_f"]).stdout.split()])
    assert a_d.shape == a_f.shape == (1000, 5)
    rel = np.abs(a_f - a_d).max(axis=1) / np.abs(a_d).max(axis=1)
    assert np.median(rel) < 1e-6 and rel.max() < 2e-5


def test_float_accuracy_script_prints_its_tables(build):
    out = run(["sh", "tools/float_accuracy.sh", str(build)]).stdout
    assert "| 1000 |" in out and "| 10 |" in out and "| 100 |" in out


# ---- CMake -----------------------------------------------------------------------------------

CONSUMER_CMAKE = """cmake_minimum_required(VERSION 3.13)
project(firmware C)
add_subdirectory({c_dir} spherical_robot)
add_executable(firmware main.c)
target_link_libraries(firmware PRIVATE sphericalrobot::sphericalrobot)
"""
CONSUMER_MAIN = """#include "spherical_robot.h"
#include <stdio.h>
int main(void) {
    const sr_real paper[SR_NPAPER] = {0.3, 2, 0.16, 0.2, 0.5, 2, 5, 0.04, 0.2, 1, 0.1, 9.81};
    sr_real x[SR_NX] = {1,0,0, 0,1,0, 0,0,1,  1,0,0, 0,1,0, 0,0,1,  1,0,0, 0,1,0, 0,0,1,  0,0,0.3};
    const sr_real u[SR_NU] = {0.1, 0};
    sr_real p[SR_NPARAM];
    sr_model m;
    int status = sr_paper_params(paper, p);
    if (status == SR_OK) status = sr_model_init(&m, p);
    if (status == SR_OK) status = sr_step(&m, SR_LIE_EULER, x, u, 0.01, x);
    printf("%s %d\\n", sr_status_string(status), (int)sizeof(sr_real));
    return status;
}
"""


@pytest.mark.skipif(not shutil.which("cmake"), reason="needs cmake")
@pytest.mark.parametrize("use_float", [False, True], ids=["double", "float"])
def test_cmake_add_subdirectory(tmp_path, use_float):
    project = tmp_path / "firmware"
    project.mkdir()
    (project / "CMakeLists.txt").write_text(CONSUMER_CMAKE.format(c_dir=C_DIR.as_posix()))
    (project / "main.c").write_text(CONSUMER_MAIN)
    build = tmp_path / "build"
    run(["cmake", "-S", str(project), "-B", str(build), f"-DSR_USE_FLOAT={'ON' if use_float else 'OFF'}"])
    run(["cmake", "--build", str(build), "-j2"])
    assert run([build / "firmware"]).stdout.split() == ["ok", "4" if use_float else "8"]


@pytest.mark.skipif(not shutil.which("cmake"), reason="needs cmake")
def test_cmake_standalone_build_runs_the_c_tests(tmp_path):
    run(["cmake", "-S", str(C_DIR), "-B", str(tmp_path)])
    run(["cmake", "--build", str(tmp_path), "-j2"])
    assert (tmp_path / "libsphericalrobot.a").exists()
    run(["ctest", "--test-dir", str(tmp_path), "--output-on-failure"])


# ---- what a Lie-Euler-only firmware links ------------------------------------------------------

#: Functions that exist only for the fourth-order methods, the dispatcher and the drivers.
NOT_LIE_EULER = {"sr_step", "sr_step_rkmk4", "sr_step_cf4", "sr_internal_advance", "sr_internal_rkmk4_core",
                 "sr_internal_dexpinv", "sr_internal_project", "sr_simulate", "sr_simulate_guarded",
                 "sr_simulate_adaptive"}


def defined_functions(program):
    return {name for kind, name in nm_symbols(program) if kind in "tT"}


def test_the_lie_euler_example_links_no_fourth_order_code(build):
    functions = defined_functions(build / "firmware_tshape")
    assert "sr_step_lie_euler" in functions
    assert not functions & NOT_LIE_EULER, sorted(functions & NOT_LIE_EULER)


def test_a_program_calling_a_fourth_order_step_links_it(build, tmp_path):
    """The control of the test above: linked the same way, a call of sr_step_rkmk4 shows up."""
    probe = tmp_path / "probe.c"
    probe.write_text('#include "spherical_robot.h"\n'
                     "int main(void) { sr_model m; sr_real x[SR_NX] = {0};\n"
                     "    return sr_step_rkmk4(&m, x, 0, SR_C(0.01), x) == SR_OK; }\n")
    run([CC, "-std=c99", "-O2", f"-I{INCLUDE}", f"-I{ROOT / 'generated'}", str(probe), str(build / "libsphericalrobot.a"),
         "-lm", "-Wl,--gc-sections", "-o", str(tmp_path / "probe")])
    assert "sr_step_rkmk4" in defined_functions(tmp_path / "probe")


def test_the_ekf_timing_driver_builds_warning_free_and_reports_every_part(build, tmp_path):
    """bench/bench_ekf.c (`make bench`'s EKF sample) against the library: strict C99, and one JSON
    line with a time for the whole sample, each part, the sample on the default (held) path, and
    the step Jacobian it is compared with."""
    exe = tmp_path / "bench_ekf"
    run([CC, "-std=c99", "-O2", "-Wall", "-Wextra", "-Wpedantic", "-Werror", f"-I{INCLUDE}", f"-I{ROOT / 'generated'}",
         str(ROOT / "bench" / "bench_ekf.c"), str(build / "libsphericalrobot.a"), "-lm", "-o", str(exe)])
    out = json.loads(run([str(exe), "5"]).stdout)
    assert out["samples"] == 5
    for part in ("predict_imu_encoders", "predict", "update_imu", "update_encoders", "held_predict_imu_encoders",
                 "held_predict_imu", "step_jacobian_rkmk4"):
        assert out[f"{part}_ns"] > 0


def test_the_ekf_timing_driver_runs_only_the_parts_asked_for(build, tmp_path):
    """bench_ekf SAMPLES PARTS: those parts once, one time (what bench/ekf_timing.py --callgrind counts)."""
    exe = tmp_path / "bench_ekf"
    run([CC, "-std=c99", "-O2", f"-I{INCLUDE}", f"-I{ROOT / 'generated'}", str(ROOT / "bench" / "bench_ekf.c"),
         str(build / "libsphericalrobot.a"), "-lm", "-o", str(exe)])
    out = json.loads(run([str(exe), "5", "2"]).stdout)
    assert set(out) == {"samples", "parts", "ns"} and out["parts"] == 2 and out["ns"] > 0


# ---- documentation tools ------------------------------------------------------------------------

def test_size_report_covers_every_public_function(tmp_path):
    probe = tmp_path / "probe.c"
    probe.write_text("int f(void) { return 0; }\n")
    if run([CC, "-fcallgraph-info=su", "-c", str(probe), "-o", str(tmp_path / "probe.o")],
           check=False, cwd=tmp_path).returncode != 0:
        pytest.skip("the C compiler has no -fcallgraph-info (GCC >= 10 needed)")
    out = run([sys.executable, str(ROOT / "tools" / "size_report.py"), "--cc", CC]).stdout
    header = "".join(re.sub(r"/\*.*?\*/", "", (INCLUDE / h).read_text(), flags=re.S)
                     for h in ("spherical_robot.h", "sr_sensors.h", "sr_ekf.h"))
    for name in re.findall(r"^[A-Za-z_][\w \t\*]*?\b(sr_\w+)\s*\(", header, flags=re.M):
        assert out.count(f"| `{name}` |") == 2, name  # one row per scalar type


@pytest.mark.parametrize("app_scalar, lib_name", [("float", "libsphericalrobot.a"), ("double", "libsphericalrobot_f.a")])
def test_a_float_double_mismatch_fails_at_link_time(build, tmp_path, app_scalar, lib_name):
    """The float build's symbols carry _f: mixing the builds cannot link (and misread buffers)."""
    flags = ["-DSR_USE_FLOAT"] if app_scalar == "float" else []
    out = run([CC, "-std=c99", *flags, f"-I{INCLUDE}", f"-I{ROOT / 'generated'}",
               str(C_DIR / "examples" / "firmware_tshape.c"), str(build / lib_name), "-lm",
               "-o", str(tmp_path / "mixed")], check=False)
    assert out.returncode != 0
    assert "undefined reference" in out.stderr + out.stdout


# ---- the paper-only build (-DSR_PAPER_ONLY) -------------------------------------------------------
PAPER_ONLY_PROBE = """#include "spherical_robot.h"
#include <stdio.h>
int main(void) {
    const sr_real paper[SR_NPAPER] = {0.3, 2, 0.16, 0.2, 0.5, 2, 5, 0.04, 0.2, 1, 0.1, 9.81};
    sr_real p[SR_NPARAM];
    sr_model m;
    int paper_robot, other_robot;
    if (sr_paper_params(paper, p) != SR_OK) return 2;
    paper_robot = sr_model_init(&m, p);
    p[SR_P_slope] = (sr_real)0.01;
    other_robot = sr_model_init(&m, p);
    printf("%d %d\\n", paper_robot, other_robot);
    return 0;
}
"""


@pytest.mark.parametrize("paper_only", [True, False], ids=["paper-only", "full"])
def test_a_paper_only_build_refuses_other_robots_and_links_no_general_kernel(tmp_path, paper_only):
    """-DSR_PAPER_ONLY leaves the general kernels out (firmware flash); the full build is the control."""
    probe = tmp_path / "probe.c"
    probe.write_text(PAPER_ONLY_PROBE)
    sources = [str(p) for p in sorted((C_DIR / "src").glob("sr_*.c"))] + [str(ROOT / "generated" / "sr_generated.c")]
    flags = ["-DSR_PAPER_ONLY"] if paper_only else []
    run([CC, "-std=c99", "-O1", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-ffunction-sections", *flags,
         f"-I{INCLUDE}", f"-I{ROOT / 'generated'}", str(probe), *sources, "-lm", "-Wl,--gc-sections",
         "-o", str(tmp_path / "probe")])
    out = run([tmp_path / "probe"]).stdout.split()
    linked = {name for _, name in nm_symbols(tmp_path / "probe")}
    general = {name for name in linked if name.startswith("sr_gen_general_")}
    if paper_only:
        assert out == ["0", str(run_status("SR_ERR_PARAM"))] and not general
    else:
        assert out == ["0", "0"] and "sr_gen_general_system" in general


SENSORS_PROBE = """#include "sr_sensors.h"
#include <stdio.h>
int main(void) {
    const sr_real paper[SR_NPAPER] = {0.3, 2, 0.16, 0.2, 0.5, 2, 5, 0.04, 0.2, 1, 0.1, 9.81};
    const sr_real mount[SR_NMOUNT] = {0, 0, -0.05, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    sr_real p[SR_NPARAM], x[SR_NX] = {0}, y[SR_NIMU];
    sr_model m;
    if (sr_paper_params(paper, p) != SR_OK || sr_model_init(&m, p) != SR_OK) return 2;
    x[SR_X_R_S] = x[SR_X_R_S + 4] = x[SR_X_R_S + 8] = 1;
    x[SR_X_R_Y] = x[SR_X_R_Y + 4] = x[SR_X_R_Y + 8] = 1;
    x[SR_X_R_P] = x[SR_X_R_P + 4] = x[SR_X_R_P + 8] = 1;
    x[SR_X_q + 2] = p[SR_P_r];
    if (sr_imu_measure_u(&m, x, NULL, SR_BODY_yoke, mount, NULL, y) != SR_OK) return 3;
    printf("%.6f %.6f %.6f\\n", (double)y[SR_IMU_accel], (double)y[SR_IMU_accel + 1], (double)y[SR_IMU_accel + 2]);
    return 0;
}
"""


@pytest.mark.parametrize("paper_only", [True, False], ids=["paper-only", "full"])
def test_the_sensors_of_a_paper_only_build_read_g_upwards_at_rest(tmp_path, paper_only):
    """The sensor kernels take their constants from the parameters, not from the general kernels'
    constants that a paper-only model leaves at zero."""
    probe = tmp_path / "probe.c"
    probe.write_text(SENSORS_PROBE)
    sources = [str(p) for p in sorted((C_DIR / "src").glob("sr_*.c"))] + [str(ROOT / "generated" / "sr_generated.c")]
    flags = ["-DSR_PAPER_ONLY"] if paper_only else []
    run([CC, "-std=c99", "-O1", "-Wall", "-Wextra", "-Wpedantic", "-Werror", *flags,
         f"-I{INCLUDE}", f"-I{ROOT / 'generated'}", str(probe), *sources, "-lm", "-o", str(tmp_path / "probe")])
    assert run([tmp_path / "probe"]).stdout.split() == ["0.000000", "0.000000", "9.810000"]


def run_status(name):
    from bindings._sr import lib
    return getattr(lib, name)


# -- the read sets of the model's checksums (c/src/sr_argcheck.h, generated/sr_generated.h) --------
# Planted wrong read sets, each in a copy of the sources: c/tests/test_model_validity.c must fail on
# each, naming the entry point.  (file, text, planted text, what the C tests must then report.)
READ_SET_PLANTS = {
    # the library checks too little: the steppers skip the accel kernel's read set
    "library": ("c/src/sr_steppers.c", "arg_model(model, READS(ACCEL) | READS(STATE))", "arg_model(model, READS(STATE))",
                r"sr_step_lie_euler \(paper robot\) with c\[\d+\] = [^,]+, which it reads, returned 0"),
    # the generator lists too little: sr_gen_accel's read set without its last run of constants
    "generator": ("generated/sr_generated.h", "#define SR_GEN_READS_accel(R) ", None,
                  r"sr_accel \(paper robot\) with c\[\d+\] = [^,]+, outside its read set"),
}


@pytest.fixture(scope="module")
def generated_object(tmp_path_factory):
    """generated/sr_generated.c compiled once (-O0: the fastest build), for the planted builds."""
    obj = tmp_path_factory.mktemp("plant-gen") / "sr_generated.o"
    run([CC, "-O0", "-std=c99", f"-I{INCLUDE}", f"-I{ROOT / 'generated'}", "-c", str(ROOT / "generated" / "sr_generated.c"),
         "-o", str(obj)])
    return obj


def planted_build(tmp_path, generated_object, path, old, new):
    """The C tests built from a copy of c/ and generated/ with `old` replaced by `new` in `path`
    (new None: the last R(...) of that line dropped)."""
    for folder in ("c/include", "c/src", "c/tests", "generated"):
        shutil.copytree(ROOT / folder, tmp_path / folder, ignore=shutil.ignore_patterns("*.c") if folder == "generated" else None)
    target = tmp_path / path
    text = target.read_text()
    assert text.count(old) >= 1, f"{path}: the text to plant in is gone: {old!r}"
    if new is None:
        start = text.index(old)
        end = text.index("\n", start)
        line = text[start:end]
        new_line = line[:line.rindex(" R(")]
        text = text[:start] + new_line + text[end:]
    else:
        text = text.replace(old, new)
    target.write_text(text)
    program = tmp_path / "sr_tests"
    sources = sorted(map(str, (tmp_path / "c" / "src").glob("*.c"))) + sorted(map(str, (tmp_path / "c" / "tests").glob("*.c")))
    run([CC, "-O0", "-std=c99", f"-I{tmp_path / 'c' / 'include'}", f"-I{tmp_path / 'generated'}",
         f"-I{tmp_path / 'c' / 'src'}", f"-I{tmp_path / 'c' / 'tests'}", *sources, str(generated_object), "-lm",
         "-o", str(program)])
    return program


@pytest.mark.parametrize("plant", sorted(READ_SET_PLANTS))
def test_the_validity_tests_fail_on_a_planted_wrong_read_set(tmp_path, generated_object, plant):
    path, old, new, report = READ_SET_PLANTS[plant]
    result = run([planted_build(tmp_path, generated_object, path, old, new)], check=False)
    assert result.returncode != 0
    assert re.search(report, result.stderr), result.stderr[-2000:]
    assert "FAILED test_each_entry_point_refuses_a_change_to_what_it_reads_and_only_that" in result.stderr
