"""A Model whose C model (sr_model) is not what sr_model_init left, in what a method reads, is refused
by that method with a KernelError naming the model (SR_ERR_MODEL), never a result; what it does not
read may change without changing its result.  The read sets are the generator's
(SR_GEN_READS_<kernel> in generated/sr_generated.h).  (C: c/tests/test_model_validity.c, every entry
point against every entry.)"""
import math
import re

import numpy as np
import pytest
from bindings._sr import lib

from runtime import Model, Params, initial_state
from runtime.errors import KernelError

from conftest import ROOT


def generated_read_sets():
    """{kernel: [(array, index), ...]}: what each generated kernel reads of a model."""
    text = (ROOT / "generated" / "sr_generated.h").read_text()
    sets = {}
    for kernel, body in re.findall(r"^#define SR_GEN_READS_(\w+)\(R\)(.*)$", text, re.M):
        sets[kernel] = [(a, i) for a, first, end in re.findall(r"R\((\w+), (\d+), (\d+)\)", body)
                        for i in range(int(first), int(end))]
    return sets


READS = generated_read_sets()
R_INDEX = 0   # p[SR_P_r]: read by every method that checks a state

X = initial_state(theta_Y=0.3, theta_P=-0.2, w_S=(0.2, 0.0, 0.1))
XB = np.stack([X, X])
U = np.array([0.1, -0.05])

#: Each method, and the generated kernel of the paper's robot it runs (None: it runs none; it reads r).
CALLS = {
    "accel": (lambda m: m.accel(X, U), "accel"),
    "accel batch": (lambda m: m.accel(XB), "accel"),
    "inertia": (lambda m: m.inertia(X), "inertia"),
    "rhs": (lambda m: m.rhs(X, U), "rhs"),
    "energy": (lambda m: m.energy(X), "energy"),
    "equilibrium_residual": (lambda m: m.equilibrium_residual(X), "equilibrium_residual"),
    "step": (lambda m: m.step(X, U, 0.01), "accel"),
    "step rkmk4 batch": (lambda m: m.step(XB, None, 0.01, "rkmk4"), "accel"),
    "simulate": (lambda m: m.simulate(X, 0.01, 3), "accel"),
    "simulate_adaptive": (lambda m: m.simulate_adaptive(X, 0.03, 0.01), "accel"),
    "retract": (lambda m: m.retract(X, np.zeros(12)), None),
    "local": (lambda m: m.local(X, X), None),
    "accel_jacobian": (lambda m: m.accel_jacobian(X, U), "accel_jacobian_yoke_terms"),
    "accel_jacobian batch": (lambda m: m.accel_jacobian(XB), "accel_jacobian_yoke_terms"),
    "step_jacobian": (lambda m: m.step_jacobian(X, U, 0.01, "rkmk4"), "accel_jacobian_yoke_terms"),
}


def read_by(name):
    """The entries of the model that method `name` reads: its kernel's read set (or r)."""
    kernel = CALLS[name][1]
    return READS[kernel] if kernel else [("p", R_INDEX)]


def poisoned(field, index, value):
    m = Model(Params())
    getattr(m._model, field)[index] = value
    return m


@pytest.mark.parametrize("name", CALLS)
def test_a_valid_model_gives_results(name):
    """The baseline: the same calls on an untouched model succeed."""
    assert not Model(Params())._model.general
    CALLS[name][0](Model(Params()))


@pytest.mark.parametrize("name", CALLS)
@pytest.mark.parametrize("which, value", [(0, math.nan), (-1, 1.5), (0, math.inf)],
                         ids=["first entry NaN", "last entry changed", "first entry inf"])
def test_a_changed_entry_that_the_method_reads_is_refused_naming_the_model(name, which, value):
    field, index = read_by(name)[which]
    with pytest.raises(KernelError, match=r"^model: is not a valid sr_model") as info:
        CALLS[name][0](poisoned(field, index, value))
    assert info.value.field == "model" and info.value.status == lib.SR_ERR_MODEL


def test_a_changed_entry_that_accel_does_not_read_changes_nothing():
    """A constant that sr_gen_energy reads and sr_gen_accel does not: accel neither refuses the
    model nor changes its result; energy refuses it."""
    field, index = next(e for e in READS["energy"] if e not in READS["accel"])
    want = Model(Params()).accel(X, U)
    model = poisoned(field, index, math.nan)
    assert np.array_equal(model.accel(X, U), want)
    with pytest.raises(KernelError, match=r"^model: "):
        model.energy(X)
