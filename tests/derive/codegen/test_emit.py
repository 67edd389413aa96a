"""emit: generated/ is reproducible, up to date, clean C99, names its sources and carries the one layout."""
import os
import re
import shutil
import subprocess
import sys

import pytest

from conftest import ROOT
from derive import parameters as P
from derive import state as S
from derive.codegen import emit

GENERATED = ["sr_generated.c", "sr_generated.h", "casadi/README.txt", "casadi/sr_accel.casadi",
             "casadi/sr_step_lie_euler.casadi", "casadi/sr_step_rkmk4.casadi", "casadi/sr_step_cf4.casadi"]
WARNINGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror"]


def generate(out_dir):
    env = dict(os.environ)
    env.pop("PYTHONHASHSEED", None)
    subprocess.run([sys.executable, "-m", "derive", str(out_dir)], cwd=ROOT, env=env, check=True,
                   capture_output=True)
    return {name: (out_dir / name).read_bytes() for name in GENERATED}


@pytest.fixture(scope="module")
def fresh(tmp_path_factory):
    return generate(tmp_path_factory.mktemp("gen1"))


def test_generation_is_deterministic(fresh, tmp_path):
    assert generate(tmp_path) == fresh


def test_committed_generated_files_are_up_to_date(fresh):
    for name in GENERATED:
        assert (ROOT / "generated" / name).read_bytes() == fresh[name], (
            f"generated/{name} differs from a fresh `make generate`")


def test_generated_files_say_they_are_generated():
    for name in [n for n in GENERATED if not n.endswith(".casadi")]:   # README.txt speaks for those
        first = (ROOT / "generated" / name).read_text().splitlines()[0]
        assert "GENERATED FILE, DO NOT EDIT" in first and "derive" in first


@pytest.mark.parametrize("scalar", ["double", "float"])
@pytest.mark.parametrize("source", ["generated/sr_generated.c"] + sorted(
    p.relative_to(ROOT).as_posix() for p in (ROOT / "c" / "src").glob("*.c")))
def test_c_compiles_cleanly_as_c99(scalar, source, tmp_path):
    cc = shutil.which("cc") or shutil.which("gcc")
    flags = WARNINGS + ["-O2", "-Igenerated", "-Ic/include"] + (["-DSR_USE_FLOAT"] if scalar == "float" else [])
    subprocess.run([cc, *flags, "-c", source, "-o", str(tmp_path / "out.o")], cwd=ROOT, check=True)


def test_generated_header_takes_the_hand_written_types_from_c_include():
    header = (ROOT / "generated" / "sr_generated.h").read_text()
    hand_written = (ROOT / "c" / "include" / emit.HAND_WRITTEN_HEADER).read_text()
    assert f'#include "{emit.HAND_WRITTEN_HEADER}"' in header
    for chosen in ("typedef", "#define SR_C(", "#define SR_GEN_PIVOT_TOL", "#define SR_GEN_OK", "#define SR_GEN_SINGULAR"):
        assert chosen not in header and chosen in hand_written


def macros(header, prefix):
    """{name: value} of the `#define <prefix><name> <integer>` lines of a header."""
    return {name: int(value) for name, value in re.findall(rf"^#define {prefix}(\w+) (\d+)$", header, re.M)}


def layout_mismatches(header):
    """Where the header's SR_P_/SR_X_/SR_U_ macros and sizes differ from derive/parameters.py and derive/state.py."""
    expected = {
        "SR_P_": {s.name: i for i, s in enumerate(P.PARAMETERS)},
        "SR_X_": {name: offset for name, offset, _ in S.STATE_BLOCKS},
        "SR_U_": dict(S.INPUT_NAMES),
        "SR_E_": {name: offset for name, offset, _ in S.ERROR_BLOCKS},
        "SR_GEN_N": {"PARAM": len(P.PARAMETERS), "X": S.NX, "U": S.NU, "V": S.NV, "E": S.NE},
    }
    found = {prefix: macros(header, prefix) for prefix in expected}
    found["SR_GEN_N"] = {k: v for k, v in found["SR_GEN_N"].items() if k in expected["SR_GEN_N"]}
    return {prefix: (found[prefix], want) for prefix, want in expected.items() if found[prefix] != want}


def test_header_layout_macros_equal_the_derive_sources():
    assert layout_mismatches((ROOT / "generated" / "sr_generated.h").read_text()) == {}


@pytest.mark.parametrize("perturb", [
    lambda h: h.replace("#define SR_P_m_P 15", "#define SR_P_m_P 16"),
    lambda h: h.replace("#define SR_X_w_Y 33\n", ""),
    lambda h: h.replace("#define SR_U_u_P 1", "#define SR_U_u_P 0"),
    lambda h: h.replace("#define SR_GEN_NX 35", "#define SR_GEN_NX 36"),
    lambda h: h.replace("#define SR_E_q 5", "#define SR_E_q 6"),
    lambda h: h.replace("#define SR_GEN_NE 12", "#define SR_GEN_NE 11"),
], ids=["parameter index", "missing state block", "input index", "state size", "error block", "error size"])
def test_header_layout_check_fails_for_a_perturbed_header(perturb):
    header = (ROOT / "generated" / "sr_generated.h").read_text()
    perturbed = perturb(header)
    assert perturbed != header
    assert layout_mismatches(perturbed) != {}


def test_provenance_covers_every_file_of_the_package(tmp_path, monkeypatch):
    """The banner's digest changes when any derive/**/*.py changes, a nested one included."""
    shutil.copytree(ROOT / "derive", tmp_path / "derive", ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(emit, "ROOT", tmp_path)
    before = emit.provenance()
    assert before == emit.provenance()
    nested = tmp_path / "derive" / "codegen" / "c_printer.py"
    nested.write_text(nested.read_text() + "# changed\n")
    assert emit.provenance() != before


# -- the read sets: what each kernel's emitted code loads of a model (p, c, cg) ----------------------
def header_read_sets(header):
    """{kernel: {(array, index)}} of the SR_GEN_READS_<kernel>(R) macros of a header."""
    return {name: {(a, i) for a, first, end in re.findall(r"R\((\w+), (\d+), (\d+)\)", body)
                   for i in range(int(first), int(end))}
            for name, body in re.findall(r"^#define SR_GEN_READS_(\w+)\(R\)(.*)$", header, re.M)}


def source_loads(source):
    """{function: {(array, index)}}: the model entries each function of the generated source loads."""
    loads = {}
    for name, body in re.findall(r"^(?:SR_LANES_CLONES )?(?:int|void) sr_gen_(\w+)\(.*?\n\{\n(.*?)\n\}\n", source, re.M | re.S):
        loads[name] = {(a, int(i)) for a, i in re.findall(r"= (p|c|cg)\[(\d+)\];", body)}
    return loads


def read_set_mismatches(header, source):
    """Kernels whose read set in the header is not what their code (and their lanes form's) loads."""
    sets, loads = header_read_sets(header), source_loads(source)
    kernels = {name for name in loads if not name.endswith("_lanes")}
    bad = {name: (sets.get(name), loads[name]) for name in kernels if sets.get(name) != loads[name]}
    bad.update({name: (sets.get(name[:-len("_lanes")]), loads[name]) for name in loads
                if name.endswith("_lanes") and sets.get(name[:-len("_lanes")]) != loads[name]})
    return bad


def test_every_kernel_has_the_read_set_that_its_code_loads():
    header = (ROOT / "generated" / "sr_generated.h").read_text()
    source = (ROOT / "generated" / "sr_generated.c").read_text()
    assert read_set_mismatches(header, source) == {}
    prototypes = set(re.findall(r"^int sr_gen_(\w+)\(", header, re.M))
    assert set(header_read_sets(header)) == prototypes and header_read_sets(header)["accel"]


@pytest.mark.parametrize("perturb", [
    lambda h: h.replace("#define SR_GEN_READS_accel(R) R(c, 6, 17)", "#define SR_GEN_READS_accel(R) R(c, 7, 17)"),
    lambda h: re.sub(r"^#define SR_GEN_READS_inertia\(R\).*\n", "", h, flags=re.M),
], ids=["an entry missing", "a kernel missing"])
def test_the_read_set_check_fails_for_a_perturbed_header(perturb):
    header = (ROOT / "generated" / "sr_generated.h").read_text()
    perturbed = perturb(header)
    assert perturbed != header
    assert read_set_mismatches(perturbed, (ROOT / "generated" / "sr_generated.c").read_text()) != {}


def test_index_ranges_are_the_runs_of_consecutive_indices():
    assert emit.index_ranges((6, 7, 8, 30)) == ((6, 9), (30, 31))
    assert emit.index_ranges(()) == ()


# -- the lanes forms: the kernels over n states, vectorised across them -------------------------------
#: The kernels emitted in lanes form (kernels.py's `lanes=True`): the batch accelerations, and the
#: analytic parameter sensitivity's two kernels, which its RKMK4 stages run on blocks of states.
LANES = {"accel", "general_accel_jacobian_terms", "regressor"}


def lanes_functions(source):
    """{kernel: (lines before the loop, lines in the loop)} of the generated source's sr_gen_*_lanes."""
    found = {}
    for name, body in re.findall(r"^SR_LANES_CLONES void sr_gen_(\w+)_lanes\(.*?\n\{\n(.*?)\n\}\n", source, re.M | re.S):
        before, _, loop = body.partition("    for (i = 0; i < n; ++i) {\n")
        found[name] = (before.splitlines(), loop.splitlines())
    return found


def lanes_loop_faults(source):
    """Lanes loops that read a model array (p, c, cg) or call a function (the sine of the slope) per
    state: GCC 12 keeps such a loop scalar, so those belong before it."""
    return {name: line for name, (_, loop) in lanes_functions(source).items() for line in loop
            if re.search(r"= (p|c|cg)\[\d+\];|SR_GEN_[A-Z]+\(", line)}


def test_the_flagged_kernels_and_only_they_have_lanes_forms():
    source = (ROOT / "generated" / "sr_generated.c").read_text()
    header = (ROOT / "generated" / "sr_generated.h").read_text()
    assert set(lanes_functions(source)) == LANES
    assert set(re.findall(r"^void sr_gen_(\w+)_lanes\(", header, re.M)) == LANES


def test_lanes_loops_read_the_model_once_and_call_nothing():
    source = (ROOT / "generated" / "sr_generated.c").read_text()
    assert lanes_loop_faults(source) == {}
    before, _ = lanes_functions(source)["regressor"]
    assert any("SR_GEN_SIN(slope)" in line for line in before)   # what was hoisted, to be checked


def test_the_lanes_loop_check_fails_for_an_expression_of_the_parameters_left_in_the_loop():
    source = (ROOT / "generated" / "sr_generated.c").read_text()
    line = next(l for l in lanes_functions(source)["regressor"][0] if "SR_GEN_SIN(slope)" in l)
    loop = "    for (i = 0; i < n; ++i) {\n"
    start = source.index("void sr_gen_regressor_lanes(")
    at = source.index(loop, start) + len(loop)
    moved = source[:start] + source[start:at].replace(line + "\n", "") + "    " + line + "\n" + source[at:]
    assert lanes_loop_faults(moved) == {"regressor": "    " + line}


def test_hoisting_moves_the_assignments_of_the_model_arrays_entries_alone():
    body = ["    const sr_real t0 = SR_GEN_SIN(slope);", "    const sr_real t1 = t0*w_Sx;",
            "    const sr_real t2 = g*t0 + SR_C(2.0);", "    good = (t1 > 0) ? good : 0;", "    const sr_real t3 = t2*t1;"]
    before, inside = emit.hoisted(body, ["slope", "g"])
    assert before == [body[0], body[2]] and inside == [body[1], body[3], body[4]]


@pytest.mark.parametrize("inputs", [("x", "u"), ("p",), ("p", "x", "sc")], ids=["no model array", "no rows", "other rows"])
def test_lanes_are_refused_for_inputs_other_than_a_model_array_then_rows(inputs):
    from derive.codegen.spec import Kernel
    with pytest.raises(ValueError, match="lanes are emitted for a model array"):
        emit.lanes_signature(Kernel("k", "doc", inputs, ()))


def vectorised_lanes(extra_flags, tmp_path):
    """The lanes kernels whose loop GCC reports vectorised when it compiles generated/ with the Python
    extension's flags (bindings/build_sr.py), `extra_flags` replacing the alias-check limit."""
    import bindings.build_sr as B
    flags = [f for f in B.COMPILE_ARGS if f not in B.VECT_ALIAS_CHECKS and f != "-DSR_CLONES"] + extra_flags
    source = (ROOT / "generated" / "sr_generated.c").read_text()
    done = subprocess.run([*B.compiler(), *flags, "-Igenerated", "-Ic/include", "-fopt-info-vec-optimized", "-c",
                           "generated/sr_generated.c", "-o", str(tmp_path / "out.o")], cwd=ROOT, check=True,
                          capture_output=True, text=True)
    lines = {int(n) for n in re.findall(r"sr_generated\.c:(\d+):\d+: optimized: loop vectorized", done.stderr)}
    starts = {m.group(1): source[:m.start()].count("\n") + 1
              for m in re.finditer(r"^SR_LANES_CLONES void sr_gen_(\w+)_lanes\(", source, re.M)}
    ends = sorted(starts.values()) + [source.count("\n") + 1]
    return {name for name, first in starts.items() if any(first < n < ends[ends.index(first) + 1] for n in lines)}


@pytest.mark.skipif(shutil.which("gcc") is None, reason="GCC's vectoriser report")
def test_the_extensions_flags_vectorise_every_lanes_loop(tmp_path):
    import bindings.build_sr as B
    assert B.VECT_ALIAS_CHECKS, "the extension is built by GCC here"
    assert vectorised_lanes(B.VECT_ALIAS_CHECKS, tmp_path) == LANES
    # without the raised limit GCC 12 leaves the kernel of five output arrays scalar: the flag is needed
    assert "general_accel_jacobian_terms" not in vectorised_lanes([], tmp_path)
