"""The compiled Kane baselines (runtime/bench/kane_compiled.py): each computes our accel from the
Kane model's own coordinates, and the bench's check refuses one that is off by 1e-6."""
import copy
import pathlib
import subprocess

import numpy as np
import pytest

from runtime.bench import baselines, harness, kane_compiled
from runtime.bench.checks import WrongNumbers
from runtime.model import Model
from runtime.params import Params
from runtime.verification.sampling import random_inputs, random_states

KANE_KEYS = ("kane_casadi_c_accel", "kane_sympy_c_accel", "kane_pydy_c_accel")


@pytest.fixture(scope="module")
def model():
    return Model(Params.paper_simulation())


@pytest.fixture(scope="module")
def c_loop(model, tmp_path_factory):
    """The C loop with the three Kane baselines, run once over 8 random states."""
    build = tmp_path_factory.mktemp("bench")
    rng = np.random.default_rng(5)
    X, U = random_states(rng, 8, model.params), random_inputs(rng, 8)
    harness.casadi_reference_c(model.params, build)
    exe = harness.build_harness(build, native=False, with_casadi=True, kane=kane_compiled.write_kane_c(build))
    result = harness.run_harness(exe, model.params, X, U, 1, kane_compiled.kane_inputs(X))
    return result, X, U


def test_every_compiled_kane_baseline_gives_our_accel(c_loop, model):
    result, X, U = c_loop
    for key in KANE_KEYS:
        assert result[key]["ns"] > 0
        for got, x, u in zip(result[key]["check"], X, U):
            expected = model.accel(x, u)
            assert np.abs(np.array(got) - expected).max() <= 1e-11 * np.abs(expected).max()
    harness.check_harness(copy.deepcopy(result), model, X, U)   # it drops the checked rows


@pytest.mark.parametrize("key", KANE_KEYS)
def test_the_bench_refuses_a_kane_baseline_off_by_1e_6(c_loop, model, key):
    result, X, U = c_loop
    bad = copy.deepcopy(result)
    bad[key]["check"][3][2] *= 1 + 1e-6
    with pytest.raises(WrongNumbers, match=key):
        harness.check_harness(bad, model, X, U)


def test_generic_lu_solves_a_system_that_needs_pivoting(tmp_path):
    (tmp_path / "lu.c").write_text(kane_compiled.GENERIC_LU + r"""
#include <stdio.h>
int main(void)
{
    double A[9] = {0, 2, 1,  1, 1, 1,  2, 1, 0}, b[3] = {5, 4, 4};   /* x = (1, 2, 1) */
    if (generic_lu_solve(3, A, b)) return 1;
    printf("%.17g %.17g %.17g\n", b[0], b[1], b[2]);
    return 0;
}
""")
    subprocess.run(["cc", "-std=c99", str(tmp_path / "lu.c"), "-lm", "-o", str(tmp_path / "lu")], check=True)
    x = np.array(subprocess.run([str(tmp_path / "lu")], capture_output=True, text=True, check=True).stdout.split(),
                 dtype=float)
    assert np.allclose(x, [1, 2, 1], rtol=0, atol=1e-14)


def test_compiled_kane_from_python_is_checked_against_our_accel_and_timed(model):
    rng = np.random.default_rng(6)
    X, U = random_states(rng, 3, model.params), random_inputs(rng, 3)
    out = baselines.compiled_kane_timings(
        model, list(zip(X, U)), lambda msg: None, min_seconds=1e-4, rounds=1)
    assert out["pydy_cython_rhs_ns"] > 0 and out["kane_casadi_function_ns"] > 0


@pytest.mark.parametrize("key, entry", [("accel_jacobian", 2), ("kane_casadi_c_accel_jacobian", 8 * 5 + 2),
                                        ("step_jacobian_lie_euler", 12 * 5 + 2), ("step_jacobian_rkmk4", 12 * 5 + 2),
                                        ("step_jacobian_cf4", 12 * 5 + 2), ("accel_general_robot", 3)])
def test_the_bench_refuses_a_jacobian_off_by_1e_6(c_loop, model, key, entry):
    """Our accel_jacobian and the Kane Jacobian by CasADi AD are checked against CasADi AD of the reference
    before their times count (the Kane one in its speed and torque columns, entry 42 = column 8, row 2)."""
    result, X, U = c_loop
    bad = copy.deepcopy(result)
    bad[key]["check"][3][entry] *= 1 + 1e-6
    with pytest.raises(WrongNumbers, match="Jacobian|jacobian|general robot"):
        harness.check_harness(bad, model, X, U)
