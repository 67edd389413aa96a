"""generated/ is reproducible, up to date and clean C99."""
import os
import shutil
import subprocess
import sys

import pytest
import sympy as sp

from conftest import ROOT

GENERATED = ["sr_generated.c", "sr_generated.h"]
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
    for name in GENERATED:
        first = (ROOT / "generated" / name).read_text().splitlines()[0]
        assert "GENERATED FILE, DO NOT EDIT" in first and "derive" in first


@pytest.mark.parametrize("scalar", ["double", "float"])
@pytest.mark.parametrize("source", ["generated/sr_generated.c", "c/sr_runtime.c"])
def test_c_compiles_cleanly_as_c99(scalar, source, tmp_path):
    cc = shutil.which("cc") or shutil.which("gcc")
    flags = WARNINGS + ["-O2", "-Igenerated", "-Ic"] + (["-DSR_USE_FLOAT"] if scalar == "float" else [])
    subprocess.run([cc, *flags, "-c", source, "-o", str(tmp_path / "out.o")], cwd=ROOT, check=True)


def test_constant_pool_moves_parameter_only_subexpressions_out_of_the_kernels():
    from derive import parameters as P
    from derive.codegen import ConstantPool
    from derive.state import gamma
    pool = ConstantPool(P.CONSTANTS)
    expr = P.l * P.m_P * P.r / 2 * gamma[0] - P.l * P.m_P * P.r / 2 * gamma[1] + P.j_P + P.j_S
    hoisted = pool.hoist(expr)
    assert hoisted.free_symbols <= {gamma[0], gamma[1], *pool.symbols()}
    assert len(pool.symbols()) == 2          # l m_P r / 2 (once, for both signs) and j_P + j_S
    back = hoisted.xreplace(dict(zip(pool.symbols(), pool.expressions())))
    assert sp.expand(back - expr) == 0


def test_joint_first_solve_refuses_coupled_joints():
    from derive import dynamics as D
    from derive.codegen import joint_first_system
    M = D.inertia().copy()
    M[3, 4] = M[4, 3] = sp.Symbol("c34")
    with pytest.raises(ValueError, match="M_34"):
        joint_first_system(M, D.rhs())


def test_code_generation_refuses_an_unproven_form():
    from derive.codegen import proven
    with pytest.raises(ValueError, match="differs from the derivation"):
        proven("test", [0, sp.Symbol("x")])


def test_factor_common_takes_a_shared_factor_out_of_a_sum():
    from derive.codegen import factor_common
    a, b, x, y, z = sp.symbols("a b x y z", real=True)
    assert factor_common(a * x + a * y + b) == a * (x + y) + b
    nested = a * b * x + a * b * y + a * z + 3 * a**2 * x
    factored = factor_common(nested)
    assert sp.expand(factored - nested) == 0
    assert sp.count_ops(factored, visual=True).coeff(sp.Symbol("MUL")) < \
        sp.count_ops(nested, visual=True).coeff(sp.Symbol("MUL"))
