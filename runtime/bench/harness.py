"""The C loop (bench/bench_kernels.c): build it with our kernels and the CasADi-generated reference, run it
over random states, and check its outputs before any of its times is believed."""
import json
import os
import pathlib
import shutil
import struct
import subprocess

import numpy as np

from ..state import NE, NU, NV
from ..verification.reference import ReferenceModel
from ..verification.steppers import STEPPERS
from .checks import WrongNumbers, check_close

ROOT = pathlib.Path(__file__).resolve().parents[2]


def casadi_reference_c(params, build):
    """The independent reference's accel as one CasADi Function, through CasADi's code generator."""
    import casadi as ca

    ref = ReferenceModel(params.as_dict())
    x, u = ca.MX.sym("x", 35), ca.MX.sym("u", 2)
    kkt, rhs = ref._f_kkt(x, u)
    sol = ca.solve(kkt, rhs, "qr")
    J, b = ref._f_conv(x)
    accel = ca.vertcat(ca.mtimes(J, sol[0:7]) + b, sol[3:5])
    fn = ca.Function("ref_accel", [x, u], [accel])
    cwd = os.getcwd()
    try:
        os.chdir(build)
        fn.generate("ref_accel.c", {"with_header": True, "casadi_real": "double"})
    finally:
        os.chdir(cwd)
    return build / "ref_accel.c"


def _compiler():
    return os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")


#: How the timed programs build the library (portable: no -march; the AVX2 clones as the extension has them).
LIBRARY_FLAGS = ["-std=c99", "-O3", "-DSR_CLONES", f"-I{ROOT / 'generated'}", f"-I{ROOT / 'c' / 'include'}"]


def _library_sources():
    """The generated and the hand-written C of the library."""
    return [p for d in ("generated", "c/src") for p in sorted((ROOT / d).glob("*.c"))]


def compile_library(folder, flags):
    """The library's objects compiled with `flags` into `folder`, each rebuilt only when its source or
    a header is newer (a bench's --objects folder is kept between runs)."""
    sources = _library_sources()
    newest_header = max(p.stat().st_mtime for d in ("generated", "c/include", "c/src") for p in (ROOT / d).glob("*.h"))
    objects = [folder / (src.stem + ".o") for src in sources]
    stale = [(src, obj) for src, obj in zip(sources, objects)
             if not obj.exists() or obj.stat().st_mtime < max(src.stat().st_mtime, newest_header)]
    for k in range(0, len(stale), 2):     # two compilers at a time: the machine's two cores
        jobs = [subprocess.Popen([_compiler(), *flags, "-c", str(src), "-o", str(obj)]) for src, obj in stale[k:k + 2]]
        if any(job.wait() for job in jobs):
            raise RuntimeError("compilation of the library failed")
    return objects


def with_baseline(folder, objects, source, revision, flags):
    """`objects` with the one built from c/src/`source` replaced by that file as it was at the git
    `revision`, compiled with `flags` into folder/baseline: the same library before a change."""
    old = folder / "baseline" / source
    old.parent.mkdir(exist_ok=True)
    old.write_bytes(subprocess.run(["git", "show", f"{revision}:c/src/{source}"], cwd=ROOT, check=True,
                                   capture_output=True).stdout)
    subprocess.run([_compiler(), *flags, f"-I{ROOT / 'c' / 'src'}", "-c", str(old), "-o", str(old.with_suffix(".o"))],
                   check=True)
    return [old.with_suffix(".o") if o.stem == old.stem else o for o in objects]


def build_harness(build, native, with_casadi, kane=None):
    """The C loop's executable; `kane` = (sources, macros) of runtime/bench/kane_compiled.write_kane_c."""
    cc = _compiler()
    sources = [str(p) for p in _library_sources()]
    flags = [*LIBRARY_FLAGS, f"-I{build}"]
    if native:
        flags.append("-march=native")
    if with_casadi:
        flags.append("-DWITH_CASADI")
        sources.append(str(build / "ref_accel.c"))
    if kane is not None:
        kane_sources, macros = kane
        flags += ["-DWITH_KANE", *(f"-D{name}={value}" for name, value in macros.items())]
        sources += map(str, kane_sources)
    exe = build / ("bench_native" if native else "bench")
    subprocess.run([cc, *flags, str(ROOT / "bench" / "bench_kernels.c"), *sources, "-lm", "-o", str(exe)],
                   check=True)
    return exe


def step_anatomy(build, input_file, repeats):
    """Where a fourth-order step's time goes (bench/step_anatomy.c): the checked
    accel, four accels chained as a step's stages chain them, and the steps; then the same steps
    with the dynamics replaced by a two-flop stub (the library's c/src/sr_steppers.c compiled into the
    program with -DANATOMY_GLUE_ONLY), i.e. everything a step does but its four accelerations.
    Built with the C loop's LIBRARY_FLAGS; `input_file` is the C loop's input."""
    library = _library_sources()
    out = {}
    for name, extra, sources in (
            ("full", [], library),
            ("glue_only", ["-DANATOMY_GLUE_ONLY", f"-I{ROOT / 'c' / 'src'}"], [p for p in library if p.name != "sr_steppers.c"])):
        exe = build / f"step_anatomy_{name}"
        subprocess.run([_compiler(), *LIBRARY_FLAGS, *extra, str(ROOT / "bench" / "step_anatomy.c"),
                        *map(str, sources), "-lm", "-o", str(exe)], check=True)
        run = subprocess.run([str(exe), str(input_file), str(repeats)], check=True, capture_output=True, text=True)
        out[name] = json.loads(run.stdout)
    return out


def ekf_sample(build, samples=2000):
    """One 200 Hz sample of the error-state EKF (bench/bench_ekf.c): an RKMK4 predict, an IMU and an
    encoder update over a recorded run, each part alone too, and one RKMK4 step Jacobian in the same
    run; ns, best of 11 rounds.  The portable -O2 build, as the firmware's."""
    exe = build / "bench_ekf"
    flags = [f for f in LIBRARY_FLAGS if f != "-O3"] + ["-O2", "-ffp-contract=off"]
    subprocess.run([_compiler(), *flags, str(ROOT / "bench" / "bench_ekf.c"), *map(str, _library_sources()), "-lm",
                    "-o", str(exe)], check=True)
    out = subprocess.run([str(exe), str(samples)], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def memory_floor(build, states, rounds=7):
    """ns per state of bench/memory_floor.c on `states` states: the batch accel's memory traffic
    alone (read x and u, write 5 numbers a state), compiled as fast as it goes."""
    exe = build / "memory_floor"
    subprocess.run([_compiler(), "-std=c99", "-O3", "-ffast-math", "-march=native", str(ROOT / "bench" / "memory_floor.c"),
                    "-o", str(exe)], check=True)
    out = subprocess.run([str(exe), str(states), str(rounds)], check=True, capture_output=True, text=True).stdout
    return json.loads(out)["ns_per_state"]


def general_robot(params):
    """The general robot the C loop times beside `params`: the same radius, so the same
    states are valid, with an off-centre battery, full tensors, geared rotors and a slope (its
    kernels are the general ones)."""
    from ..scenario import load_scenario
    return load_scenario("battery-geared").params.replace(r=params.r, slope=0.05)


#: The LQR's schedule and the target of its timed sample (bench/bench_kernels.c: LQR_TARGET).
LQR_RATE, LQR_U_MAX = 50.0, 0.5


def lqr_controller(params):
    """The LQR controller that the C loop's controller timing uses, designed for `params`."""
    from ..control.lqr import Lqr
    return Lqr(params, LQR_RATE, LQR_U_MAX)


def lqr_target():
    """The path target that the controller timings track (a curve with a cross-track error)."""
    from ..control.reference import Target
    return Target(speed=0.3, heading=0.5, curvature=0.2, cross_track=0.05)


def write_input(path, params, X, U, kane_inputs=None):
    """The C loop's input file (bench/bench_kernels.c; bench/step_anatomy.c reads its first four
    parts): n, the parameters, the states, the torques, then what only the C loop reads."""
    with open(path, "wb") as f:
        f.write(struct.pack("i", len(X)))
        f.write(np.ascontiguousarray(params.as_array()).tobytes())
        f.write(np.ascontiguousarray(X).tobytes())
        f.write(np.ascontiguousarray(U).tobytes())
        f.write(np.ascontiguousarray(general_robot(params).as_array()).tobytes())
        from bindings._sr import ffi
        f.write(bytes(ffi.buffer(lqr_controller(params)._c)))
        if kane_inputs is not None:     # the Kane model's coordinates, then its (the paper's) parameters
            f.write(np.ascontiguousarray(kane_inputs, dtype=np.float64).tobytes())
            f.write(np.ascontiguousarray(params.paper_params.as_array(), dtype=np.float64).tobytes())
    return path


def run_harness(exe, params, X, U, repeats, kane_inputs=None):
    """Runs the compiled C timing loop `exe` on the states X and torques U, `repeats` sweeps; returns its
    JSON output as a dict."""
    data = write_input(exe.parent / "input.bin", params, X, U, kane_inputs)
    out = subprocess.run([str(exe), str(data), str(repeats)], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def _reference_jacobians(ref, X, U):
    """(Ja (n, 5, 12), Jb (n, 5, 2)) by CasADi AD of the reference at x ⊕ d (runtime.verification.jacobians)."""
    from ..verification.jacobians import reference_accel_jacobian
    n = len(X)
    Ja, Jb = reference_accel_jacobian(ref).map(n)(np.asarray(X).T, np.asarray(U).T)
    return (np.asarray(Ja).reshape(NV, n, 12).transpose(1, 0, 2), np.asarray(Jb).reshape(NV, n, 2).transpose(1, 0, 2))


def check_harness(result, model, X, U, step_dt=0.01):
    """Every state's outputs of the C loop against independent numbers, before any time is believed.

    All n states: accel (checked and raw) and the CasADi-generated reference's against the
    reference (runtime.verification.reference), inertia against the reference's, and each
    stepper's step against the NumPy transcription of its tableau (runtime.verification.steppers)
    driven by the reference's accel, so that no check compares the C with itself.  Then the
    outputs (n rows per kernel) are dropped from `result` and the worst relative differences
    kept under result["checked"]; raises WrongNumbers on the first failure.
    """
    ref = ReferenceModel(model.params.as_dict())
    n = len(X)
    worst = {}

    def check(name, key, expected, rtol):
        got = result[key]["check"]
        if len(got) != n:
            raise WrongNumbers(f"{name}: the C loop returned {len(got)} of its {n} states")
        for i in range(n):
            err = check_close(f"{name} (state {i})", np.reshape(got[i], np.shape(expected(i))), expected(i), rtol)
            worst[name] = max(worst.get(name, 0.0), err)

    accel = ref.accel_batch(X, U)
    check("C accel vs reference", "accel", lambda i: accel[i], 1e-10)
    check("C raw accel vs reference", "accel_unchecked", lambda i: accel[i], 1e-10)
    if "checked_accel_batch" in result:
        check("C checked accel batch vs reference", "checked_accel_batch", lambda i: accel[i], 1e-10)
    check("C inertia vs reference", "inertia", lambda i: ref.inertia(X[i]), 1e-10)
    for key, method in [("step_lie_euler", "lie-euler"), ("step_rkmk4", "rkmk4"), ("step_cf4", "cf4"),
                        ("step_batch_lie_euler", "lie-euler"), ("step_batch_rkmk4", "rkmk4"),
                        ("step_batch_cf4", "cf4")]:
        if key in result:
            step = STEPPERS[method]
            check(f"C {method} step vs NumPy tableau on the reference", key,
                  lambda i, step=step: step(ref.accel, ref.params["r"], X[i], U[i], step_dt), 1e-10)
    for key in ("kane_casadi_c_accel", "kane_sympy_c_accel", "kane_pydy_c_accel"):
        if key in result:
            check(f"C loop {key} vs reference", key, lambda i: accel[i], 1e-10)
    if "accel_jacobian" in result or "kane_casadi_c_accel_jacobian" in result:
        Ja, Jb = _reference_jacobians(ref, X, U)
        if "accel_jacobian" in result:
            check("C accel_jacobian vs CasADi AD of the reference", "accel_jacobian",
                  lambda i: np.concatenate([Ja[i].ravel(), Jb[i].ravel()]), 1e-10)
        if "kane_casadi_c_accel_jacobian" in result:
            # The Kane Jacobian is column-major 5 x 14 in (qw, u); its speed columns (7..11) are our ν block.
            rows = result["kane_casadi_c_accel_jacobian"]["check"]
            result["kane_casadi_c_accel_jacobian"]["check"] = [
                list(np.concatenate([np.reshape(r, (14, NV)).T[:, 7:12].ravel(), np.reshape(r, (14, NV)).T[:, 12:14].ravel()]))
                for r in rows]
            check("C loop Kane Jacobian by CasADi AD (speed and torque columns) vs CasADi AD of the reference",
                  "kane_casadi_c_accel_jacobian",
                  lambda i: np.concatenate([Ja[i][:, 7:12].ravel(), Jb[i].ravel()]), 1e-9)
    for method in ("lie-euler", "rkmk4", "cf4"):
        key = "step_jacobian_" + method.replace("-", "_")
        if key in result:
            from ..step_jacobian import jacobian_function
            n = len(X)
            F, G = jacobian_function(method).map(n)(np.asarray(X).T, np.asarray(U).T, step_dt, model.params.as_array())
            F = np.asarray(F).reshape(NE, n, NE).transpose(1, 0, 2)
            G = np.asarray(G).reshape(NE, n, NU).transpose(1, 0, 2)
            check(f"C {method} step_jacobian vs CasADi AD of the exported SX step", key,
                  lambda i, F=F, G=G: np.concatenate([F[i].ravel(), G[i].ravel()]), 1e-10)
    if "accel_general_robot" in result:
        general = ReferenceModel(general_robot(model.params).as_dict())
        general_accel = general.accel_batch(X, U)
        check("C accel of a general robot vs reference", "accel_general_robot", lambda i: general_accel[i], 1e-10)
        check("C RKMK4 step of a general robot vs NumPy tableau on the reference", "step_rkmk4_general_robot",
              lambda i: STEPPERS["rkmk4"](general.accel, general.params["r"], X[i], U[i], step_dt), 1e-10)
    if "lqr_control" in result:
        from ..control.lqr_law import numpy_law
        controller, target = lqr_controller(model.params), lqr_target()
        g = controller.gains
        check("C lqr_control vs the NumPy law (runtime.control.lqr_law)", "lqr_control",
              lambda i: numpy_law(controller.schedule, model.params.r, X[i], target, np.zeros(2), None,
                                  controller.period, controller.u_max, g.kappa_rate, g.steady_rate_m_s,
                                  tight_band=g.tight_band_m, tight_rise=g.tight_rise_s)[1], 1e-10)
    if "casadi_generated_reference_accel" in result:
        check("CasADi-generated reference vs reference", "casadi_generated_reference_accel", lambda i: accel[i], 1e-10)
    for value in result.values():
        if isinstance(value, dict):
            value.pop("check", None)
    result["checked"] = {"states": n, "worst_relative_difference": worst}
    return worst
